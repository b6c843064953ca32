#include "arm/arm_component.h"

#include "arm/arm_motion.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace costar::arm {

using component::OperationResult;
using component::ParamSpec;
using component::ValueType;

namespace {

/// The longest JogCartesian along one axis (a jog is a small move).
constexpr double kMaxJogMetres = 0.2;

std::unique_ptr<component::RunningOperation> finished(OperationResult result) {
  return std::make_unique<component::FinishedOperation>(std::move(result));
}

/// How far (rad, any joint) a FollowJointPath may start from where the arm is.
constexpr double kPathStartTolerance = 0.01;

ParamSpec speedParam(double default_speed) {
  ParamSpec speed{"speed", ValueType::kDouble, "fraction of the arm's top speed and acceleration", default_speed};
  speed.min = 0.01;
  speed.max = 1.0;
  return speed;
}

}  // namespace

ArmComponent::ArmComponent(ArmDriver& driver, const Clock& clock, const planning::CollisionWorld& collisions,
                           WaypointStore& waypoints, FrameLookup frames, std::shared_ptr<const Kinematics> kinematics,
                           ArmConfig config, ForceControl force)
    : driver_(driver),
      clock_(clock),
      waypoints_(waypoints),
      frames_(std::move(frames)),
      kinematics_(std::move(kinematics)),
      config_(std::move(config)),
      force_(force) {
  if (kinematics_ == nullptr) {
    throw std::invalid_argument("ArmComponent '" + config_.name + "': no kinematics");
  }
  if (config_.home.size() != kinematics_->jointCount()) {
    throw std::invalid_argument("ArmComponent '" + config_.name + "': the home configuration has " +
                                std::to_string(config_.home.size()) + " angles, the arm " +
                                std::to_string(kinematics_->jointCount()) + " joints");
  }
  const auto check_count = [this](const std::vector<std::string>& list, const char* what) {
    if (!list.empty() && static_cast<int>(list.size()) != kinematics_->jointCount()) {
      throw std::invalid_argument("ArmComponent '" + config_.name + "': " + std::to_string(list.size()) + " " + what +
                                  " for " + std::to_string(kinematics_->jointCount()) + " joints");
    }
  };
  check_count(config_.joint_names, "joint names");
  check_count(config_.joint_labels, "joint labels");
  if (config_.joint_names.empty()) {
    for (int j = 1; j <= kinematics_->jointCount(); ++j) {
      config_.joint_names.push_back("joint_" + std::to_string(j));
    }
  }
  planner_.emplace(driver_, clock_, collisions, kinematics_, config_);
  if (force_.sensor != nullptr) {
    force_.sensor->tare();  // as a sensor is biased when it starts, with the arm at rest
  }
  declareOperations();
}

