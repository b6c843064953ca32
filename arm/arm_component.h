#pragma once
// The UR5 as a CoSTAR component implementing the abstract Arm (Teach, Move, `endpoint`).
//
// Every motion is planned before it runs: the goal is solved with the closed-form IK (the
// nearest solution within the joint limits whose configuration is collision-free), the
// straight joint-space motion is collision-checked along its whole length against the table,
// known parts and the arm itself, and when it would collide OMPL plans a way around. The
// motion is then time-parameterized within the joint velocity and acceleration limits
// (scaled by the operation's speed) and handed to the driver. Cancelling decelerates along
// the path within the acceleration limits and stops.
//
// Operations: Move(waypoint), Home, MoveToPose(pose, frame), MoveRelative(offset, frame)
// (a straight Cartesian line), Teach(waypoint, kind, frame), RenameWaypoint, DeleteWaypoint,
// JogJoint(joint, degrees), JogCartesian(axis, amount, frame).
// Symbols: endpoint (the tool centre point in the world), arm_joints, and every waypoint
// (pose waypoints as frames relative to their frame, joint waypoints as configurations).
// Predicates: arm_moving, at_waypoint(w).

#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "arm/arm_driver.h"
#include "arm/trajectory.h"
#include "arm/ur5_kinematics.h"
#include "arm/waypoints.h"
#include "component/component.h"
#include "planning/collision_world.h"
#include "planning/planner.h"

namespace costar::arm {

struct ArmConfig {
  std::string name = "arm";
  std::string type = "UR5";
  /// Where the robot's base frame is in the world.
  world::Pose base_in_world = world::Pose::Identity();
  /// The tool centre point in the flange frame (between the gripper's finger pads).
  world::Pose tcp_in_flange = world::Pose(Eigen::Translation3d(0, 0, 0.14));
  JointLimits limits = JointLimits::ur5();
  JointVector home{};
  /// Default speed of motions: a fraction of the joint velocity and acceleration limits.
  double default_speed = 0.5;
  /// at_waypoint tolerances.
  double at_waypoint_distance = 0.005;            // m
  double at_waypoint_angle = 2.0 * M_PI / 180.0;  // rad
  double at_waypoint_joints = 0.01;               // rad
  /// A motion fails if the arm is not within this of its goal this long after the end.
  double arrival_tolerance = 0.005;  // rad
  Duration settle_time = std::chrono::seconds(1);
  /// A joint state older than this (by the driver's stamp) means the driver stopped updating.
  Duration state_timeout = std::chrono::milliseconds(50);
  /// Cartesian straight lines are followed through IK points this far apart.
  double line_step = 0.005;  // m
  planning::PlannerOptions planner;
};

/// A motion ready to run, or why there is none.
struct MotionPlan {
  std::shared_ptr<const JointTrajectory> trajectory;
  JointVector goal{};
  std::string failure;
  bool ok() const { return trajectory != nullptr; }
};

/// The motion the driver follows, shared by the component and the motion's operation.
struct ArmMotion {
  std::uint64_t counter = 0;  // bumped by every new motion and every stop
  std::shared_ptr<const JointTrajectory> trajectory;
  TimePoint start{};
};

class ArmComponent final : public component::LocalComponent {
 public:
  /// Pose in the world of a frame symbol ("table_center", a part...), or nullopt if unknown.
  using FrameLookup = std::function<std::optional<world::Pose>(const std::string&)>;

  /// Everything passed by reference must outlive the component. `collisions` holds the
  /// table and known parts; the component adds nothing to it.
  ArmComponent(ArmDriver& driver, const Clock& clock, planning::CollisionWorld& collisions, WaypointStore& waypoints,
               FrameLookup frames, ArmConfig config);

  const component::ComponentDescription& description() const override { return description_; }
  world::Report report() const override;

  // --- planning, for other components (SmartMove) and the operations -------------------
  /// The tool centre point's pose in the world now (from the joint encoders).
  world::Pose endpoint() const;
  /// Every IK solution for a TCP pose in the world, each expressed nearest to `seed` within
  /// the joint limits, nearest first.
  std::vector<JointVector> solutions(const world::Pose& tcp_in_world, const JointVector& seed) const;
  /// The joint configuration now (from the encoders).
  JointVector joints() const { return checkedRead().position; }
  /// The driver's reading, checked: finite and fresh.
  /// @throws std::runtime_error naming the problem (NaN joints, a state that stopped updating,
  /// or the driver's own error).
  ArmState checkedRead() const;
  /// Stops any motion now: decelerates along its path within the acceleration limits. Needs
  /// no reading from the driver (it may be the thing that failed). The motion's operation
  /// then fails.
  void stop();
  /// A collision-free motion from the current configuration to the TCP pose.
  MotionPlan planToPose(const world::Pose& tcp_in_world, double speed) const;
  /// A collision-free motion from `from` (default: where the arm is) to `goal`.
  MotionPlan planToJoints(const JointVector& goal, double speed) const { return planToJoints(joints(), goal, speed); }
  MotionPlan planToJoints(const JointVector& from, const JointVector& goal, double speed) const;
  /// A straight Cartesian line of the TCP from where it is (or from `from`) to `tcp_in_world`.
  MotionPlan planLine(const world::Pose& tcp_in_world, double speed) const {
    return planLine(joints(), tcp_in_world, speed);
  }
  MotionPlan planLine(const JointVector& from, const world::Pose& tcp_in_world, double speed) const;
  /// TCP pose in the world at a joint configuration.
  world::Pose toolAt(const JointVector& q) const;

  /// Runs a plan. Fails at once (nothing moves) when the plan is empty or does not start
  /// where the arm is.
  std::unique_ptr<component::RunningOperation> execute(MotionPlan plan, const std::string& what);

  const ArmConfig& config() const { return config_; }
  const Ur5Kinematics& kinematics() const { return kinematics_; }

 private:
  std::unique_ptr<component::RunningOperation> begin(const std::string& operation,
                                                     const component::ParamMap& params) override;
  std::optional<world::Pose> waypointPose(const Waypoint& waypoint) const;
  world::Pose flangeInBase(const world::Pose& tcp_in_world) const;
  MotionPlan timed(std::vector<JointVector> path, double speed) const;
  Eigen::VectorXd toEigen(const JointVector& q) const;

  component::ComponentDescription description_;
  ArmDriver& driver_;
  const Clock& clock_;
  planning::CollisionWorld& collisions_;
  WaypointStore& waypoints_;
  FrameLookup frames_;
  ArmConfig config_;
  Ur5Kinematics kinematics_;
  std::shared_ptr<ArmMotion> motion_ = std::make_shared<ArmMotion>();
};

}  // namespace costar::arm
