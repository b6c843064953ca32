#include "arm/motion_planner.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace costar::arm {

namespace {

std::string format(const char* pattern, double value) {
  char text[96];
  std::snprintf(text, sizeof text, pattern, value);
  return text;
}

/// How far (rad) beyond a limit a motion may start: an arm that was sent to a joint limit reads
/// a hair beyond it (a tracking error of ~1e-7 rad in the simulator, an encoder count on
/// hardware), and a motion from there must still be planned. Such a start is taken as at the
/// limit; further out, the trajectory refuses it with the joint and the distance.
constexpr double kStartBeyondLimitTolerance = 1e-3;

/// `q` with each joint that lies beyond its limit by at most `tolerance` put on the limit.
JointVector atLimitsWithin(const JointVector& q, const JointLimits& limits, double tolerance) {
  JointVector result = q;
  for (int j = 0; j < q.size(); ++j) {
    if (q[j] > limits.max_position[j] && q[j] <= limits.max_position[j] + tolerance) {
      result[j] = limits.max_position[j];
    } else if (q[j] < limits.min_position[j] && q[j] >= limits.min_position[j] - tolerance) {
      result[j] = limits.min_position[j];
    }
  }
  return result;
}

}  // namespace

std::string readingProblem(const ArmState& state, TimePoint now, Duration timeout,
                           const std::vector<std::string>& joint_names) {
  // Velocities: one per joint, or none from a driver that does not measure them.
  const int count = static_cast<int>(joint_names.size());
  if (state.position.size() != count || (state.velocity.size() != count && !state.velocity.empty())) {
    return "arm driver: the joint state has " + std::to_string(state.position.size()) + " positions and " +
           std::to_string(state.velocity.size()) + " velocities for " + std::to_string(count) + " joints";
  }
  for (int j = 0; j < count; ++j) {
    if (!std::isfinite(state.position[j]) || (!state.velocity.empty() && !std::isfinite(state.velocity[j]))) {
      return "arm driver: the joint state is not a number (" + joint_names[j] + ")";
    }
  }
  if (state.stamp != TimePoint{} && now - state.stamp > timeout) {
    return "arm driver: the joint state stopped updating (" + format("%.3f", toSeconds(now - state.stamp)) + " s old)";
  }
  return {};
}

MotionPlanner::MotionPlanner(const ArmDriver& driver, const Clock& clock, const planning::CollisionWorld& collisions,
                             std::shared_ptr<const Kinematics> kinematics, const ArmConfig& config)
    : driver_(driver),
      clock_(clock),
      collisions_(collisions),
      kinematics_(std::move(kinematics)),
      base_in_world_(config.base_in_world),
      tcp_in_flange_(config.tcp_in_flange),
      joint_names_(config.joint_names),
      state_timeout_(config.state_timeout),
      line_step_(config.line_step),
      planner_(config.planner) {
  if (kinematics_ == nullptr) {
    throw std::invalid_argument("motion planner of '" + config.name + "': no kinematics");
  }
  if (joint_names_.empty()) {
    for (int j = 1; j <= kinematics_->jointCount(); ++j) {
      joint_names_.push_back("joint_" + std::to_string(j));
    }
  }
}

ArmState MotionPlanner::checkedRead() const {
  const ArmState state = driver_.read();
  if (const std::string problem = readingProblem(state, clock_.now(), state_timeout_, joint_names_); !problem.empty()) {
    throw std::runtime_error(problem);
  }
  return state;
}

world::Pose MotionPlanner::toolAt(const JointVector& q) const {
  return base_in_world_ * kinematics_->forward(q) * tcp_in_flange_;
}

world::Pose MotionPlanner::flangeInBase(const world::Pose& tcp_in_world) const {
  return base_in_world_.inverse() * tcp_in_world * tcp_in_flange_.inverse();
}

std::vector<JointVector> MotionPlanner::solutions(const world::Pose& tcp_in_world, const JointVector& seed) const {
  IkSolutions found;
  kinematics_->solutionsNear(flangeInBase(tcp_in_world), seed, found);
  return std::vector<JointVector>(found.begin(), found.end());
}

std::optional<planning::Contact> MotionPlanner::collision(const JointVector& q, const QueryScene& scene) const {
  return collisions_.check(q.eigen(), scene);
}

std::optional<planning::Contact> MotionPlanner::collisionAlong(const JointVector& from, const JointVector& to,
                                                               const QueryScene& scene) const {
  return collisions_.checkSegment(from.eigen(), to.eigen(), scene);
}

std::vector<std::string> MotionPlanner::obstacleNames() const { return collisions_.obstacleNames(); }

