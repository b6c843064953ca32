#include "arm/arm_component.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace costar::arm {

using component::OperationResult;
using component::ParamSpec;
using component::ValueType;

namespace {

constexpr double kTwoPi = 2.0 * M_PI;
constexpr const char* kJointNames[kJointCount] = {"shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint",
                                                  "wrist_1_joint",      "wrist_2_joint",       "wrist_3_joint"};

std::string format(const char* pattern, double value) {
  char text[96];
  std::snprintf(text, sizeof text, pattern, value);
  return text;
}

double maxAbs(const JointVector& a, const JointVector& b) {
  double largest = 0.0;
  for (int j = 0; j < kJointCount; ++j) {
    largest = std::max(largest, std::abs(a[j] - b[j]));
  }
  return largest;
}

/// Why a reading cannot be trusted, or empty.
std::string problemWith(const ArmState& state, TimePoint now, Duration timeout) {
  for (int j = 0; j < kJointCount; ++j) {
    if (!std::isfinite(state.position[j]) || !std::isfinite(state.velocity[j])) {
      return std::string("arm driver: the joint state is not a number (") + kJointNames[j] + ")";
    }
  }
  if (state.stamp != TimePoint{} && now - state.stamp > timeout) {
    return "arm driver: the joint state stopped updating (" + format("%.3f", toSeconds(now - state.stamp)) + " s old)";
  }
  return {};
}

/// Decelerates the motion being followed along its path, if it is not over.
void stopMotion(ArmMotion& motion, ArmDriver& driver, const Clock& clock, const JointLimits& limits) {
  ++motion.counter;
  if (!motion.trajectory) {
    return;
  }
  const TimePoint now = clock.now();
  if (now - motion.start < motion.trajectory->duration()) {
    const TrajectoryPoint state = motion.trajectory->sample(now - motion.start);
    auto stop = std::make_shared<JointTrajectory>(JointTrajectory::stopFrom(state, limits));
    driver.execute(stop, now);
    motion.trajectory = std::move(stop);
    motion.start = now;
  }
}

/// A motion being executed by the driver.
class MotionOperation final : public component::RunningOperation {
 public:
  MotionOperation(ArmDriver& driver, const Clock& clock, MotionPlan plan, std::shared_ptr<ArmMotion> motion,
                  const ArmConfig& config, std::string what)
      : driver_(driver),
        clock_(clock),
        plan_(std::move(plan)),
        motion_(std::move(motion)),
        id_(++motion_->counter),
        config_(config),
        what_(std::move(what)),
        start_(clock.now()) {
    motion_->trajectory = plan_.trajectory;
    motion_->start = start_;
    driver_.execute(plan_.trajectory, start_);
  }

  OperationResult poll() override {
    if (motion_->counter != id_) {
      return OperationResult::failure("the arm was stopped, or another motion took over, before " + what_ +
                                      " finished");
    }
    const TimePoint now = clock_.now();
    // Every poll checks the driver's reading: a driver that fails, reads NaN or stopped
    // updating stops the motion at once.
    ArmState state;
    std::string problem;
    try {
      state = driver_.read();
      problem = problemWith(state, now, config_.state_timeout);
    } catch (const std::exception& e) {
      problem = e.what();
    }
    if (!problem.empty()) {
      stopMotion(*motion_, driver_, clock_, config_.limits);
      return OperationResult::failure(what_ + ": " + problem + "; the arm was stopped");
    }
    const TimePoint end = start_ + plan_.trajectory->duration();
    if (now < end) {
      return OperationResult::running();
    }
    const double error = maxAbs(state.position, plan_.goal);
    const double speed = maxAbs(state.velocity, JointVector{});
    if (error < config_.arrival_tolerance && speed < 0.05) {
      return OperationResult::success({{"duration", toSeconds(plan_.trajectory->duration())}});
    }
    if (now > end + config_.settle_time) {
      return OperationResult::failure(what_ + ": the arm stopped " + format("%.3f", error) +
                                      " rad from its goal (blocked, or the controller cannot follow)");
    }
    return OperationResult::running();
  }

  void cancel() override {
    if (motion_->counter == id_) {
      stopMotion(*motion_, driver_, clock_, config_.limits);
    }
  }

 private:
  ArmDriver& driver_;
  const Clock& clock_;
  MotionPlan plan_;
  std::shared_ptr<ArmMotion> motion_;
  std::uint64_t id_;
  const ArmConfig& config_;
  std::string what_;
  TimePoint start_;
};

ParamSpec speedParam(double default_speed) {
  ParamSpec speed{"speed", ValueType::kDouble, "fraction of the arm's top speed and acceleration", default_speed};
  speed.min = 0.01;
  speed.max = 1.0;
  return speed;
}

}  // namespace

