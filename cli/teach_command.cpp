#include "cli/teach_command.h"

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <iostream>
#include <set>
#include <sstream>
#include <string>

#include "arm/arm_component.h"
#include "arm/free_drive.h"
#include "arm/hand_guiding_limits.h"
#include "bt/builder.h"
#include "bt/executor.h"
#include "bt/plan_xml.h"
#include "core/image.h"
#include "core/text.h"
#include "sim/simulation.h"
#include "trials/free_drive_trial.h"
#include "workcell/workcell.h"

namespace costar::cli {

namespace {

constexpr const char* kHelp = R"(commands:
  where                               the tool's pose and the joint angles
  list                                taught waypoints
  jog joint N DEGREES                 turn joint N: JOINTS
  jog x|y|z METRES [tool]             move the tool in a straight line (world axes, or the tool's)
  jog roll|pitch|yaw DEGREES [tool]   turn the tool about an axis
  teach NAME [joints] [in FRAME]      save where the arm is: the tool's pose (relative to FRAME,
                                      default world), or with 'joints' the joint angles
  move NAME [SPEED]                   go to a waypoint (SPEED: 0.01 .. 1, default 0.5)
  home                                go to the home configuration
  rename OLD NEW | delete NAME        manage waypoints
  open | close                        the gripper
  detect                              detect the parts (DetectObjects)
  objects                             the parts detected, with their poses
  grasp CLASS NAME                    teach a grasp: the gripper is around a detected part of
                                      CLASS now; SmartMove will grasp parts of CLASS like this
  drag FX FY FZ SECONDS [MODE] [lock AXES] [tool] [turn TX TY TZ]
                                      free-drive (simulated cells): a hand pushes the tool with
                                      FX FY FZ N (world) and TX TY TZ N m, dead-man held for
                                      SECONDS; MODE free, translation or rotation; AXES e.g. z,rx
  drag random SECONDS SEED            a person's random drag for SECONDS of simulated time,
                                      judged: joint limits, contacts, tool speed
  drag stroke SEED [SPEED]            guide a curved stroke by hand, record it ('stroke'),
                                      replay it (FollowTrajectory at SPEED), compare the paths
  drag ... record NAME [in FRAME]     record the guided path as trajectory NAME (in FRAME)
  replay NAME [in FRAME] [SPEED]      FollowTrajectory: replay a recorded trajectory
  trajectories                        recorded trajectories
  snapshot FILE.png                   a picture of the cell (simulated cells)
  help | quit
)";

/// The help with the joints of `cell`'s arm as its JogJoint operation names them (from the
/// robot description: "1 (base) to 6 (wrist 3)" on the UR5, "1 (A1) to 7 (A7)" on the iiwa);
/// without a cell, the arm's joints in general.
std::string helpText(workcell::Workcell* cell) {
  std::string joints = "1 (the base) to the number of the arm's joints";
  if (cell != nullptr) {
    if (const component::Component* arm = cell->components().provider("JogJoint")) {
      for (const auto& operation : arm->description().operations) {
        for (const auto& param : operation.params) {
          if (operation.name == "JogJoint" && param.name == "joint") {
            joints = param.description;
          }
        }
      }
    }
  }
  std::string help = kHelp;
  help.replace(help.find("JOINTS"), 6, joints);
  return help;
}

std::string escape(const std::string& text) {
  std::string out;
  for (const char c : text) {
    out += c == '"'   ? std::string("&quot;")
           : c == '&' ? std::string("&amp;")
           : c == '<' ? std::string("&lt;")
                      : std::string(1, c);
  }
  return out;
}

/// Runs one operation node (XML) to completion, calling `each_tick` before every tick; prints
/// the outcome.
bool runNode(workcell::Workcell& cell, const std::string& node, const std::function<void()>& each_tick = {}) {
  try {
    const bt::Plan plan =
        bt::loadPlanText(R"(<root BTCPP_format="4"><BehaviorTree ID="teach">)" + node + "</BehaviorTree></root>",
                         "command", {.follow_includes = false});
    bt::Tree tree = bt::buildTree(plan, cell.nodes(), cell.clock());
    bt::Executor executor(tree, cell.clock());
    executor.setBeforeTick([&cell, &each_tick] {
      cell.beforeTick();
      if (each_tick) {
        each_tick();
      }
    });
    const bt::RunResult result = executor.run();
    if (result.status == bt::Status::kSuccess) {
      std::printf("ok (%.2f s)\n", toSeconds(result.elapsed));
      return true;
    }
    std::printf("failed: %s\n", result.failure_reason.c_str());
  } catch (const bt::PlanError& error) {
    for (const auto& diagnostic : error.diagnostics()) {
      std::printf("error: %s\n", diagnostic.message.c_str());
    }
  }
  return false;
}

void printWhere(workcell::Workcell& cell) {
  cell.beforeTick();
  const auto& world = cell.components().world();
  if (const auto* endpoint = world.symbol("endpoint"); endpoint != nullptr && endpoint->frame() != nullptr) {
    const world::Pose& pose = endpoint->frame()->pose;
    const Eigen::Vector3d rpy = world::rpyOf(pose.linear()) * 180.0 / M_PI;
    std::printf("tool: x %.4f  y %.4f  z %.4f m   roll %.1f  pitch %.1f  yaw %.1f deg\n", pose.translation().x(),
                pose.translation().y(), pose.translation().z(), rpy.x(), rpy.y(), rpy.z());
  }
  if (const auto* joints = world.symbol("arm_joints"); joints != nullptr && joints->joints() != nullptr) {
    std::printf("joints (deg):");
    for (const double q : joints->joints()->positions) {
      std::printf(" %.1f", q * 180.0 / M_PI);
    }
    std::printf("\n");
  }
}

void printWaypoints(workcell::Workcell& cell) {
  cell.beforeTick();
  // The arm's symbols besides those its description declares (endpoint, arm_joints, wrench, ...)
  // are its taught waypoints (a hostile tester saw the force sensor's 'wrench' listed as one).
  const component::Component* arm = cell.components().provider("Teach");
  std::set<std::string> own;
  if (arm != nullptr) {
    for (const auto& symbol : arm->description().symbols) {
      own.insert(symbol.name);
    }
  }
  int count = 0;
  for (const world::Symbol* symbol : cell.components().world().symbols()) {
    if (arm == nullptr || symbol->source != arm->description().name || own.contains(symbol->name)) {
      continue;
    }
    ++count;
    if (const auto* frame = symbol->frame()) {
      const auto& p = frame->pose.translation();
      std::printf("  %-20s pose in %s: %.4f %.4f %.4f\n", symbol->name.c_str(), frame->parent.c_str(), p.x(), p.y(),
                  p.z());
    } else {
      std::printf("  %-20s joint configuration\n", symbol->name.c_str());
    }
  }
  if (count == 0) {
    std::printf("  (no waypoints taught yet)\n");
  }
}

/// A number from a command's word, or nullopt (after saying so).
std::optional<double> number(const std::string& word) {
  try {
    std::size_t used = 0;
    const double value = std::stod(word, &used);
    if (used == word.size() && std::isfinite(value)) {
      return value;
    }
  } catch (const std::exception&) {
  }
  std::printf("error: '%s' is not a number\n", word.c_str());
  return std::nullopt;
}

/// drag random SECONDS SEED: the scripted random drag, judged.
void dragRandom(workcell::Workcell& cell, const std::vector<std::string>& w) {
  const auto seconds = number(w[2]);
  const auto seed = number(w[3]);
  if (!seconds || !seed) {
    return;
  }
  if (*seconds <= 0.0 || *seed < 0.0) {
    std::printf("error: drag random needs a positive duration and a seed of 0 or more\n");
    return;
  }
  try {
    const trials::FreeDriveTrialResult r =
        trials::runFreeDriveTrial(cell, {.seconds = *seconds, .seed = static_cast<std::uint64_t>(*seed)});
    std::printf("dragged %.1f s (simulated) in %d holds, the tool travelled %.2f m\n", r.seconds, r.holds, r.travelled);
    std::printf("joint limit violations: %llu ticks (closest to a limit: %.3f rad)\n",
                static_cast<unsigned long long>(r.joint_limit_violations), r.closest_to_limit);
    std::printf("the joints at most %.3f rad from the configuration the steps were checked at\n", r.max_departure);
    std::printf("nearest a singularity: dexterity %.4f m/rad (joints %s; the guard slows from %.3f, stops at %.3f)\n",
                r.least_dexterity, r.least_dexterity_joints.c_str(), arm::AdmittanceGains{}.singular_slow,
                arm::AdmittanceGains{}.singular_floor);
    std::printf("contacts: table %llu physics steps, parts %llu ticks%s%s; lowest tool %.3f m above the table\n",
                static_cast<unsigned long long>(r.table_contact_steps),
                static_cast<unsigned long long>(r.part_contact_ticks), r.first_part_contact.empty() ? "" : " (first: ",
                (r.first_part_contact + (r.first_part_contact.empty() ? "" : ")")).c_str(), r.lowest_tool);
    std::printf("tool speed: at most %.3f m/s (at %.2f s, %s); at rest %.2f s after letting go at most\n",
                r.max_tool_speed, r.max_speed_at, r.max_speed_held ? "free-driving" : "let go", r.max_stop_time);
    std::printf("the tool at most %.1f mm from its reference (the protective stop's limit: %.0f mm)\n",
                1000.0 * r.max_tracking, 1000.0 * arm::ProtectiveLimits{}.tracking);
    for (const auto& [why, ticks] : r.blocked) {
      std::printf("  refused steps: %-40s %d ticks\n", why.c_str(), ticks);
    }
    if (!r.failure.empty()) {
      std::printf("failed: %s\n", r.failure.c_str());
    }
  } catch (const std::exception& e) {
    std::printf("failed: %s\n", e.what());
  }
}

/// drag stroke SEED [SPEED]: a stroke recorded by hand and replayed, compared.
void dragStroke(workcell::Workcell& cell, const std::vector<std::string>& w) {
  const auto seed = number(w[2]);
  const auto speed = w.size() > 3 ? number(w[3]) : std::optional<double>(1.0);
  if (!seed || !speed) {
    return;
  }
  try {
    const trials::ReplayTrialResult r = trials::runReplayTrial(cell, static_cast<std::uint64_t>(*seed), *speed);
    if (!r.failure.empty()) {
      std::printf("failed: %s\n", r.failure.c_str());
      return;
    }
    std::printf("recorded a %.3f m stroke in %.2f s: %zu samples, %zu kept\n", r.length, r.recorded_seconds, r.samples,
                r.kept);
    std::printf(
        "replayed in %.2f s: the tool %.2f mm RMS from the recorded path (%.2f mm at most), turned %.2f deg "
        "from it at most\n",
        r.replay_seconds, 1000.0 * r.rms_position, 1000.0 * r.max_position, r.max_angle * 180.0 / M_PI);
  } catch (const std::exception& e) {
    std::printf("failed: %s\n", e.what());
  }
}

/// drag FX FY FZ SECONDS [MODE] [lock AXES] [tool] [turn TX TY TZ]: one push with the dead-man held.
void drag(workcell::Workcell& cell, const std::vector<std::string>& w) {
  sim::Simulation* simulation = cell.simulation();
  auto* arm = dynamic_cast<arm::ArmComponent*>(cell.components().provider("FreeDrive"));
  if (simulation == nullptr || arm == nullptr) {
    std::printf("failed: '%s' is not a simulated workcell with free-drive\n", cell.name().c_str());
    return;
  }
  arm::Wrench hand;
  std::optional<double> seconds;
  for (int i = 0; i < 3; ++i) {
    const auto value = number(w[static_cast<std::size_t>(i + 1)]);
    if (!value) {
      return;
    }
    hand.force[i] = *value;
  }
  if (seconds = number(w[4]); !seconds) {
    return;
  }
  // A person's hand, as in the editor: a firm push and twist at most.
  const auto tooHard = [](const Eigen::Vector3d& value, double limit, const char* verb, const char* what,
                          const char* unit) {
    if (value.norm() <= limit) {
      return false;
    }
    std::printf("error: a hand %s the tool with at most %g %s; the %s asked is %g %s (nothing was done)\n", verb, limit,
                unit, what, value.norm(), unit);
    return true;
  };
  std::string mode = "free";
  std::string locked;
  std::string axes = "world";
  std::string record;
  std::string record_frame = "world";
  for (std::size_t i = 5; i < w.size(); ++i) {
    if (w[i] == "lock" && i + 1 < w.size()) {
      locked = w[++i];
    } else if (w[i] == "tool") {
      axes = "tool";
    } else if (w[i] == "record" && i + 1 < w.size()) {
      record = w[++i];
    } else if (w[i] == "in" && i + 1 < w.size()) {
      record_frame = w[++i];
    } else if (w[i] == "turn" && i + 3 < w.size()) {
      for (int k = 0; k < 3; ++k) {
        const auto value = number(w[++i]);
        if (!value) {
          return;
        }
        hand.torque[k] = *value;
      }
    } else {
      mode = w[i];
    }
  }
  if (tooHard(hand.force, arm::kMaxHandForce, "pushes", "force", "N") ||
      tooHard(hand.torque, arm::kMaxHandTorque, "turns", "torque", "N m")) {
    return;
  }
  const world::Pose before = simulation->tcpPose();
  const TimePoint start = cell.clock().now();
  std::string blocked;
  // The tool's fastest, measured on the simulator's true pose between ticks.
  double fastest = 0.0;
  world::Pose last = before;
  TimePoint last_time = start;
  const bool ok =
      runNode(cell,
              "<FreeDrive mode=\"" + escape(mode) + "\" locked=\"" + escape(locked) + "\" axes=\"" + axes +
                  "\" hold=\"0.2\" record=\"" + escape(record) + "\" record_frame=\"" + escape(record_frame) + "\"/>",
              [&] {
                const world::Pose now = simulation->tcpPose();
                if (const double dt = toSeconds(cell.clock().now() - last_time); dt > 0.0) {
                  fastest = std::max(fastest, (now.translation() - last.translation()).norm() / dt);
                }
                last = now;
                last_time = cell.clock().now();
                if (toSeconds(cell.clock().now() - start) < *seconds) {
                  simulation->setHandWrench(hand);
                  arm->holdFreeDrive(std::chrono::milliseconds(100));
                  if (const std::string why = arm->freeDriveStatus().blocked; !why.empty()) {
                    blocked = why;
                  }
                } else {
                  simulation->setHandWrench({});
                }
              });
  simulation->setHandWrench({});
  const world::Pose after = simulation->tcpPose();
  const Eigen::Vector3d moved = after.translation() - before.translation();
  std::printf("the tool moved %.4f %.4f %.4f m and turned %.1f deg, at %.3f m/s at most%s%s\n", moved.x(), moved.y(),
              moved.z(), world::rotationAngle(before, after) * 180.0 / M_PI, fastest,
              ok && !blocked.empty() ? "; held back: " : "", ok ? blocked.c_str() : "");
}

/// One command line; returns false to end the session.
bool handle(workcell::Workcell& cell, const std::string& line) {
  std::istringstream words(line);
  std::vector<std::string> w;
  for (std::string word; words >> word;) {
    w.push_back(word);
  }
  if (w.empty() || w[0].starts_with("#")) {
    return true;
  }
  // Names end up in the waypoint file (JSON, UTF-8): say so here, not as an error in the plan
  // the command becomes.
  if (const auto bad = invalidUtf8At(line)) {
    std::printf("error: the command is not UTF-8 text (byte %zu of the line, 0x%02X): names are UTF-8\n", *bad + 1,
                static_cast<unsigned>(static_cast<unsigned char>(line[*bad])));
    return true;
  }
  const std::string& command = w[0];
  if (command == "quit" || command == "exit") {
    return false;
  }
  if (command == "help") {
    std::printf("%s", helpText(&cell).c_str());
  } else if (command == "where") {
    printWhere(cell);
  } else if (command == "list") {
    printWaypoints(cell);
  } else if (command == "home") {
    runNode(cell, "<Home/>");
  } else if (command == "detect") {
    runNode(cell, "<DetectObjects/>");
  } else if (command == "objects") {
    cell.beforeTick();
    const auto& world = cell.components().world();
    int count = 0;
    for (const world::Predicate* is_a : world.predicates("is_a")) {
      if (is_a->args.size() == 2) {
        if (const auto pose = world.worldPose(is_a->args[0])) {
          const auto& p = pose->translation();
          std::printf("  %-12s %-6s at %.3f %.3f %.3f\n", is_a->args[0].c_str(), is_a->args[1].c_str(), p.x(), p.y(),
                      p.z());
          ++count;
        }
      }
    }
    if (count == 0) {
      std::printf("  (no parts detected: try 'detect')\n");
    }
  } else if (command == "grasp" && w.size() == 3) {
    runNode(cell, "<TeachGrasp object_class=\"" + escape(w[1]) + "\" grasp=\"" + escape(w[2]) + "\"/>");
  } else if (command == "open" || command == "close") {
    runNode(cell, command == "open" ? "<Open/>" : "<Close/>");
  } else if (command == "jog" && w.size() >= 3 && w[1] == "joint" && w.size() == 4) {
    runNode(cell, "<JogJoint joint=\"" + escape(w[2]) + "\" degrees=\"" + escape(w[3]) + "\"/>");
  } else if (command == "jog" && w.size() >= 3) {
    const std::string frame = w.size() > 3 && w[3] == "tool" ? "tool" : "world";
    runNode(cell,
            "<JogCartesian axis=\"" + escape(w[1]) + "\" amount=\"" + escape(w[2]) + "\" frame=\"" + frame + "\"/>");
  } else if (command == "teach" && w.size() >= 2) {
    std::string kind = "pose";
    std::string frame = "world";
    for (std::size_t i = 2; i < w.size(); ++i) {
      if (w[i] == "joints") {
        kind = "joints";
      } else if (w[i] == "in" && i + 1 < w.size()) {
        frame = w[++i];
      }
    }
    runNode(cell, "<Teach waypoint=\"" + escape(w[1]) + "\" kind=\"" + kind + "\" frame=\"" + escape(frame) + "\"/>");
  } else if (command == "move" && w.size() >= 2) {
    const std::string speed = w.size() > 2 ? " speed=\"" + escape(w[2]) + "\"" : "";
    runNode(cell, "<Move waypoint=\"" + escape(w[1]) + "\"" + speed + "/>");
  } else if (command == "rename" && w.size() == 3) {
    runNode(cell, "<RenameWaypoint waypoint=\"" + escape(w[1]) + "\" new_name=\"" + escape(w[2]) + "\"/>");
  } else if (command == "delete" && w.size() == 2) {
    runNode(cell, "<DeleteWaypoint waypoint=\"" + escape(w[1]) + "\"/>");
  } else if (command == "trajectories") {
    const auto* arm = dynamic_cast<const arm::ArmComponent*>(cell.components().provider("FollowTrajectory"));
    const auto trajectories = arm != nullptr ? arm->waypoints().trajectories() : std::vector<arm::RecordedTrajectory>{};
    for (const arm::RecordedTrajectory& t : trajectories) {
      std::printf("  %-20s in %s: %zu poses, %.3f m in %.2f s\n", t.name.c_str(), t.frame.c_str(), t.poses.size(),
                  t.length(), t.duration());
    }
    if (trajectories.empty()) {
      std::printf("  (no trajectories recorded yet: drag ... record NAME)\n");
    }
  } else if (command == "replay" && w.size() >= 2) {
    std::string node = "<FollowTrajectory trajectory=\"" + escape(w[1]) + "\"";
    for (std::size_t i = 2; i < w.size(); ++i) {
      if (w[i] == "in" && i + 1 < w.size()) {
        node += " frame=\"" + escape(w[++i]) + "\"";
      } else {
        node += " speed=\"" + escape(w[i]) + "\"";
      }
    }
    runNode(cell, node + "/>");
  } else if (command == "drag" && (w.size() == 3 || w.size() == 4) && w[1] == "stroke") {
    dragStroke(cell, w);
  } else if (command == "drag" && w.size() == 4 && w[1] == "random") {
    dragRandom(cell, w);
  } else if (command == "drag" && w.size() >= 5) {
    drag(cell, w);
  } else if (command == "snapshot" && w.size() == 2) {
    if (cell.simulation() == nullptr) {
      std::printf("failed: '%s' is not a simulated workcell\n", cell.name().c_str());
    } else {
      try {
        writePng(w[1], cell.simulation()->renderImage("overview", 1280, 960));
        std::printf("wrote %s\n", w[1].c_str());
      } catch (const std::exception& e) {
        std::printf("failed: %s\n", e.what());
      }
    }
  } else {
    std::printf("unknown or incomplete command '%s' (type 'help')\n", line.c_str());
  }
  return true;
}

}  // namespace

