// The Arm component's force sensing and force-controlled operations (docs/FORCE.md):
//   Tare             zeroes the wrist sensor (nothing touching the tool, the arm still)
//   MoveUntilContact a guarded approach: the tool moves in a direction at a speed until it
//                    pushes with the force, then keeps pushing with it
//   PressAndFollow   presses with a force along the tool's axis and follows a path of
//                    waypoints, compliant with a stiffness in the other directions; resumes
//                    where an interrupted one stopped, and skips waypoints already pressed
//   ReleaseContact   stops pressing and backs the tool away
//   ForgetPressed    forgets which waypoints were pressed (a new workpiece)
// Each is made of the controller's Cartesian motions (arm/cartesian_controller.h) and the arm's
// joint motions. Safety: a force above max_force stops the motion (the controller's stop
// condition) and the operation fails naming the force; a pressing operation whose force falls
// below max(1 N, 30 % of its force) for three polls in a row (the tool lifted away, the surface
// ended) stops and fails; the contact force's torques must stay within half of every joint's
// motor torque at every waypoint, checked before anything moves.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <set>
#include <stdexcept>

#include "arm/arm_component.h"
#include "arm/motion_planner.h"

namespace costar::arm {

using component::OperationResult;
using component::ParamMap;
using component::ParamSpec;
using component::ValueType;

struct ArmComponent::Pressing {
  /// The waypoints the tool pressed through since the last ForgetPressed.
  std::set<std::string> pressed;
  /// Where the last PressAndFollow stopped, while it has not finished its path: its waypoints
  /// and how far along them (m, the full path's arc length).
  struct Interrupted {
    std::vector<std::string> path;
    double arc = 0.0;
  };
  std::optional<Interrupted> interrupted;
  /// The controller's motion that presses now (0: none) and its force axis in the world.
  std::uint64_t motion = 0;
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();
};

namespace {

/// The joints move slower than this (rad/s) for kStillTime: the arm is still.
constexpr double kStillSpeed = 0.005;
constexpr Duration kStillTime = std::chrono::milliseconds(150);
constexpr Duration kStillTimeout = std::chrono::seconds(3);
/// Polls in a row with the force below the contact-lost threshold that end a press.
constexpr int kLostPolls = 3;
/// How far the controller may move the path along the force axis before a press gives up.
constexpr double kMaxPathOffset = 0.03;  // m
/// Speed (m/s) the tool goes down at to meet the surface in PressAndFollow.
constexpr double kDescentSpeed = 0.02;
/// Contact the force's torques may use of each joint's motor torque.
constexpr double kTorqueShare = 0.5;
/// A pressing path's lines are checked in reach every kReachStep (m), the joints turning at most
/// kReachJump (rad) from one point to the next.
constexpr double kReachStep = 0.01;
constexpr double kReachJump = 0.2;
/// The Cartesian paths' acceleration and corner blend.
constexpr double kPathAcceleration = 0.25;      // m/s^2
constexpr double kPathBlend = 0.01;             // m
constexpr double kRotationalStiffness = 200.0;  // N m/rad

std::unique_ptr<component::RunningOperation> finishedWith(OperationResult result) {
  return std::make_unique<component::FinishedOperation>(std::move(result));
}

std::string newtons(double value) { return formatNumber("%.1f N", value); }

/// An operation made of steps, each polled until it is done.
struct Step {
  enum class Kind { kRunning, kNext, kDone, kFailed };
  Kind kind = Kind::kRunning;
  std::string reason;
  nlohmann::json data;
  static Step running() { return {}; }
  static Step next() { return {Kind::kNext, {}, {}}; }
  static Step done(nlohmann::json data = {}) { return {Kind::kDone, {}, std::move(data)}; }
  static Step failed(std::string reason) { return {Kind::kFailed, std::move(reason), {}}; }
};

class StepOperation final : public component::RunningOperation {
 public:
  using StepFunction = std::function<Step()>;
  StepOperation(std::vector<StepFunction> steps, std::function<void()> on_end)
      : steps_(std::move(steps)), on_end_(std::move(on_end)) {}

  OperationResult poll() override {
    if (result_) {
      return *result_;
    }
    while (index_ < steps_.size()) {
      Step step;
      try {
        step = steps_[index_]();
      } catch (const std::exception& e) {
        step = Step::failed(e.what());
      }
      switch (step.kind) {
        case Step::Kind::kRunning:
          return OperationResult::running();
        case Step::Kind::kNext:
          ++index_;
          continue;
        case Step::Kind::kDone:
          return end(OperationResult::success(std::move(step.data)));
        case Step::Kind::kFailed:
          return end(OperationResult::failure(std::move(step.reason)));
      }
    }
    return end(OperationResult::success());
  }

  void cancel() override {
    if (!result_) {
      end(OperationResult::failure("cancelled"));
    }
  }

 private:
  OperationResult end(OperationResult result) {
    result_ = result;
    if (on_end_) {
      on_end_();
    }
    return result;
  }