ArmComponent::ArmComponent(ArmDriver& driver, const Clock& clock, planning::CollisionWorld& collisions,
                           WaypointStore& waypoints, FrameLookup frames, ArmConfig config)
    : driver_(driver),
      clock_(clock),
      collisions_(collisions),
      waypoints_(waypoints),
      frames_(std::move(frames)),
      config_(std::move(config)) {
  description_.name = config_.name;
  description_.type = config_.type;
  description_.implements = {"Arm"};
  description_.inputs = {"joint_states"};
  description_.outputs = {"joint_trajectory"};

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
  ParamSpec joint{"joint", ValueType::kInt, "joint number, 1 (base) to 6 (wrist 3)", {}};
  joint.min = 1;
  joint.max = 6;
  ParamSpec degrees{"degrees", ValueType::kDouble, "how far to turn, in degrees", {}};
  degrees.min = -90;
  degrees.max = 90;
  ParamSpec axis{"axis", ValueType::kString, "direction to jog", {}, {"x", "y", "z", "roll", "pitch", "yaw"}};
  ParamSpec amount{"amount", ValueType::kDouble, "metres along x/y/z, degrees about roll/pitch/yaw", {}};
  amount.min = -90;
  amount.max = 90;
  const ParamSpec speed = speedParam(config_.default_speed);
  description_.operations = {
      {"Move", "Moves the tool to a taught waypoint, around obstacles.", {waypoint, speed}},
      {"Home", "Moves the arm to its home configuration.", {speed}},
      {"MoveToPose",
       "Moves the tool to a pose given in a frame.",
       {{"pose", ValueType::kPose, "x;y;z;roll;pitch;yaw (m, degrees)", {}}, frame, speed}},
      {"MoveRelative",
       "Moves the tool along a straight line by an offset (e.g. 0;0;0.1 lifts 10 cm).",
       {{"offset", ValueType::kPose, "x;y;z[;roll;pitch;yaw] (m, degrees)", {}}, axis_frame, speed}},
      {"Teach",
       "Saves where the arm is as a named waypoint.",
       {{"waypoint", ValueType::kString, "name for the waypoint", {}}, kind, frame},
       component::OperationKind::kKnowledge},
      {"RenameWaypoint",
       "Renames a taught waypoint.",
       {waypoint, {"new_name", ValueType::kString, "the waypoint's new name", {}}},
       component::OperationKind::kKnowledge},
      {"DeleteWaypoint", "Forgets a taught waypoint.", {waypoint}, component::OperationKind::kKnowledge},
      {"JogJoint", "Turns one joint by a few degrees.", {joint, degrees, speed}},
      {"JogCartesian",
       "Moves the tool a little along or about one axis, in a straight line.",
       {axis, amount, axis_frame, speed}}};
  description_.symbols = {{"endpoint", world::SymbolKind::kFrame, "the tool centre point, in the world"},
                          {"arm_joints", world::SymbolKind::kJoints, "the joint configuration"}};
  description_.predicates = {{"arm_moving", 0, "a joint is turning"},
                             {"at_waypoint", 1, "at_waypoint(w): the tool is at waypoint w"}};
}

Eigen::VectorXd ArmComponent::toEigen(const JointVector& q) const {
  return Eigen::Map<const Eigen::Matrix<double, kJointCount, 1>>(q.data());
}

world::Pose ArmComponent::endpoint() const {
  return config_.base_in_world * kinematics_.forward(checkedRead().position) * config_.tcp_in_flange;
}

ArmState ArmComponent::checkedRead() const {
  const ArmState state = driver_.read();
  if (const std::string problem = problemWith(state, clock_.now(), config_.state_timeout); !problem.empty()) {
    throw std::runtime_error(problem);
  }
  return state;
}

void ArmComponent::stop() { stopMotion(*motion_, driver_, clock_, config_.limits); }

world::Pose ArmComponent::flangeInBase(const world::Pose& tcp_in_world) const {
  return config_.base_in_world.inverse() * tcp_in_world * config_.tcp_in_flange.inverse();
}

std::vector<JointVector> ArmComponent::solutions(const world::Pose& tcp_in_world, const JointVector& seed) const {
  std::array<JointVector, Ur5Kinematics::kMaxSolutions> raw;
  const int count = kinematics_.inverse(flangeInBase(tcp_in_world), raw, seed[5]);
  std::vector<JointVector> result;
  for (int s = 0; s < count; ++s) {
    JointVector q = raw[s];
    bool within = true;
    for (int j = 0; j < kJointCount && within; ++j) {
      // The 2*pi-equivalent nearest the seed, moved inside the limits if it is not.
      double angle = q[j] + kTwoPi * std::round((seed[j] - q[j]) / kTwoPi);
      while (angle > config_.limits.max_position[j]) {
        angle -= kTwoPi;
      }
      while (angle < config_.limits.min_position[j]) {
        angle += kTwoPi;
      }
      within = angle <= config_.limits.max_position[j];
      q[j] = angle;
    }
    if (within) {
      result.push_back(q);
    }
  }
  std::sort(result.begin(), result.end(), [&seed](const JointVector& a, const JointVector& b) {
    double da = 0;
    double db = 0;
    for (int j = 0; j < kJointCount; ++j) {
      da += (a[j] - seed[j]) * (a[j] - seed[j]);
      db += (b[j] - seed[j]) * (b[j] - seed[j]);
    }
    return da < db;
  });
  return result;
}