void ArmComponent::declareOperations() {
  component::ComponentDescription description;
  description.name = config_.name;
  description.type = config_.type;
  description.implements = {"Arm"};
  description.inputs = {"joint_states"};
  description.outputs = {"joint_trajectory"};

  ParamSpec waypoint{"waypoint", ValueType::kString, "name of a taught waypoint", {}};
  waypoint.choices_from = "waypoint";
  ParamSpec frame{"frame", ValueType::kString, "frame the pose is given in: world or a frame symbol",
                  std::string("world")};
  frame.choices_from = "frame";
  ParamSpec kind{"kind",
                 ValueType::kString,
                 "what to store: the tool's pose, or the joint configuration",
                 std::string("pose"),
                 {"pose", "joints"}};
  ParamSpec axis_frame{
      "frame", ValueType::kString, "axes of the offset: world or tool", std::string("world"), {"world", "tool"}};
  const int joint_count = kinematics_->jointCount();
  const auto label = [this](int j) {
    return config_.joint_labels.empty() ? std::string() : " (" + config_.joint_labels[j] + ")";
  };
  ParamSpec joint{"joint",
                  ValueType::kInt,
                  "joint number, 1" + label(0) + " to " + std::to_string(joint_count) + label(joint_count - 1),
                  {}};
  joint.min = 1;
  joint.max = joint_count;
  ParamSpec degrees{"degrees", ValueType::kDouble, "how far to turn, in degrees", {}};
  degrees.min = -90;
  degrees.max = 90;
  ParamSpec axis{"axis", ValueType::kString, "direction to jog", {}, {"x", "y", "z", "roll", "pitch", "yaw"}};
  ParamSpec amount{
      "amount", ValueType::kDouble, "metres along x/y/z (up to 0.2), degrees about roll/pitch/yaw (up to 90)", {}};
  amount.min = -90;
  amount.max = 90;
  const ParamSpec speed = speedParam(config_.default_speed);
  using Params = component::ParamMap;
  component::OperationTable operations;
  operations.add({"Move", "Moves the tool to a taught waypoint, around obstacles.", {waypoint, speed}},
                 [this](const Params& params) { return move(params); });
  operations.add({"Home", "Moves the arm to its home configuration.", {speed}},
                 [this](const Params& params) { return execute(planToJoints(config_.home, speedOf(params)), "Home"); });
  operations.add({"MoveToPose",
                  "Moves the tool to a pose given in a frame.",
                  {{"pose", ValueType::kPose, "x;y;z;roll;pitch;yaw (m, degrees)", {}}, frame, speed}},
                 [this](const Params& params) {
                   const std::string name = params.at("frame").asString();
                   const auto base = frameInWorld(name);
                   if (!base) {
                     return finished(OperationResult::failure("unknown frame '" + name + "'"));
                   }
                   return execute(planToPose(*base * params.at("pose").asPose(), speedOf(params)), "MoveToPose");
                 });
  operations.add({"MoveRelative",
                  "Moves the tool along a straight line by an offset (e.g. 0;0;0.1 lifts 10 cm).",
                  {{"offset", ValueType::kPose, "x;y;z[;roll;pitch;yaw] (m, degrees)", {}}, axis_frame, speed}},
                 [this](const Params& params) { return straightLine("MoveRelative", params); });
  operations.add({"Teach",
                  "Saves where the arm is as a named waypoint.",
                  {{"waypoint", ValueType::kString, "name for the waypoint", {}}, kind, frame},
                  component::OperationKind::kKnowledge},
                 [this](const Params& params) { return teach(params); });
  operations.add({"RenameWaypoint",
                  "Renames a taught waypoint.",
                  {waypoint, {"new_name", ValueType::kString, "the waypoint's new name", {}}},
                  component::OperationKind::kKnowledge},
                 [this](const Params& params) { return renameOrDelete(true, params); });
  operations.add({"DeleteWaypoint", "Forgets a taught waypoint.", {waypoint}, component::OperationKind::kKnowledge},
                 [this](const Params& params) { return renameOrDelete(false, params); });
  operations.add({"JogJoint", "Turns one joint by a few degrees.", {joint, degrees, speed}},
                 [this](const Params& params) { return jogJoint(params); });
  component::OperationSpec jog_cartesian{"JogCartesian",
                                         "Moves the tool a little along or about one axis, in a straight line.",
                                         {axis, amount, axis_frame, speed}};
  // One range for metres and degrees would allow a jog of 90 m (a hostile tester's finding):
  // checked when the plan is validated.
  jog_cartesian.check = [](const Params& params) -> std::string {
    const auto axis = params.find("axis");
    const auto amount = params.find("amount");
    if (axis == params.end() || amount == params.end() || axis->second.asString().size() != 1 ||
        std::abs(amount->second.asDouble()) <= kMaxJogMetres) {
      return {};
    }
    return "amount " + component::formatValue(amount->second) + " along " + axis->second.asString() +
           ": JogCartesian moves at most 0.2 m at a time";
  };
  operations.add(std::move(jog_cartesian),
                 [this](const Params& params) { return straightLine("JogCartesian", params); });
  ParamSpec path{"path",
                 ValueType::kString,
                 "the joint waypoints, start first, as JSON: [[q1, ..., qn], ...] (rad), from the cell's motion "
                 "service",
                 {}};
  ParamSpec motion_label{"label", ValueType::kString, "what the motion is called in messages",
                         std::string(kFollowJointPath)};
  operations.add({std::string(kFollowJointPath),
                  "Follows joint waypoints planned by the cell's motion service, timed within the arm's limits.",
                  {path, speed, motion_label},
                  component::OperationKind::kInternal},
                 [this](const Params& params) { return followJointPath(params); });
  description.symbols = {{"endpoint", world::SymbolKind::kFrame, "the tool centre point, in the world"},
                         {"arm_joints", world::SymbolKind::kJoints, "the joint configuration"}};
  description.predicates = {{"arm_moving", 0, "a joint is turning"},
                            {"at_waypoint", 1, "at_waypoint(w): the tool is at waypoint w"}};
  declareForceOperations(description, operations);
  if (force_.sensor != nullptr && force_.controller != nullptr) {
    description.predicates.push_back({"free_driving", 0, "the arm is guided by hand (FreeDrive), its dead-man held"});
    declareFreeDrive(operations);
  }
  declareFollowTrajectory(operations);
  declare(std::move(description), std::move(operations));
}

world::Pose ArmComponent::endpoint() const { return planner_->endpoint(); }

void ArmComponent::stop() {
  if (motion_->cartesian && force_.controller != nullptr) {
    if (const CartesianState state = force_.controller->state(); state.following && state.force_limit_stop) {
      // The controller holds the tool where it gave way to what it pushed, compliant, without
      // pressing (arm/cartesian_controller.h); the joints held where they are would keep the force.
      ++motion_->counter;
      return;
    }
  }
  stopMotion(*motion_, driver_, clock_, kinematics_->limits());
}