  std::vector<StepFunction> steps_;
  std::function<void()> on_end_;
  std::size_t index_ = 0;
  std::optional<OperationResult> result_;
};

/// A direction a technician names, in the world (PREDICATES.md's axes: x away from the robot,
/// y to its left, z up), or along the tool's axis.
Eigen::Vector3d directionNamed(const std::string& name, const world::Pose& tool) {
  if (name == "down") {
    return -Eigen::Vector3d::UnitZ();
  }
  if (name == "up") {
    return Eigen::Vector3d::UnitZ();
  }
  if (name == "forward") {
    return Eigen::Vector3d::UnitX();
  }
  if (name == "backward") {
    return -Eigen::Vector3d::UnitX();
  }
  if (name == "left") {
    return Eigen::Vector3d::UnitY();
  }
  if (name == "right") {
    return -Eigen::Vector3d::UnitY();
  }
  return tool.linear().col(2);  // "tool": the way the tool points
}

ParamSpec number(const char* name, const std::string& description, double value, double min, double max) {
  ParamSpec spec{name, ValueType::kDouble, description, value};
  spec.min = min;
  spec.max = max;
  return spec;
}

/// The force must stay below the limit that stops the motion (checked again when an operation
/// starts, whoever starts it).
std::string forceBelowLimit(const ParamMap& params) {
  const double force = params.at("force").asDouble();
  const double limit = params.at("max_force").asDouble();
  if (force >= limit) {
    return "the force (" + newtons(force) + ") must be below max_force (" + newtons(limit) +
           "), the force that stops the motion";
  }
  return {};
}

/// Why MoveUntilContact refuses a speed above ArmComponent::kMaxApproachSpeed (empty: it does not).
std::string approachSpeedProblem(double speed) {
  if (speed <= ArmComponent::kMaxApproachSpeed) {
    return {};
  }
  return formatNumber("%g m/s", speed) + " is faster than a guarded approach may touch at (" +
         formatNumber("%g m/s", ArmComponent::kMaxApproachSpeed) +
         "): the arm's momentum alone would push past the force on a hard surface; move close first (MoveToPose), "
         "then approach";
}

/// A force the operation keeps: below the limit that stops the motion (a constraint kept in the
/// stored descriptions, so that `costar validate` without the robot checks it too).
ParamSpec keptForce(const std::string& description, double value) {
  ParamSpec spec = number("force", description, value, 1.0, ArmComponent::kMaxContactForce);
  spec.less_than = "max_force";
  return spec;
}

}  // namespace

Wrench ArmComponent::toolWrench(const Wrench& sensor) const {
  const world::Pose sensor_in_flange = force_.sensor->inFlange();
  const world::Pose sensor_in_tool = config_.tcp_in_flange.inverse() * sensor_in_flange;
  Wrench tool;
  tool.force = sensor_in_tool.linear() * sensor.force;
  tool.torque = sensor_in_tool.linear() * sensor.torque + sensor_in_tool.translation().cross(tool.force);
  return tool;
}

void ArmComponent::declareForceOperations(component::ComponentDescription& description,
                                          component::OperationTable& operations) {
  if (force_.sensor == nullptr) {
    return;
  }
  pressing_ = std::make_shared<Pressing>();
  description.inputs.push_back("wrist_wrench");
  description.symbols.push_back({"wrench", world::SymbolKind::kWrench,
                                 "what the tool pushes its surroundings with (N, N m), in the tool frame about the "
                                 "tool centre point, from the wrist force/torque sensor"});
  description.predicates.push_back(
      {"in_contact", 0,
       "the wrist sensor reads more than 4 N (the tool touches something, or the arm accelerates it)"});
  operations.add({"Tare",
                  "Zeroes the wrist force sensor: nothing may touch the tool, the arm comes to rest first.",
                  {},
                  component::OperationKind::kKnowledge},
                 [this](const ParamMap&) { return tare(); });
  if (force_.controller == nullptr) {
    return;
  }
  description.predicates.push_back(
      {"pressed_at", 1, "pressed_at(w): a PressAndFollow pressed the tool through waypoint w (until ForgetPressed)"});

  ParamSpec direction{"direction",
                      ValueType::kString,
                      "where the tool moves: along its own axis (tool), or down, up, forward (away from the robot), "
                      "backward, left, right (the robot's)",
                      std::string("tool"),
                      {"tool", "down", "up", "forward", "backward", "left", "right"}};
  const ParamSpec max_force =
      number("max_force", "a force above this (N) stops the arm and fails the operation", 40.0, 5.0, kMaxForceLimit);
  ParamSpec path{"path", ValueType::kStringList, "the waypoints to follow, in order (taught touching the surface)", {}};
  path.choices_from = "waypoint";
  path.validate = [](std::string_view text) -> std::string {
    return text.find_first_not_of("; ") == std::string_view::npos ? "name at least one waypoint" : "";
  };
  ParamSpec approach_speed =
      number("speed", "how fast the tool approaches (m/s); faster, the touch itself would push past the force", 0.01,
             0.002, kMaxApproachSpeed);
  approach_speed.validate = [](std::string_view text) {
    char* end = nullptr;
    const std::string written(text);
    const double speed = std::strtod(written.c_str(), &end);
    return end != written.c_str() ? approachSpeedProblem(speed) : std::string();
  };
  component::OperationSpec until_contact{
      "MoveUntilContact",
      "Moves the tool in a direction until it pushes with the force, then keeps pushing with it (a guarded approach).",
      {direction, keptForce("the force (N) that stops the approach and is kept", 5.0), approach_speed,
       number("distance", "the farthest it goes looking for contact (m)", 0.15, 0.005, 0.5), max_force}};
  operations.add(std::move(until_contact), [this](const ParamMap& params) { return moveUntilContact(params); });
  component::OperationSpec press{
      "PressAndFollow",
      "Presses the tool onto the surface with the force along its axis and follows the waypoints, giving way in the "
      "other directions; resumes where it stopped and skips the waypoints already pressed.",
      {path,
       keptForce("the force (N) the tool presses with, along its axis", 10.0),
       number("speed", "how fast the tool follows the path (m/s)", 0.03, 0.005, 0.2),
       number("stiffness", "how firmly the tool holds the path across its axis (N/m)", 2000.0, 100.0,
              CartesianImpedance::kMaxStiffness),
       max_force,
       number("approach", "the tool comes down from this far above the path's start (m)", 0.05, 0.01, 0.2),
       {"resume", ValueType::kBool, "go on where an interrupted PressAndFollow on this path stopped", true},
       {"tare", ValueType::kBool, "zero the force sensor above the path's start before touching", true}}};
  operations.add(std::move(press), [this](const ParamMap& params) { return pressAndFollow(params); });
  ParamSpec back = number("distance", "how far the tool backs away (m)", 0.05, 0.005, 0.3);
  const ParamSpec speed = number("speed", "how fast the tool backs away (m/s)", 0.05, 0.005, 0.25);
  operations.add({"ReleaseContact",
                  "Stops pressing and backs the tool away from what it touches, against the direction it pressed in.",
                  {back, speed}},
                 [this](const ParamMap& params) { return releaseContact(params); });
  operations.add({"ForgetPressed",
                  "Forgets which waypoints were pressed and where a PressAndFollow stopped (a new workpiece).",
                  {},
                  component::OperationKind::kKnowledge},
                 [this](const ParamMap&) {
                   pressing_->pressed.clear();
                   pressing_->interrupted.reset();
                   return finishedWith(OperationResult::success());
                 });
}

void ArmComponent::reportForce(world::Report& report) const {
  if (force_.sensor == nullptr) {
    return;
  }
  const ForceTorqueReading reading = force_.sensor->read();
  if (!reading.wrench.force.allFinite() || !reading.wrench.torque.allFinite()) {
    throw std::runtime_error("the wrist force sensor reads a value that is not a number");
  }
  const Wrench wrench = toolWrench(reading.wrench);
  report.symbols.push_back({"wrench", "", clock_.now(), world::WrenchValue{"tool", wrench.force, wrench.torque}});
  if (wrench.force.norm() > kContactForce) {
    report.predicates.push_back({"in_contact", {}, true, ""});
  }
  if (pressing_) {
    for (const std::string& name : pressing_->pressed) {
      report.predicates.push_back({"pressed_at", {name}, true, ""});
    }
  }
}

namespace {

/// Waits until the arm is still (kStillTime), failing after kStillTimeout.
class StillWait {
 public:
  StillWait(const ArmDriver& driver, const Clock& clock) : driver_(driver), clock_(clock) {}
  Step poll(const std::string& what) {
    const TimePoint now = clock_.now();
    if (!began_) {
      began_ = now;
    }
    const ArmState state = driver_.read();
    if (maxAbs(state.velocity) > kStillSpeed) {
      still_since_.reset();
    } else if (!still_since_) {
      still_since_ = now;
    }
    if (still_since_ && now - *still_since_ >= kStillTime) {
      return Step::next();
    }
    if (now - *began_ > kStillTimeout) {
      return Step::failed(what + ": the arm did not come to rest");
    }
    return Step::running();
  }