MotionPlan ArmComponent::timed(std::vector<JointVector> path, double speed) const {
  MotionPlan plan;
  try {
    plan.goal = path.back();
    plan.trajectory = std::make_shared<JointTrajectory>(
        path.size() == 2 ? JointTrajectory::pointToPoint(path.front(), path.back(), config_.limits, speed)
                         : JointTrajectory::alongPath(path, config_.limits, speed));
  } catch (const std::invalid_argument& e) {
    plan.trajectory.reset();
    plan.failure = e.what();
  }
  return plan;
}

world::Pose ArmComponent::toolAt(const JointVector& q) const {
  return config_.base_in_world * kinematics_.forward(q) * config_.tcp_in_flange;
}

MotionPlan ArmComponent::planToJoints(const JointVector& start, const JointVector& goal, double speed) const {
  for (int j = 0; j < kJointCount; ++j) {
    if (goal[j] < config_.limits.min_position[j] || goal[j] > config_.limits.max_position[j]) {
      return {nullptr, goal, "joint " + std::to_string(j + 1) + " would leave its limits"};
    }
  }
  const planning::PlanResult path = planning::planPath(collisions_, toEigen(start), toEigen(goal), config_.planner);
  if (!path.ok()) {
    return {nullptr, goal, path.failure};
  }
  std::vector<JointVector> joints;
  for (const auto& q : path.path) {
    JointVector v;
    std::copy(q.data(), q.data() + kJointCount, v.begin());
    joints.push_back(v);
  }
  return timed(std::move(joints), speed);
}

MotionPlan ArmComponent::planToPose(const world::Pose& tcp_in_world, double speed) const {
  const JointVector current = checkedRead().position;
  const std::vector<JointVector> candidates = solutions(tcp_in_world, current);
  if (candidates.empty()) {
    return {nullptr, current, "the pose is out of reach (no inverse kinematics solution within the joint limits)"};
  }
  std::string first_problem;
  for (const JointVector& goal : candidates) {
    if (const auto contact = collisions_.check(toEigen(goal))) {
      if (first_problem.empty()) {
        first_problem = "at the goal, " + contact->str();
      }
      continue;
    }
    MotionPlan plan = planToJoints(goal, speed);
    if (plan.ok()) {
      return plan;
    }
    if (first_problem.empty()) {
      first_problem = plan.failure;
    }
  }
  return {nullptr, current,
          "none of the " + std::to_string(candidates.size()) + " arm configurations reaching the pose works (" +
              first_problem + ")"};
}

MotionPlan ArmComponent::planLine(const JointVector& current, const world::Pose& target, double speed) const {
  const world::Pose start = config_.base_in_world * kinematics_.forward(current) * config_.tcp_in_flange;
  const double distance = (target.translation() - start.translation()).norm();
  const double angle = world::rotationAngle(start, target);
  const int steps =
      std::max(1, static_cast<int>(std::ceil(std::max(distance / config_.line_step, angle / (2.0 * M_PI / 180.0)))));
  const Eigen::Quaterniond q0(start.linear());
  const Eigen::Quaterniond q1(target.linear());
  std::vector<JointVector> path{current};
  for (int i = 1; i <= steps; ++i) {
    const double s = static_cast<double>(i) / steps;
    world::Pose pose = world::Pose::Identity();
    pose.translation() = start.translation() + s * (target.translation() - start.translation());
    pose.linear() = q0.slerp(s, q1).toRotationMatrix();
    const std::vector<JointVector> options = solutions(pose, path.back());
    if (options.empty()) {
      return {nullptr, current, "the straight line leaves the arm's reach " + format("%.0f %% of the way", 100.0 * s)};
    }
    if (maxAbs(options.front(), path.back()) > 0.25) {
      return {nullptr, current, "the straight line passes too close to a singularity (a joint would have to flip)"};
    }
    path.push_back(options.front());
  }
  for (std::size_t i = 1; i < path.size(); ++i) {
    if (const auto contact = collisions_.checkSegment(toEigen(path[i - 1]), toEigen(path[i]))) {
      return {nullptr, current, "the straight line is blocked: " + contact->str()};
    }
  }
  return timed(std::move(path), speed);
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
  return std::make_unique<MotionOperation>(driver_, clock_, std::move(plan), motion_, config_, what);
}