std::optional<world::Pose> ArmComponent::waypointPose(const Waypoint& waypoint) const {
  if (waypoint.frame == "world") {
    return waypoint.pose;
  }
  const auto frame = frames_ ? frames_(waypoint.frame) : std::nullopt;
  if (!frame) {
    return std::nullopt;
  }
  return *frame * waypoint.pose;
}

std::unique_ptr<component::RunningOperation> ArmComponent::execute(MotionPlan plan, const std::string& what) {
  if (!plan.ok()) {
    return std::make_unique<component::FinishedOperation>(OperationResult::failure(what + ": " + plan.failure));
  }
  return std::make_unique<MotionOperation>(driver_, clock_, std::move(plan), motion_, config_, kinematics_, what);
}

double ArmComponent::speedOf(const component::ParamMap& params) const {
  const auto it = params.find("speed");
  return it == params.end() ? config_.default_speed : it->second.asDouble();
}

std::optional<world::Pose> ArmComponent::frameInWorld(const std::string& frame) const {
  if (frame == "world") {
    return world::Pose::Identity();
  }
  return frames_ ? frames_(frame) : std::nullopt;
}

std::unique_ptr<component::RunningOperation> ArmComponent::move(const component::ParamMap& params) {
  const std::string name = params.at("waypoint").asString();
  const auto waypoint = waypoints_.find(name);
  if (!waypoint) {
    std::string known;
    for (const auto& w : waypoints_.all()) {
      known += (known.empty() ? "" : ", ") + w.name;
    }
    return finished(OperationResult::failure("unknown waypoint '" + name + "'" +
                                             (known.empty() ? " (none taught yet)" : " (known: " + known + ")")));
  }
  if (waypoint->kind == Waypoint::Kind::kJoints) {
    return execute(planToJoints(waypoint->joints, speedOf(params)), "Move to '" + name + "'");
  }
  const auto pose = waypointPose(*waypoint);
  if (!pose) {
    return finished(OperationResult::failure("waypoint '" + name + "' is relative to '" + waypoint->frame +
                                             "', which is not known now"));
  }
  return execute(planToPose(*pose, speedOf(params)), "Move to '" + name + "'");
}

std::unique_ptr<component::RunningOperation> ArmComponent::straightLine(const std::string& operation,
                                                                        const component::ParamMap& params) {
  world::Pose offset = world::Pose::Identity();
  if (operation == "MoveRelative") {
    offset = params.at("offset").asPose();
  } else {
    const std::string axis = params.at("axis").asString();
    const double amount = params.at("amount").asDouble();
    const int index = axis == "x" || axis == "roll" ? 0 : axis == "y" || axis == "pitch" ? 1 : 2;
    if (axis.size() == 1) {
      if (std::abs(amount) > kMaxJogMetres) {
        return finished(OperationResult::failure("JogCartesian moves at most 0.2 m at a time"));
      }
      offset.translation()[index] = amount;
    } else {
      offset.linear() = Eigen::AngleAxisd(amount * M_PI / 180.0, Eigen::Vector3d::Unit(index)).toRotationMatrix();
    }
  }
  const world::Pose now = endpoint();
  world::Pose target = now;
  if (params.at("frame").asString() == "tool") {
    target = now * offset;
  } else {
    target.translation() = now.translation() + offset.translation();
    target.linear() = offset.linear() * now.linear();
  }
  return execute(planLine(target, speedOf(params)), operation);
}

std::unique_ptr<component::RunningOperation> ArmComponent::jogJoint(const component::ParamMap& params) {
  JointVector goal = checkedRead().position;
  goal[params.at("joint").asInt() - 1] += params.at("degrees").asDouble() * M_PI / 180.0;
  return execute(planToJoints(goal, speedOf(params)), "JogJoint");
}

std::string ArmComponent::nameTaken(const std::string& name) const {
  if (waypoints_.find(name)) {
    return {};  // taught again, or renamed to itself
  }
  if (name == "world") {
    return "'world' is the frame every pose is given in";
  }
  for (const auto& symbol : description().symbols) {
    if (symbol.name == name) {
      return "'" + name + "' is the arm's own symbol (" + symbol.description + ")";
    }
  }
  // Another component's frame ("camera", "table_center", a part): a waypoint of that name would
  // hide it, and the editor could reach neither.
  if (frameInWorld(name)) {
    return "'" + name + "' names a frame the cell knows already (a calibrated frame or a part)";
  }
  return {};
}