void addSmartMoveCommands(CLI::App& app, int& exit_code) {
  CLI::App* smartmove = app.add_subcommand("smartmove", "SmartMove set-up");
  smartmove->require_subcommand(1);
  auto options = std::make_shared<workcell::WorkcellOptions>();
  auto object_class = std::make_shared<std::string>();
  auto grasp = std::make_shared<std::string>();
  auto at = std::make_shared<std::string>();
  CLI::App* teach = smartmove->add_subcommand(
      "teach",
      "Teach a grasp by demonstration: detect the parts, move the gripper around one (to a taught "
      "waypoint), store how it holds the part");
  teach->add_option("class", *object_class, "object class (e.g. node)")->required();
  teach->add_option("name", *grasp, "name of the grasp (e.g. top)")->required();
  teach->add_option("--at", *at, "a taught waypoint where the gripper is around a part")->required();
  teach->add_option("-w,--workcell", options->name, "workcell")->capture_default_str();
  teach->add_option("--scene", options->scene, "simulated workcells: scene file")->check(CLI::ExistingFile);
  teach->add_option("--waypoints", options->waypoints, "waypoint file")->check(CLI::ExistingFile);
  teach->callback([=, &exit_code] {
    for (const std::string* name : {object_class.get(), grasp.get(), at.get()}) {
      if (invalidUtf8At(*name)) {  // it ends up in the grasp file (JSON, UTF-8)
        std::cerr << "error: '" << *name << "' is not UTF-8 text: names are UTF-8\n";
        exit_code = 2;
        return;
      }
    }
    std::unique_ptr<workcell::Workcell> cell;
    try {
      cell = workcell::makeWorkcell(*options);
    } catch (const std::exception& e) {
      std::cerr << "error: " << e.what() << "\n";
      exit_code = 2;
      return;
    }
    const bool ok = runNode(*cell, "<Sequence><Home/><DetectObjects/><Move waypoint=\"" + escape(*at) +
                                       "\"/><TeachGrasp object_class=\"" + escape(*object_class) + "\" grasp=\"" +
                                       escape(*grasp) + "\"/></Sequence>");
    if (ok) {
      std::printf("taught grasp '%s' for class '%s' (kept in %s)\n", grasp->c_str(), object_class->c_str(),
                  workcell::defaultGraspFile(cell->name()).c_str());
    }
    exit_code = ok ? 0 : 1;
  });
}