std::unique_ptr<component::RunningOperation> ArmComponent::begin(const std::string& operation,
                                                                 const component::ParamMap& params) {
  const auto finished = [](OperationResult result) {
    return std::make_unique<component::FinishedOperation>(std::move(result));
  };
  const auto speed = [&params, this] {
    const auto it = params.find("speed");
    return it == params.end() ? config_.default_speed : it->second.asDouble();
  };

  if (operation == "Move") {
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
      return execute(planToJoints(waypoint->joints, speed()), "Move to '" + name + "'");
    }
    const auto pose = waypointPose(*waypoint);
    if (!pose) {
      return finished(OperationResult::failure("waypoint '" + name + "' is relative to '" + waypoint->frame +
                                               "', which is not known now"));
    }
    return execute(planToPose(*pose, speed()), "Move to '" + name + "'");
  }
  if (operation == "Home") {
    return execute(planToJoints(config_.home, speed()), "Home");
  }
  if (operation == "MoveToPose") {
    const std::string frame = params.at("frame").asString();
    const auto base = frame == "world" ? std::optional<world::Pose>(world::Pose::Identity())
                                       : (frames_ ? frames_(frame) : std::nullopt);
    if (!base) {
      return finished(OperationResult::failure("unknown frame '" + frame + "'"));
    }
    return execute(planToPose(*base * params.at("pose").asPose(), speed()), "MoveToPose");
  }
  if (operation == "MoveRelative" || operation == "JogCartesian") {
    world::Pose offset = world::Pose::Identity();
    if (operation == "MoveRelative") {
      offset = params.at("offset").asPose();
    } else {
      const std::string axis = params.at("axis").asString();
      const double amount = params.at("amount").asDouble();
      const int index = axis == "x" || axis == "roll" ? 0 : axis == "y" || axis == "pitch" ? 1 : 2;
      if (axis.size() == 1) {
        if (std::abs(amount) > 0.2) {
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
    return execute(planLine(target, speed()), operation);
  }
  if (operation == "JogJoint") {
    JointVector goal = checkedRead().position;
    goal[params.at("joint").asInt() - 1] += params.at("degrees").asDouble() * M_PI / 180.0;
    return execute(planToJoints(goal, speed()), "JogJoint");
  }
  if (operation == "Teach") {
    Waypoint waypoint;
    waypoint.name = params.at("waypoint").asString();
    if (params.at("kind").asString() == "joints") {
      waypoint.kind = Waypoint::Kind::kJoints;
      waypoint.joints = checkedRead().position;
    } else {
      waypoint.frame = params.at("frame").asString();
      const auto frame = waypoint.frame == "world" ? std::optional<world::Pose>(world::Pose::Identity())
                                                   : (frames_ ? frames_(waypoint.frame) : std::nullopt);
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
  if (operation == "RenameWaypoint" || operation == "DeleteWaypoint") {
    const std::string name = params.at("waypoint").asString();
    try {
      if (operation == "RenameWaypoint") {
        waypoints_.rename(name, params.at("new_name").asString());
      } else if (!waypoints_.remove(name)) {
        return finished(OperationResult::failure("unknown waypoint '" + name + "'"));
      }
    } catch (const std::exception& e) {
      return finished(OperationResult::failure(e.what()));
    }
    return finished(OperationResult::success());
  }
  return finished(OperationResult::failure("unknown operation " + operation));
}

world::Report ArmComponent::report() const {
  // A reading that cannot be trusted makes the report throw: the registry then stops the cell.
  const ArmState state = checkedRead();
  const world::Pose tcp = config_.base_in_world * kinematics_.forward(state.position) * config_.tcp_in_flange;
  const TimePoint now = clock_.now();
  world::Report report;
  report.symbols.push_back({"endpoint", "", now, world::FrameValue{"world", tcp}});
  report.symbols.push_back({"arm_joints", "", now,
                            world::JointsValue{std::vector<std::string>(std::begin(kJointNames), std::end(kJointNames)),
                                               std::vector<double>(state.position.begin(), state.position.end())}});
  if (maxAbs(state.velocity, JointVector{}) > 0.01) {
    report.predicates.push_back({"arm_moving", {}, true, ""});
  }
  for (const Waypoint& waypoint : waypoints_.all()) {
    if (waypoint.kind == Waypoint::Kind::kJoints) {
      report.symbols.push_back(
          {waypoint.name, "", now,
           world::JointsValue{std::vector<std::string>(std::begin(kJointNames), std::end(kJointNames)),
                              std::vector<double>(waypoint.joints.begin(), waypoint.joints.end())}});
      if (maxAbs(waypoint.joints, state.position) < config_.at_waypoint_joints) {
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
