#include "trials/disturbance.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>

#include <Eigen/Geometry>

#include "sim/power_tool.h"
#include "sim/scene.h"
#include "sim/simulation.h"
#include "smartmove/footprint.h"

namespace costar::trials {

namespace {

constexpr double kApproachRadius = 0.03;  // m, tool centre from the part's centre, in x and y
constexpr double kApproachLow = 0.04;     // m above the part's centre
constexpr double kApproachHigh = 0.09;
constexpr double kOnTable = 0.06;  // m: a part's centre below this rests on the table
constexpr double kNudgeMin = 0.01;
constexpr double kNudgeMax = 0.03;
constexpr double kTurnMaxDeg = 15.0;
constexpr double kNudgeGap = 0.002;  // m kept between the nudged part's footprint and others'
constexpr int kNudgeDraws = 32;
constexpr double kAddGap = 0.03;            // m between an added part's footprint and others'
constexpr double kAddToolClearance = 0.12;  // m from the tool's centre, in x and y
constexpr int kAddDraws = 64;

std::string format(const char* pattern, auto... values) {
  char text[256];
  std::snprintf(text, sizeof text, pattern, values...);
  return text;
}

const world::ObjectClass* classOf(const sim::Simulation& simulation, const std::string& name) {
  for (const auto& object_class : simulation.objectClasses()) {
    if (object_class.name == name) {
      return &object_class;
    }
  }
  return nullptr;
}

}  // namespace

DisturbanceSpec parseDisturbance(std::string_view text) {
  DisturbanceSpec spec;
  spec.text = std::string(text);
  const std::string where = "disturbance '" + spec.text + "': ";
  const std::size_t at = text.find('@');
  const std::string_view kind = text.substr(0, at);
  if (kind == "nudge") {
    spec.kind = DisturbanceKind::kNudge;
  } else if (kind == "take-away") {
    spec.kind = DisturbanceKind::kTakeAway;
  } else if (kind == "drop-frame") {
    spec.kind = DisturbanceKind::kDropFrame;
  } else if (kind == "add") {
    spec.kind = DisturbanceKind::kAdd;
  } else if (kind == "take-tool") {
    spec.kind = DisturbanceKind::kTakeTool;
  } else {
    throw std::invalid_argument(where + "unknown kind '" + std::string(kind) +
                                "' (known: nudge, take-away, drop-frame, add, take-tool)");
  }
  if (at != std::string_view::npos && spec.kind == DisturbanceKind::kTakeTool) {
    const std::string_view when = text.substr(at + 1);
    constexpr std::string_view kAt = "at=";
    constexpr std::string_view kWithin = "within=";
    const auto seconds = [&where](const std::string& number, const char* what) {
      std::size_t used = 0;
      double value = -1.0;
      try {
        value = std::stod(number, &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (number.empty() || used != number.size() || !(value >= 0.0 && value <= 1e4)) {
        throw std::invalid_argument(where + what + " needs a number of seconds from 0 to 10000, not '" + number + "'");
      }
      return value;
    };
    if (when.substr(0, kAt.size()) == kAt) {
      spec.at_seconds = seconds(std::string(when.substr(kAt.size())), "at=SECONDS");
    } else if (when.substr(0, kWithin.size()) == kWithin) {
      const std::string_view window = when.substr(kWithin.size());
      const std::size_t dash = window.find('-');
      if (dash == std::string_view::npos) {
        throw std::invalid_argument(where + "within=A-B needs two numbers of seconds joined by '-', not '" +
                                    std::string(window) + "'");
      }
      spec.within = {seconds(std::string(window.substr(0, dash)), "within=A-B"),
                     seconds(std::string(window.substr(dash + 1)), "within=A-B")};
      if (!(spec.within.first < spec.within.second)) {
        throw std::invalid_argument(where + "within=A-B needs A before B, not '" + std::string(window) + "'");
      }
    } else {
      throw std::invalid_argument(where + "expected @at=SECONDS or @within=A-B after take-tool, not '@" +
                                  std::string(when) + "'");
    }
    return spec;
  }
  if (at != std::string_view::npos) {
    const std::string_view when = text.substr(at + 1);
    if (spec.kind == DisturbanceKind::kDropFrame) {
      throw std::invalid_argument(where + "drop-frame takes no @ (its frame is drawn from the seed)");
    }
    constexpr std::string_view kGrasp = "grasp=";
    if (when.substr(0, kGrasp.size()) != kGrasp) {
      throw std::invalid_argument(where + "expected @grasp=N after the kind, not '@" + std::string(when) + "'");
    }
    const std::string number(when.substr(kGrasp.size()));
    std::size_t used = 0;
    int value = 0;
    try {
      value = std::stoi(number, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (number.empty() || used != number.size() || value < 1 || value > 100) {
      throw std::invalid_argument(where + "grasp=N needs a whole number from 1 to 100, not '" + number + "'");
    }
    spec.grasp = value;
  }
  return spec;
}

std::string disturbanceGrammar() {
  return "KIND[@grasp=N], drawn from each trial's seed:\n"
         "  nudge       the part about to be grasped is pushed 1-3 cm and turned up to 15 deg as the gripper goes "
         "down\n"
         "  take-away   the part about to be grasped is taken off the table\n"
         "  drop-frame  one camera frame of a DetectObjects comes empty\n"
         "  add         a part (node or link, drawn) is put on the table at a free place as the gripper goes down to "
         "another\n"
         "  take-tool   the power tool is taken (from the gripper or its stand) 1-19 s into the trial, within the "
         "polishing plan's span (@within=A-B: A-B s; @at=S: at S s), and given back onto its stand 2-8 s later\n"
         "  @grasp=N    the N-th approach to a part (default: the 1st to 3rd, drawn)";
}

Disturber::Disturber(std::vector<DisturbanceSpec> specs, std::uint64_t seed)
    : random_(seed * 0x9E3779B97F4A7C15ULL + 0x5EEDD15ULL) {
  for (DisturbanceSpec& spec : specs) {
    if (spec.kind == DisturbanceKind::kDropFrame) {
      const int frame = std::uniform_int_distribution<int>(1, kFramesDrawn)(random_);
      faults_.push_back("drop-frame:camera@op=" + std::to_string(frame));
      continue;
    }
    Pending pending;
    if (spec.kind == DisturbanceKind::kTakeTool) {
      pending.take_at = spec.at_seconds.value_or(
          std::uniform_real_distribution<double>(spec.within.first, spec.within.second)(random_));
      pending.away_for = std::uniform_real_distribution<double>(2.0, 8.0)(random_);
    } else {
      pending.approach = spec.grasp > 0 ? spec.grasp : std::uniform_int_distribution<int>(1, 3)(random_);
    }
    pending.spec = std::move(spec);
    pending_.push_back(std::move(pending));
  }
}

void Disturber::watch(sim::Simulation& simulation) {
  bool approaches = false;
  for (Pending& pending : pending_) {
    if (pending.spec.kind == DisturbanceKind::kTakeTool) {
      if (!pending.done) {
        takeTool(simulation, pending);
      }
    } else {
      approaches = true;
    }
  }
  if (!approaches) {
    return;
  }
  const world::Pose tcp = simulation.tcpPose();
  const sim::FingerState fingers = simulation.fingers();
  const bool descending = tcp.translation().z() < last_tcp_z_ - 1e-5;
  last_tcp_z_ = tcp.translation().z();
  std::string approached;
  if (descending && !fingers.pads_in_contact && fingers.opening > 0.005) {
    for (const sim::PartState& part : simulation.parts()) {
      const Eigen::Vector3d offset = tcp.translation() - part.pose.translation();
      if (part.pose.translation().z() < kOnTable && part.linear_velocity.norm() < 0.01 &&
          offset.head<2>().norm() < kApproachRadius && offset.z() > kApproachLow && offset.z() < kApproachHigh) {
        approached = part.name;
        break;
      }
    }
  }
  if (!approached.empty() && approached != approaching_) {
    ++approaches_;
    for (Pending& pending : pending_) {
      if (!pending.done && pending.spec.kind != DisturbanceKind::kTakeTool && pending.approach == approaches_) {
        pending.done = true;
        if (pending.spec.kind == DisturbanceKind::kNudge) {
          nudge(simulation, pending, approached);
        } else if (pending.spec.kind == DisturbanceKind::kAdd) {
          add(simulation, pending);
        } else {
          takeAway(simulation, pending, approached);
        }
      }
    }
  }
  approaching_ = approached;
}

void Disturber::nudge(sim::Simulation& simulation, Pending& pending, const std::string& name) {
  const std::vector<sim::PartState> parts = simulation.parts();
  const auto part = std::find_if(parts.begin(), parts.end(), [&](const auto& p) { return p.name == name; });
  const world::ObjectClass* object_class = classOf(simulation, part->object_class);
  std::uniform_real_distribution<double> distance(kNudgeMin, kNudgeMax);
  std::uniform_real_distribution<double> direction(-std::numbers::pi, std::numbers::pi);
  std::uniform_real_distribution<double> turn(-kTurnMaxDeg, kTurnMaxDeg);
  // The first draw that keeps clear of every other part (a person nudges a part into free
  // space, not onto a neighbour).
  for (int draw = 0; draw < kNudgeDraws; ++draw) {
    const double d = distance(random_);
    const double angle = direction(random_);
    const double degrees = turn(random_);
    world::Pose moved = part->pose;
    moved.linear() = Eigen::AngleAxisd(degrees * std::numbers::pi / 180.0, Eigen::Vector3d::UnitZ()) * moved.linear();
    moved.translation() += Eigen::Vector3d(d * std::cos(angle), d * std::sin(angle), 0.0);
    bool clear = true;
    if (object_class != nullptr) {
      for (const sim::PartState& other : parts) {
        const world::ObjectClass* other_class = classOf(simulation, other.object_class);
        if (other.name == name || other_class == nullptr || other.pose.translation().z() > 0.2) {
          continue;
        }
        if (smartmove::footprintGap(*object_class, moved, *other_class, other.pose) < kNudgeGap) {
          clear = false;
          break;
        }
      }
    }
    if (clear) {
      simulation.movePart(name, moved);
      pending.event = format("nudge %s: %.0f mm, %+.0f deg at %.1f s (approach %d)", name.c_str(), d * 1000.0, degrees,
                             toSeconds(simulation.time().time_since_epoch()), pending.approach);
      return;
    }
  }
  pending.event = format("nudge %s: no free spot 1-3 cm away (approach %d)", name.c_str(), pending.approach);
}

void Disturber::takeAway(sim::Simulation& simulation, Pending& pending, const std::string& name) {
  // Off the table, out of the robot's reach and the camera's view.
  const double y = -1.2 - 0.15 * taken_++;
  const auto parts = simulation.parts();
  const auto part = std::find_if(parts.begin(), parts.end(), [&](const auto& p) { return p.name == name; });
  world::Pose away = part->pose;
  away.translation() = Eigen::Vector3d(0.4, y, part->pose.translation().z());
  simulation.movePart(name, away);
  pending.event = format("take-away %s at %.1f s (approach %d)", name.c_str(),
                         toSeconds(simulation.time().time_since_epoch()), pending.approach);
}

int Disturber::additions() const {
  return static_cast<int>(std::count_if(pending_.begin(), pending_.end(), [](const Pending& pending) {
    return pending.spec.kind == DisturbanceKind::kAdd;
  }));
}

void Disturber::add(sim::Simulation& simulation, Pending& pending) {
  const std::vector<sim::PartState> parts = simulation.parts();
  std::vector<const sim::PartState*> spares;
  for (const sim::PartState& part : parts) {
    if (sim::Simulation::parked(part) && classOf(simulation, part.object_class) != nullptr) {
      spares.push_back(&part);
    }
  }
  if (spares.empty()) {
    pending.event = format("add: no spare part is parked off the table (approach %d)", pending.approach);
    return;
  }
  const sim::PartState& spare = *spares[std::uniform_int_distribution<std::size_t>(0, spares.size() - 1)(random_)];
  const world::ObjectClass& object_class = *classOf(simulation, spare.object_class);
  // Anywhere on the reachable table the camera sees, clear of every part on it and of the
  // gripper going down (a person puts a part where there is room, not under the robot).
  const sim::Region table = sim::defaultRegions().at("table");
  const Eigen::Vector2d tool = simulation.tcpPose().translation().head<2>();
  std::uniform_real_distribution<double> x(table.min.x(), table.max.x());
  std::uniform_real_distribution<double> y(table.min.y(), table.max.y());
  std::uniform_real_distribution<double> yaw(-std::numbers::pi, std::numbers::pi);
  for (int draw = 0; draw < kAddDraws; ++draw) {
    world::Pose placed = world::Pose::Identity();
    const double degrees = yaw(random_) * 180.0 / std::numbers::pi;
    placed.linear() =
        Eigen::AngleAxisd(degrees * std::numbers::pi / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    placed.translation() = Eigen::Vector3d(x(random_), y(random_), object_class.rest_height);
    bool clear = (placed.translation().head<2>() - tool).norm() > kAddToolClearance;
    for (const sim::PartState& other : parts) {
      const world::ObjectClass* other_class = classOf(simulation, other.object_class);
      if (!clear || other.name == spare.name || other_class == nullptr || sim::Simulation::parked(other)) {
        continue;
      }
      clear = smartmove::footprintGap(object_class, placed, *other_class, other.pose) >= kAddGap;
    }
    if (clear) {
      simulation.movePart(spare.name, placed);
      pending.event = format("add %s at (%.2f, %.2f) m, %+.0f deg at %.1f s (approach %d)", spare.name.c_str(),
                             placed.translation().x(), placed.translation().y(), degrees,
                             toSeconds(simulation.time().time_since_epoch()), pending.approach);
      return;
    }
  }
  pending.event = format("add %s: no free place on the table (approach %d)", spare.name.c_str(), pending.approach);
}

void Disturber::takeTool(sim::Simulation& simulation, Pending& pending) {
  const double now = toSeconds(simulation.time().time_since_epoch());
  sim::SimPowerTool* tool = simulation.powerTool();
  if (tool == nullptr || !tool->hasTool()) {
    pending.done = true;
    pending.event = "take-tool: not applied: the scene has no power tool";
    return;
  }
  if (!pending.taken && now >= pending.take_at) {
    const tool::PowerToolReading reading = tool->read();
    const char* from = reading.held ? "out of the gripper" : reading.docked ? "off its stand" : "from where it was";
    tool->take();
    pending.taken = true;
    pending.take_at = now;
    pending.event = format("take-tool: taken %s (%s) at %.1f s", from, reading.powered ? "running" : "off", now);
  } else if (pending.taken && now >= pending.take_at + pending.away_for) {
    tool->giveBack();
    pending.done = true;
    pending.event += format(", given back onto its stand at %.1f s", now);
  }
}

std::vector<std::string> Disturber::events() const {
  std::vector<std::string> lines;
  for (const Pending& pending : pending_) {
    if (pending.spec.kind == DisturbanceKind::kTakeTool && !pending.done) {
      lines.push_back(pending.taken ? pending.event + " and kept until the trial ended"
                                    : format("take-tool: not applied: the trial ended before %.1f s", pending.take_at));
      continue;
    }
    lines.push_back(pending.done
                        ? pending.event
                        : pending.spec.text + ": not applied: no approach " + std::to_string(pending.approach) + " (" +
                              std::to_string(approaches_) + " approach(es) to a part)");
  }
  for (const std::string& fault : faults_) {
    lines.push_back(fault);
  }
  return lines;
}

}  // namespace costar::trials