void addTeachCommand(CLI::App& app, int& exit_code) {
  auto options = std::make_shared<workcell::WorkcellOptions>();
  CLI::App* teach = app.add_subcommand(
      "teach", "Jog the arm and teach waypoints, interactively (commands from standard input; 'help' lists them)");
  teach->add_option("-w,--workcell", options->name, "workcell")->capture_default_str();
  teach->add_option("--scene", options->scene, "simulated workcells: scene file")->check(CLI::ExistingFile);
  teach->add_option(
      "--waypoints", options->waypoints,
      "waypoint file to read and write (default " + workcell::defaultWaypointFile("<workcell>").string() + ")");
  teach->footer(helpText(nullptr));
  teach->callback([options, &exit_code] {
    std::unique_ptr<workcell::Workcell> cell;
    try {
      cell = workcell::makeWorkcell(*options);
    } catch (const std::exception& e) {
      std::cerr << "error: " << e.what() << "\n";
      exit_code = 2;
      return;
    }
    const bool interactive = ::isatty(STDIN_FILENO) != 0;
    if (interactive) {
      std::printf("costar teach on %s. Type 'help' for the commands.\n", cell->description().c_str());
    }
    std::string line;
    while (true) {
      if (interactive) {
        std::printf("costar> ");
        std::fflush(stdout);
      }
      if (!std::getline(std::cin, line) || !handle(*cell, line)) {
        break;
      }
      std::fflush(stdout);
    }
    exit_code = 0;
  });
}

}  // namespace costar::cli