double MotionPlanner::largestDisplacement(const JointVector& from, const JointVector& to) const {
  const planning::RobotModel& robot = collisions_.robot();
  std::vector<world::Pose> before;
  std::vector<world::Pose> after;
  robot.linkPoses(from.eigen(), before);
  robot.linkPoses(to.eigen(), after);
  double largest = 0.0;
  for (std::size_t i = 0; i < robot.links().size(); ++i) {
    for (const planning::CollisionShape& shape : robot.links()[i].shapes) {
      double reach = shape.size.x();  // a sphere's radius
      if (shape.kind == planning::CollisionShape::Kind::kBox) {
        reach = 0.5 * shape.size.norm();
      } else if (shape.kind == planning::CollisionShape::Kind::kCylinder) {
        reach = std::hypot(shape.size.x(), 0.5 * shape.size.y());
      }
      const world::Pose a = before[i] * shape.origin;
      const world::Pose b = after[i] * shape.origin;
      largest = std::max(largest, (b.translation() - a.translation()).norm() + world::rotationAngle(a, b) * reach);
    }
  }
  return largest;
}

MotionPlan MotionPlanner::timed(std::vector<JointVector> path, double speed) const {
  if (path.size() < 2) {
    return MotionPlan::failed(path.empty() ? JointVector{} : path.back(),
                              "a path needs a start and a goal, not " + std::to_string(path.size()) + " point(s)");
  }
  MotionPlan plan;
  try {
    plan.goal = path.back();
    plan.trajectory = std::make_shared<JointTrajectory>(
        path.size() == 2 ? JointTrajectory::pointToPoint(path.front(), path.back(), kinematics_->limits(), speed)
                         : JointTrajectory::alongPath(path, kinematics_->limits(), speed));
    plan.path = std::move(path);
    plan.speed = speed;
  } catch (const std::invalid_argument& e) {
    plan.trajectory.reset();
    plan.failure = e.what();
  }
  return plan;
}

MotionPlan MotionPlanner::planToJoints(const JointVector& from, const JointVector& goal, double speed,
                                       const QueryScene& scene) const {
  const JointLimits& limits = kinematics_->limits();
  if (goal.size() != limits.size() || from.size() != limits.size()) {
    return MotionPlan::failed(goal, "the goal has " + std::to_string(goal.size()) + " joints and the start " +
                                        std::to_string(from.size()) + ", the arm " + std::to_string(limits.size()));
  }
  const JointVector start = atLimitsWithin(from, limits, kStartBeyondLimitTolerance);
  for (int j = 0; j < goal.size(); ++j) {
    if (goal[j] < limits.min_position[j] || goal[j] > limits.max_position[j]) {
      return MotionPlan::failed(goal, "joint " + std::to_string(j + 1) + " would leave its limits");
    }
  }
  const planning::PlanResult path = planning::planPath(collisions_, start.eigen(), goal.eigen(), planner_, scene);
  if (!path.ok()) {
    return MotionPlan::failed(goal, path.failure);
  }
  std::vector<JointVector> joints;
  for (const auto& q : path.path) {
    joints.push_back(JointVector::fromEigen(q));
  }
  return timed(std::move(joints), speed);
}

MotionPlan MotionPlanner::planToPose(const JointVector& from, const world::Pose& tcp_in_world, double speed,
                                     const QueryScene& scene) const {
  const std::vector<JointVector> candidates = solutions(tcp_in_world, from);
  if (candidates.empty()) {
    return MotionPlan::failed(from,
                              "the pose is out of reach (no inverse kinematics solution within the joint limits)");
  }
  std::string first_problem;
  for (const JointVector& goal : candidates) {
    if (const auto contact = collision(goal, scene)) {
      if (first_problem.empty()) {
        first_problem = "at the goal, " + contact->str();
      }
      continue;
    }
    MotionPlan plan = planToJoints(from, goal, speed, scene);
    if (plan.ok()) {
      return plan;
    }
    if (first_problem.empty()) {
      first_problem = plan.failure;
    }
  }
  return MotionPlan::failed(from, "none of the " + std::to_string(candidates.size()) +
                                      " arm configurations reaching the pose works (" + first_problem + ")");
}

MotionPlan MotionPlanner::planLine(const JointVector& from, const world::Pose& target, double speed,
                                   const QueryScene& scene) const {
  const JointVector current = from.size() == kinematics_->limits().size()
                                  ? atLimitsWithin(from, kinematics_->limits(), kStartBeyondLimitTolerance)
                                  : from;
  const world::Pose start = toolAt(current);
  const double distance = (target.translation() - start.translation()).norm();
  const double angle = world::rotationAngle(start, target);
  const int steps =
      std::max(1, static_cast<int>(std::ceil(std::max(distance / line_step_, angle / (2.0 * M_PI / 180.0)))));
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
      return MotionPlan::failed(current,
                                "the straight line leaves the arm's reach " + format("%.0f %% of the way", 100.0 * s));
    }
    if (maxAbsDifference(options.front(), path.back()) > 0.25) {
      return MotionPlan::failed(current,
                                "the straight line passes too close to a singularity (a joint would have to flip)");
    }
    path.push_back(options.front());
  }
  planning::CollisionWorld::Query query = collisions_.query(scene);
  for (std::size_t i = 1; i < path.size(); ++i) {
    if (const auto contact = query.checkSegment(path[i - 1].eigen(), path[i].eigen())) {
      return MotionPlan::failed(current, "the straight line is blocked: " + contact->str());
    }
  }
  return timed(std::move(path), speed);
}

}  // namespace costar::arm