 private:
  const ArmDriver& driver_;
  const Clock& clock_;
  std::optional<TimePoint> began_;
  std::optional<TimePoint> still_since_;
};

/// Fails with `failure` once the arm is at rest (or with why it does not come to rest).
Step failOnceStill(StillWait& still, const std::string& failure) {
  const Step settled = still.poll(failure);
  return settled.kind == Step::Kind::kNext ? Step::failed(failure) : settled;
}

}  // namespace

std::unique_ptr<component::RunningOperation> ArmComponent::tare() {
  const CartesianState state = force_.controller != nullptr ? force_.controller->state() : CartesianState{};
  if (pressing_->motion != 0 && state.following && state.motion == pressing_->motion && !state.force_limit_stop) {
    return finishedWith(OperationResult::failure(
        "Tare: the tool is pressing on something (MoveUntilContact or PressAndFollow): ReleaseContact first"));
  }
  auto still = std::make_shared<StillWait>(driver_, clock_);
  return std::make_unique<StepOperation>(
      std::vector<StepOperation::StepFunction>{[still] { return still->poll("Tare"); },
                                               [this] {
                                                 const Wrench before = toolWrench(force_.sensor->read().wrench);
                                                 force_.sensor->tare();
                                                 return Step::done({{"zeroed_force_n", before.force.norm()}});
                                               }},
      nullptr);
}

namespace {

/// What a force-controlled operation checks at every poll of a Cartesian motion: the arm's
/// reading, that the motion is still its own, and the controller's force-limit stop.
std::string cartesianProblem(const ArmDriver& driver, const Clock& clock, const ArmConfig& config,
                             const CartesianState& state, std::uint64_t motion, double force_limit) {
  const std::string problem = readingProblem(driver.read(), clock.now(), config.state_timeout, config.joint_names);
  if (!problem.empty()) {
    return problem;
  }
  if (!state.following || state.motion != motion) {
    return "another motion took over";
  }
  if (state.force_limit_stop) {
    return "the force reached " + newtons(state.stop_force) + ", above max_force " + newtons(force_limit) +
           ": the arm stopped";
  }
  return {};
}

}  // namespace

std::unique_ptr<component::RunningOperation> ArmComponent::moveUntilContact(const ParamMap& params) {
  struct State {
    Eigen::Vector3d direction;
    double force = 0.0;
    double speed = 0.0;
    double distance = 0.0;
    double max_force = 0.0;
    std::uint64_t arm_motion = 0;
    std::uint64_t controller_motion = 0;
    double peak = 0.0;
    /// The approach ended (in contact, or stopped by the force limit): the operation ends once
    /// the arm is at rest, so that its end and arm_moving agree.
    std::shared_ptr<StillWait> settling;
    std::optional<std::string> failure;
    nlohmann::json contact;
  };
  auto state = std::make_shared<State>();
  state->direction = directionNamed(params.at("direction").asString(), endpoint());
  state->force = params.at("force").asDouble();
  state->speed = params.at("speed").asDouble();
  state->distance = params.at("distance").asDouble();
  state->max_force = params.at("max_force").asDouble();
  if (const std::string problem = forceBelowLimit(params); !problem.empty()) {
    return finishedWith(OperationResult::failure("MoveUntilContact: " + problem));
  }
  if (const std::string problem = approachSpeedProblem(state->speed); !problem.empty()) {
    return finishedWith(OperationResult::failure("MoveUntilContact: speed " + problem));
  }
  const CartesianState current = force_.controller->state();
  const bool pressing = pressing_->motion != 0 && current.following && current.motion == pressing_->motion;
  auto still = std::make_shared<StillWait>(driver_, clock_);
  std::vector<StepOperation::StepFunction> steps;
  if (!pressing) {
    steps.push_back([still] { return still->poll("MoveUntilContact"); });
    steps.push_back([this] {
      force_.sensor->tare();
      return Step::next();
    });
  }
  steps.push_back([this, state] {
    CartesianMotion motion;
    motion.path = std::make_shared<CartesianPath>(CartesianPath::through({endpoint()}, {}));
    motion.impedance.rotational_stiffness = Eigen::Vector3d::Constant(kRotationalStiffness);
    motion.force = ForceAxis{state->direction, state->force, state->speed};
    motion.force_limit = state->max_force;
    state->arm_motion = ++motion_->counter;
    motion_->trajectory.reset();
    motion_->cartesian = true;
    force_.controller->follow(std::move(motion), clock_.now());
    state->controller_motion = force_.controller->state().motion;
    return Step::next();
  });
  steps.push_back([this, state] {
    const CartesianState now = force_.controller->state();
    if (state->failure) {
      // Stopped by the force limit: the controller holds the tool where it stopped.
      return failOnceStill(*state->settling, *state->failure);
    }
    if (motion_->counter != state->arm_motion) {
      return Step::failed("MoveUntilContact: the arm was stopped, or another motion took over");
    }
    state->peak = std::max(state->peak, now.axis_force);
    if (const std::string problem =
            cartesianProblem(driver_, clock_, config_, now, state->controller_motion, state->max_force);
        !problem.empty()) {
      const bool held = now.force_limit_stop && now.motion == state->controller_motion;
      stop();
      if (held) {
        state->failure = "MoveUntilContact: " + problem;
        state->settling = std::make_shared<StillWait>(driver_, clock_);
        return Step::running();
      }
      return Step::failed("MoveUntilContact: " + problem);
    }
    if (!state->settling && now.offset > state->distance) {
      stop();
      return Step::failed("MoveUntilContact: no contact within " + formatNumber("%.3f m", state->distance) +
                          " (the force along the direction stayed below " + newtons(state->force) + ")");
    }
    if (!state->settling && now.axis_force >= 0.95 * state->force) {
      pressing_->motion = now.motion;
      pressing_->axis = state->direction;
      state->contact = {{"travel_m", now.offset}, {"force_n", now.axis_force}};
      state->settling = std::make_shared<StillWait>(driver_, clock_);
    }
    if (state->settling) {
      // In contact: done once the arm is at rest, pressing with the force.
      const Step settled = state->settling->poll("MoveUntilContact");
      if (settled.kind == Step::Kind::kFailed) {
        pressing_->motion = 0;  // the operation's end stops the arm
      }
      if (settled.kind != Step::Kind::kNext) {
        return settled;
      }
      state->contact["force_n"] = now.axis_force;
      state->contact["peak_force_n"] = state->peak;
      return Step::done(state->contact);
    }
    return Step::running();
  });
  return std::make_unique<StepOperation>(std::move(steps), [this, state] {
    if (motion_->counter == state->arm_motion && pressing_->motion != force_.controller->state().motion) {
      stop();  // not in contact: the approach ends where it is
    }
  });
}

std::unique_ptr<component::RunningOperation> ArmComponent::pressAndFollow(const ParamMap& params) {
  const std::string who = "PressAndFollow";
  if (const std::string problem = forceBelowLimit(params); !problem.empty()) {
    return finishedWith(OperationResult::failure(who + ": " + problem));
  }
  struct State {
    std::vector<std::string> names;
    std::vector<world::Pose> poses;
    std::shared_ptr<const CartesianPath> full;
    double start_arc = 0.0;  // where on the full path the press starts
    std::size_t next = 0;    // the first waypoint not yet pressed
    world::Pose start = world::Pose::Identity();
    Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();
    double force = 0.0;
    double speed = 0.0;
    double stiffness = 0.0;
    double max_force = 0.0;
    double approach = 0.0;
    bool tare = true;
    bool pressing = false;                                // already pressing when it started: slides over to the start
    std::unique_ptr<component::RunningOperation> motion;  // the joint motion above the start
    std::uint64_t arm_motion = 0;
    std::uint64_t controller_motion = 0;
    double arc_offset = 0.0;  // the full path's arc where the followed path's arc is 0
    double offset_at_start = 0.0;
    int contact_polls = 0;
    int low_polls = 0;
    bool following = false;
    double squared_error = 0.0;
    int samples = 0;
    double peak = 0.0;
    /// Stopped by the force limit: the operation fails once the arm is at rest (arm_moving agrees).
    std::optional<std::string> failure;
    std::shared_ptr<StillWait> settling;
  };
  auto state = std::make_shared<State>();
  // A problem while the controller presses: the arm stops; a force-limit stop leaves the tool
  // held where it stopped, and the operation fails once it is at rest.
  const auto stopOnProblem = [this](State& pressing, const CartesianState& now, std::string failure) {
    const bool held = now.force_limit_stop && now.motion == pressing.controller_motion;
    stop();
    if (!held) {
      return Step::failed(std::move(failure));
    }
    pressing.failure = std::move(failure);
    pressing.settling = std::make_shared<StillWait>(driver_, clock_);
    return Step::running();
  };
  state->names = params.at("path").asList();
  state->force = params.at("force").asDouble();
  state->speed = params.at("speed").asDouble();
  state->stiffness = params.at("stiffness").asDouble();
  state->max_force = params.at("max_force").asDouble();
  state->approach = params.at("approach").asDouble();
  state->tare = params.at("tare").asBool();
  if (state->names.empty()) {
    return finishedWith(OperationResult::failure(who + ": the path names no waypoint"));
  }
  for (const std::string& name : state->names) {
    const auto waypoint = waypoints_.find(name);
    if (!waypoint) {
      return finishedWith(OperationResult::failure(who + ": unknown waypoint '" + name + "'"));
    }
    const auto pose =
        waypoint->kind == Waypoint::Kind::kJoints ? std::optional(toolAt(waypoint->joints)) : waypointPose(*waypoint);
    if (!pose) {
      return finishedWith(OperationResult::failure(who + ": waypoint '" + name + "' is relative to '" +
                                                   waypoint->frame + "', which is not known now"));
    }
    state->poses.push_back(*pose);
  }
  state->full = std::make_shared<CartesianPath>(
      CartesianPath::through(state->poses, {state->speed, kPathAcceleration, kPathBlend}));
  // Where to start: where an interrupted press of this path stopped, else after the waypoints
  // already pressed in a row from the first.
  const bool resume = params.at("resume").asBool();
  const auto all_pressed = std::all_of(state->names.begin(), state->names.end(),
                                       [this](const std::string& name) { return pressing_->pressed.contains(name); });
  if (resume && all_pressed) {
    return finishedWith(OperationResult::success({{"pressed", "already"}}));
  }
  if (resume && pressing_->interrupted && pressing_->interrupted->path == state->names) {
    state->start_arc = pressing_->interrupted->arc;
  } else if (resume) {
    std::size_t done = 0;
    while (done < state->names.size() && pressing_->pressed.contains(state->names[done])) {
      ++done;
    }
    state->start_arc = done == 0 ? 0.0 : state->full->arcAt(done - 1);
  }
  while (state->next < state->names.size() && state->full->arcAt(state->next) < state->start_arc - 1e-3) {
    ++state->next;
  }
  state->start = state->full->poseAt(state->start_arc);
  state->axis = state->start.linear().col(2);

  // Before anything moves: every waypoint within reach, the path's lines feasible, and the
  // contact's torques within half of every motor's.
  const JointVector torque_limits = force_.controller->torqueLimits();
  JointVector seed = joints();
  std::vector<world::Pose> checked = {state->start};
  std::vector<std::string> checked_names = {state->next < state->names.size() &&
                                                    state->full->arcAt(state->next) < state->start_arc + 1e-3
                                                ? state->names[state->next]
                                                : "the path's start"};
  for (std::size_t i = state->next; i < state->poses.size(); ++i) {
    checked.push_back(state->poses[i]);
    checked_names.push_back(state->names[i]);
  }
  for (std::size_t i = 0; i < checked.size(); ++i) {
    const std::vector<JointVector> found = solutions(checked[i], seed);
    if (found.empty()) {
      return finishedWith(OperationResult::failure(who + ": waypoint '" + checked_names[i] + "' is out of reach"));
    }
    if (i > 0) {
      // The line in reach, the joints turning smoothly along it (the tool touches the surface on
      // purpose: no collision check, as a force-controlled path is taught in contact).
      const Eigen::Vector3d from = checked[i - 1].translation();
      const Eigen::Vector3d to = checked[i].translation();
      const int steps = std::max(1, static_cast<int>(std::ceil((to - from).norm() / kReachStep)));
      const Eigen::Quaterniond turn_from(checked[i - 1].linear());
      const Eigen::Quaterniond turn_to(checked[i].linear());
      for (int k = 1; k <= steps; ++k) {
        const double f = static_cast<double>(k) / steps;
        world::Pose along = world::Pose::Identity();
        along.linear() = turn_from.slerp(f, turn_to).toRotationMatrix();
        along.translation() = from + f * (to - from);
        const std::vector<JointVector> near = solutions(along, seed);
        if (near.empty() || maxAbsDifference(near.front(), seed) > kReachJump) {
          return finishedWith(OperationResult::failure(
              who + ": the line to '" + checked_names[i] + "' leaves the arm's reach (or needs the joints to jump) " +
              formatNumber("%.0f mm", (along.translation() - from).norm() * 1000) + " along it"));
        }
        seed = near.front();
      }
    } else {
      seed = found.front();
    }
    // The torques of max_force along the tool's axis: J^T f, J by finite differences.
    const world::Pose at = toolAt(seed);
    const Eigen::Vector3d pushed = state->max_force * state->axis;
    for (int j = 0; j < jointCount(); ++j) {
      constexpr double kStep = 1e-6;
      JointVector moved = seed;
      moved[j] += kStep;
      const Eigen::Vector3d linear = (toolAt(moved).translation() - at.translation()) / kStep;
      const double torque = std::abs(linear.dot(pushed));
      if (torque > kTorqueShare * torque_limits[j]) {
        const std::string joint = "joint " + std::to_string(j + 1) +
                                  (config_.joint_labels.empty() ? "" : " (" + config_.joint_labels[j] + ")");
        return finishedWith(OperationResult::failure(
            who + ": pressing with up to max_force " + newtons(state->max_force) + " at '" + checked_names[i] +
            "' needs " + formatNumber("%.1f N m", torque) + " of " + joint + ", more than half its " +
            formatNumber("%.0f N m", torque_limits[j]) + ": lower max_force"));
      }
    }
  }

  const CartesianState current = force_.controller->state();
  state->pressing = pressing_->motion != 0 && current.following && current.motion == pressing_->motion &&
                    !current.force_limit_stop && (endpoint().translation() - state->start.translation()).norm() < 0.05;
  std::vector<StepOperation::StepFunction> steps;
  auto still = std::make_shared<StillWait>(driver_, clock_);
  if (!state->pressing) {
    // Above the start, still, zeroed, then down until the tool presses.
    steps.push_back([this, state, who] {
      if (!state->motion) {
        world::Pose above = state->start;
        above.translation() -= state->approach * state->axis;
        MotionPlan plan = planToPose(above, config_.default_speed);
        if (!plan.ok()) {
          return Step::failed(who + ": above the start: " + plan.failure);
        }
        state->motion = execute(std::move(plan), who + " (above the start)");
      }
      const OperationResult result = state->motion->poll();
      if (result.state == component::OperationState::kFailure) {
        return Step::failed(result.reason);
      }
      return result.state == component::OperationState::kSuccess ? Step::next() : Step::running();
    });
    steps.push_back([still, who] { return still->poll(who); });
    steps.push_back([this, state] {
      if (state->tare) {
        force_.sensor->tare();
      }
      CartesianMotion motion;
      world::Pose above = state->start;
      above.translation() -= state->approach * state->axis;
      motion.path = std::make_shared<CartesianPath>(CartesianPath::through({above}, {}));
      motion.impedance.stiffness = Eigen::Vector3d(state->stiffness, state->stiffness, 2000.0);
      motion.impedance.rotational_stiffness = Eigen::Vector3d::Constant(kRotationalStiffness);
      motion.force = ForceAxis{state->axis, state->force, std::min(kDescentSpeed, state->speed)};
      motion.force_limit = state->max_force;
      state->arm_motion = ++motion_->counter;
      motion_->trajectory.reset();
      motion_->cartesian = true;
      force_.controller->follow(std::move(motion), clock_.now());
      state->controller_motion = force_.controller->state().motion;
      return Step::next();
    });
    steps.push_back([this, state, who, stopOnProblem] {
      const CartesianState now = force_.controller->state();
      if (state->failure) {
        return failOnceStill(*state->settling, *state->failure);
      }
      if (motion_->counter != state->arm_motion) {
        return Step::failed(who + ": the arm was stopped, or another motion took over");
      }
      if (const std::string problem =
              cartesianProblem(driver_, clock_, config_, now, state->controller_motion, state->max_force);
          !problem.empty()) {
        return stopOnProblem(*state, now, who + ": " + problem);
      }
      if (now.offset > state->approach + kMaxPathOffset) {
        stop();
        return Step::failed(who + ": found no surface within " + formatNumber("%.3f m", kMaxPathOffset) +
                            " past the path's start");
      }
      state->contact_polls = now.axis_force >= 0.8 * state->force ? state->contact_polls + 1 : 0;
      return state->contact_polls >= 3 ? Step::next() : Step::running();
    });
  }
  steps.push_back([this, state] {
    // The path from where the press starts (from where the tool is, when it was pressing).
    std::vector<world::Pose> poses;
    if (state->pressing) {
      world::Pose here = endpoint();
      here.linear() = state->start.linear();
      poses.push_back(here);
    }
    poses.push_back(state->start);
    for (std::size_t i = state->next; i < state->poses.size(); ++i) {
      if ((state->poses[i].translation() - poses.back().translation()).norm() > 1e-4 ||
          world::rotationAngle(state->poses[i], poses.back()) > 1e-4) {
        poses.push_back(state->poses[i]);
      }
    }
    auto path =
        std::make_shared<CartesianPath>(CartesianPath::through(poses, {state->speed, kPathAcceleration, kPathBlend}));
    state->arc_offset = state->start_arc - (state->pressing ? path->arcAt(1) : 0.0);
    CartesianMotion motion;
    motion.path = path;
    motion.impedance.stiffness = Eigen::Vector3d(state->stiffness, state->stiffness, 2000.0);
    motion.impedance.rotational_stiffness = Eigen::Vector3d::Constant(kRotationalStiffness);
    motion.force = ForceAxis{state->axis, state->force, kDescentSpeed};
    motion.force_limit = state->max_force;
    state->arm_motion = ++motion_->counter;
    motion_->trajectory.reset();
    motion_->cartesian = true;
    force_.controller->follow(std::move(motion), clock_.now());
    const CartesianState now = force_.controller->state();
    state->controller_motion = now.motion;
    state->offset_at_start = now.offset;
    state->following = true;
    pressing_->motion = now.motion;
    pressing_->axis = state->axis;
    return Step::next();
  });
  steps.push_back([this, state, who, stopOnProblem] {
    const CartesianState now = force_.controller->state();
    if (state->failure) {
      return failOnceStill(*state->settling, *state->failure);
    }
    if (motion_->counter != state->arm_motion) {
      return Step::failed(who + ": the arm was stopped, or another motion took over");
    }
    // At the path's end every waypoint was pressed through (the followed path's blends make its
    // arc lengths differ a little from the full path's).
    const double arc =
        now.path_done && now.motion == state->controller_motion ? state->full->length() : state->arc_offset + now.arc;
    if (const std::string problem =
            cartesianProblem(driver_, clock_, config_, now, state->controller_motion, state->max_force);
        !problem.empty()) {
      return stopOnProblem(*state, now, who + ": " + problem);
    }
    state->peak = std::max(state->peak, now.axis_force);
    state->squared_error += (now.axis_force - state->force) * (now.axis_force - state->force);
    ++state->samples;
    const double lost = std::max(1.0, 0.3 * state->force);
    state->low_polls = now.axis_force < lost ? state->low_polls + 1 : 0;
    if (state->low_polls >= kLostPolls) {
      stop();
      return Step::failed(who + ": contact lost (the force along the tool fell below " + newtons(lost) +
                          "): the tool was lifted away or the surface ended; the arm stopped");
    }
    if (std::abs(now.offset - state->offset_at_start) > kMaxPathOffset) {
      stop();
      return Step::failed(who + ": the surface is more than " + formatNumber("%.0f mm", kMaxPathOffset * 1000) +
                          " off the path along the tool: the arm stopped");
    }
    while (state->next < state->names.size() && arc >= state->full->arcAt(state->next) - 1e-3) {
      pressing_->pressed.insert(state->names[state->next]);
      ++state->next;
    }
    pressing_->interrupted = Pressing::Interrupted{state->names, std::min(arc, state->full->length())};
    if (now.path_done && state->next >= state->names.size()) {
      pressing_->interrupted.reset();
      return Step::done({{"force_rms_error_n", std::sqrt(state->squared_error / std::max(state->samples, 1))},
                         {"peak_force_n", state->peak},
                         {"length_m", state->full->length() - state->start_arc}});
    }
    return Step::running();
  });
  return std::make_unique<StepOperation>(std::move(steps), [this, state] {
    if (state->motion) {
      state->motion->cancel();
    }
    const bool ours = motion_->counter == state->arm_motion && state->arm_motion != 0;
    const CartesianState now = force_.controller->state();
    const bool finished =
        state->following && now.motion == state->controller_motion && now.path_done && !pressing_->interrupted;
    if (ours && !finished) {
      stop();
    }
    if (!finished && pressing_->motion == state->controller_motion) {
      pressing_->motion = 0;
    }
  });
}

std::unique_ptr<component::RunningOperation> ArmComponent::releaseContact(const ParamMap& params) {
  struct State {
    double distance = 0.0;
    double speed = 0.0;
    Eigen::Vector3d axis;
    bool pressing = false;
    std::optional<TimePoint> since;
    std::uint64_t arm_motion = 0;
    std::uint64_t controller_motion = 0;
  };
  auto state = std::make_shared<State>();
  state->distance = params.at("distance").asDouble();
  state->speed = params.at("speed").asDouble();
  const CartesianState current = force_.controller->state();
  state->pressing = pressing_->motion != 0 && current.following && current.motion == pressing_->motion;
  auto still = std::make_shared<StillWait>(driver_, clock_);
  state->axis = state->pressing ? pressing_->axis : Eigen::Vector3d(endpoint().linear().col(2));
  std::vector<StepOperation::StepFunction> steps;
  if (state->pressing) {
    // Let the force go first: the controller backs off until the tool no longer pushes.
    steps.push_back([this, state] {
      const TimePoint time = clock_.now();
      if (!state->since) {
        state->since = time;
        force_.controller->setForce(0.0);
      }
      const CartesianState now = force_.controller->state();
      if (!now.following || now.axis_force < 1.0 || time - *state->since > std::chrono::seconds(1)) {
        pressing_->motion = 0;
        return Step::next();
      }
      return Step::running();
    });
  }
  // Back along the axis, compliant (it starts touching: a planned line would refuse to start
  // in contact), then held by the joints where it ends.
  steps.push_back([this, state] {
    if (state->arm_motion == 0) {
      world::Pose back = endpoint();
      back.translation() -= state->distance * state->axis;
      CartesianMotion motion;
      motion.path = std::make_shared<CartesianPath>(
          CartesianPath::through({endpoint(), back}, {state->speed, kPathAcceleration, 0.0}));
      motion.impedance.rotational_stiffness = Eigen::Vector3d::Constant(kRotationalStiffness);
      motion.force_limit = kMaxForceLimit;
      state->arm_motion = ++motion_->counter;
      motion_->trajectory.reset();
      motion_->cartesian = true;
      force_.controller->follow(std::move(motion), clock_.now());
      state->controller_motion = force_.controller->state().motion;
    }
    const CartesianState now = force_.controller->state();
    if (motion_->counter != state->arm_motion) {
      return Step::failed("ReleaseContact: the arm was stopped, or another motion took over");
    }
    if (const std::string problem =
            cartesianProblem(driver_, clock_, config_, now, state->controller_motion, kMaxForceLimit);
        !problem.empty()) {
      stop();
      return Step::failed("ReleaseContact: " + problem);
    }
    return now.path_done ? Step::next() : Step::running();
  });
  steps.push_back([still] { return still->poll("ReleaseContact"); });
  steps.push_back([this] {
    stop();  // the joints hold where it is
    return Step::done();
  });
  return std::make_unique<StepOperation>(std::move(steps), [this, state] {
    if (state->arm_motion != 0 && motion_->counter == state->arm_motion) {
      stop();
    }
  });
}

}  // namespace costar::arm
