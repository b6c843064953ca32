#pragma once
// What other components ask about an arm's motion (SmartMove, Calibrate, ...): where the arm
// is, the inverse kinematics within the joint limits, collision queries and motion plans. Every
// query carries its scene (planning::QueryScene): the contacts it allows (the fingers may touch
// the part being grasped), the gripper's fingers as the motion will have them, obstacles only
// it has (a keep-out box) or leaves out (the part held); nothing is toggled in a shared
// collision world around a query. Every query is const and takes all it needs as arguments,
// so a service in another process could answer it, and the cell's own answers several at once.
//
// The workcell builds the service (arm/motion_planner.h: the arm's kinematics and the cell's
// collision world) and hands it to the components that need it. They move the arm through its
// operations (FollowJointPath, with a plan's joint waypoints), never through the arm's class,
// so they would work the same with the arm behind a process boundary.

#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "arm/joints.h"
#include "arm/trajectory.h"
#include "component/value.h"
#include "planning/collision_world.h"
#include "world/pose.h"

namespace costar::arm {

/// A motion ready to run, or why there is none.
struct MotionPlan {
  std::shared_ptr<const JointTrajectory> trajectory;
  JointVector goal{};
  std::string failure;
  /// The joint waypoints the trajectory passes through, start first (the arm's FollowJointPath
  /// takes them and the speed, and times them again the same way).
  std::vector<JointVector> path;
  /// The fraction of the joint speed and acceleration limits it was timed at.
  double speed = 0.0;

  bool ok() const { return trajectory != nullptr; }
  static MotionPlan failed(const JointVector& goal, std::string reason) {
    MotionPlan plan;
    plan.goal = goal;
    plan.failure = std::move(reason);
    return plan;
  }
};

using planning::AllowedContacts;
using planning::QueryScene;

/// The arm's operation that follows a planned path (for other components; no node type).
inline constexpr std::string_view kFollowJointPath = "FollowJointPath";
/// A path as FollowJointPath's `path` parameter: JSON [[q1, ..., qn], ...] in radians, every
/// angle written so that it reads back exactly.
std::string pathParam(const std::vector<JointVector>& path);
/// Reads a `path` parameter of `joint_count` angles a point, at least two points, every angle
/// a finite number. @throws std::invalid_argument naming the point and the problem.
std::vector<JointVector> pathFromParam(std::string_view text, int joint_count);
/// FollowJointPath's parameters for a plan (its path and speed), called `label` in messages.
/// @pre plan.ok()
component::ParamMap followParams(const MotionPlan& plan, const std::string& label);

class MotionService {
 public:
  virtual ~MotionService() = default;

  /// The joint configuration now. @throws std::runtime_error when the arm's reading cannot be
  /// trusted (not a number, stopped updating, the driver's own error), naming the problem.
  virtual JointVector joints() const = 0;
  /// The tool centre point's pose in the world now. @throws like joints().
  virtual world::Pose endpoint() const = 0;
  /// The tool centre point's pose in the world at `q`.
  virtual world::Pose toolAt(const JointVector& q) const = 0;
  /// Every IK solution for a TCP pose in the world within the joint limits, each expressed
  /// nearest to `seed`, nearest first (not checked for collisions: see collision()).
  virtual std::vector<JointVector> solutions(const world::Pose& tcp_in_world, const JointVector& seed) const = 0;
  /// What the arm would touch at `q` in the cell as `scene` changes it, or nullopt.
  virtual std::optional<planning::Contact> collision(const JointVector& q, const QueryScene& scene) const = 0;

  /// A collision-free joint-space motion from `from` to `goal` (straight when it is free, else
  /// planned around), timed at `speed` (a fraction of the joint speed and acceleration limits).
  /// A `from` (here and in planLine) a hair beyond a joint limit, as an arm sent to the limit
  /// reads, starts on the limit; further beyond it the plan fails naming the joint.
  virtual MotionPlan planToJoints(const JointVector& from, const JointVector& goal, double speed,
                                  const QueryScene& scene = {}) const = 0;
  /// A straight Cartesian line of the TCP from the pose at `from` to `tcp_in_world`.
  virtual MotionPlan planLine(const JointVector& from, const world::Pose& tcp_in_world, double speed,
                              const QueryScene& scene = {}) const = 0;
  /// A collision-free motion from `from` to the TCP pose: the first IK solution (nearest
  /// `from`) that is free and reachable.
  virtual MotionPlan planToPose(const JointVector& from, const world::Pose& tcp_in_world, double speed,
                                const QueryScene& scene = {}) const = 0;

  /// The first of `candidates` free of collisions, or nullopt with the first contact found in
  /// `reason` (left as it is when there is no candidate).
  std::optional<JointVector> firstFree(const std::vector<JointVector>& candidates, const QueryScene& scene,
                                       std::string& reason) const {
    for (const JointVector& q : candidates) {
      const auto contact = collision(q, scene);
      if (!contact) {
        return q;
      }
      if (reason.empty()) {
        reason = contact->str();
      }
    }
    return std::nullopt;
  }
};

}  // namespace costar::arm