std::unique_ptr<component::RunningOperation> ArmComponent::teach(const component::ParamMap& params) {
  Waypoint waypoint;
  waypoint.name = params.at("waypoint").asString();
  if (const std::string taken = nameTaken(waypoint.name); !taken.empty()) {
    return finished(OperationResult::failure("cannot save the waypoint: " + taken + "; choose another name"));
  }
  if (params.at("kind").asString() == "joints") {
    waypoint.kind = Waypoint::Kind::kJoints;
    waypoint.joints = checkedRead().position;
  } else {
    waypoint.frame = params.at("frame").asString();
    const auto frame = frameInWorld(waypoint.frame);
    if (!frame) {
      return finished(
          OperationResult::failure("cannot teach relative to '" + waypoint.frame + "': no such frame is known now"));
    }
    waypoint.pose = frame->inverse() * endpoint();
  }
  try {
    waypoints_.put(waypoint);
  } catch (const std::exception& e) {
    return finished(OperationResult::failure(std::string("cannot save the waypoint: ") + e.what()));
  }
  return finished(OperationResult::success({{"waypoint", waypoint.name}}));
}

std::unique_ptr<component::RunningOperation> ArmComponent::renameOrDelete(bool rename,
                                                                          const component::ParamMap& params) {
  const std::string name = params.at("waypoint").asString();
  try {
    if (rename) {
      const std::string new_name = params.at("new_name").asString();
      if (const std::string taken = nameTaken(new_name); !taken.empty() && new_name != name) {
        return finished(OperationResult::failure("cannot rename '" + name + "': " + taken + "; choose another name"));
      }
      waypoints_.rename(name, new_name);
    } else if (!waypoints_.remove(name)) {
      return finished(OperationResult::failure("unknown waypoint '" + name + "'"));
    }
  } catch (const std::exception& e) {
    return finished(OperationResult::failure(e.what()));
  }
  return finished(OperationResult::success());
}

std::unique_ptr<component::RunningOperation> ArmComponent::followJointPath(const component::ParamMap& params) {
  const std::string label = params.contains("label") ? params.at("label").asString() : std::string(kFollowJointPath);
  std::vector<JointVector> path;
  try {
    path = pathFromParam(params.at("path").asString(), jointCount());
  } catch (const std::invalid_argument& e) {
    return finished(OperationResult::failure(label + ": " + e.what()));
  }
  // A path planned from elsewhere than where the arm is would jump. A reading that cannot be
  // trusted is reported (and the arm stopped) by the motion's first poll, as for every motion.
  try {
    const JointVector now = checkedRead().position;
    if (const double gap = maxAbsDifference(path.front(), now); gap > kPathStartTolerance) {
      return finished(OperationResult::failure(label + ": the path starts " + formatNumber("%.3f", gap) +
                                               " rad from where the arm is (planned from elsewhere?)"));
    }
  } catch (const std::exception&) {
  }
  return execute(planner_->timed(std::move(path), speedOf(params)), label);
}

world::Report ArmComponent::report() const {
  // A reading that cannot be trusted makes the report throw: the registry then stops the cell.
  const ArmState state = checkedRead();
  const world::Pose tcp = toolAt(state.position);
  const TimePoint now = clock_.now();
  world::Report report;
  report.symbols.push_back({"endpoint", "", now, world::FrameValue{"world", tcp}});
  report.symbols.push_back(
      {"arm_joints", "", now,
       world::JointsValue{config_.joint_names, std::vector<double>(state.position.begin(), state.position.end())}});
  if (maxAbs(state.velocity) > 0.01) {
    report.predicates.push_back({"arm_moving", {}, true, ""});
  }
  reportForce(report);
  if (freeDriveStatus().active) {
    report.predicates.push_back({"free_driving", {}, true, ""});
  }
  for (const Waypoint& waypoint : waypoints_.all()) {
    if (waypoint.kind == Waypoint::Kind::kJoints) {
      report.symbols.push_back({waypoint.name, "", now,
                                world::JointsValue{config_.joint_names, std::vector<double>(waypoint.joints.begin(),
                                                                                            waypoint.joints.end())}});
      if (maxAbsDifference(waypoint.joints, state.position) < config_.at_waypoint_joints) {
        report.predicates.push_back({"at_waypoint", {waypoint.name}, true, ""});
      }
      continue;
    }
    report.symbols.push_back({waypoint.name, "", now, world::FrameValue{waypoint.frame, waypoint.pose}});
    if (const auto pose = waypointPose(waypoint)) {
      if ((pose->translation() - tcp.translation()).norm() < config_.at_waypoint_distance &&
          world::rotationAngle(*pose, tcp) < config_.at_waypoint_angle) {
        report.predicates.push_back({"at_waypoint", {waypoint.name}, true, ""});
      }
    }
  }
  return report;
}

}  // namespace costar::arm
