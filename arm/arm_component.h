#pragma once
// A robot arm as a CoSTAR component implementing the abstract Arm (Teach, Move, `endpoint`).
// The robot is data: its kinematics (arm/kinematics.h: joint count, limits, forward and
// inverse) and its configuration (base, tool, home, joint names); nothing here is specific to
// one arm.
//
// Every motion is planned before it runs (arm/motion_planner.h: IK within the limits, the
// first collision-free solution, the motion checked along its whole length and planned around
// obstacles with OMPL when needed), time-parameterized within the joint velocity and
// acceleration limits (scaled by the operation's speed) and handed to the driver. Cancelling
// decelerates along the path within the acceleration limits and stops.
//
// Operations (one table of spec and handler, component/operation_table.h): Move(waypoint),
// Home, MoveToPose(pose, frame), MoveRelative(offset, frame) (a straight Cartesian line),
// Teach(waypoint, kind, frame), RenameWaypoint, DeleteWaypoint, JogJoint(joint, degrees),
// JogCartesian(axis, amount, frame); and, for other components only (no node type),
// FollowJointPath(path, speed, label): follows joint waypoints planned by the cell's motion
// service (arm/motion_service.h), timed within the arm's limits: how SmartMove moves the arm.
// Symbols: endpoint (the tool centre point in the world), arm_joints, and every waypoint
// (pose waypoints as frames relative to their frame, joint waypoints as configurations).
// Predicates: arm_moving, at_waypoint(w).
//
// With a wrist force/torque sensor (ForceControl): the symbol `wrench` (what the tool pushes
// its surroundings with, in the tool frame about the tool centre point), the predicate
// `in_contact` and the operation Tare; the component zeroes the sensor once when it starts.
// With the controller's Cartesian impedance mode as well: MoveUntilContact, PressAndFollow,
// ReleaseContact and ForgetPressed, and the predicate pressed_at(w) (docs/FORCE.md:
// arm/force_operations.cpp), and FreeDrive(mode, locked, axes, hold): hand guiding, moving while
// its dead-man is held (holdFreeDrive), the predicate free_driving (docs/TEACHING.md:
// arm/free_drive.h, arm/free_drive_operation.cpp).

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "arm/arm_config.h"
#include "arm/arm_driver.h"
#include "arm/arm_motion.h"
#include "arm/cartesian_controller.h"
#include "arm/force_torque.h"
#include "arm/kinematics.h"
#include "arm/motion_planner.h"
#include "arm/trajectory.h"
#include "arm/waypoints.h"
#include "component/operation_table.h"
#include "planning/collision_world.h"

namespace costar::arm {

/// The force sensing and compliant motion an arm may have (both optional): the wrist
/// force/torque sensor and the controller's Cartesian impedance mode.
struct ForceControl {
  ForceTorqueSensor* sensor = nullptr;
  CartesianController* controller = nullptr;
  /// What the sensor carries (its weight is taken out of free-drive's readings).
  Payload payload;
};

class ArmComponent final : public component::TableComponent {
 public:
  /// Pose in the world of a frame symbol ("table_center", a part...), or nullopt if unknown.
  using FrameLookup = std::function<std::optional<world::Pose>(const std::string&)>;

  /// Everything passed by reference must outlive the component. `collisions` holds the
  /// table and known parts; the component adds nothing to it. `kinematics` is the arm's
  /// (its joint count and limits are the arm's).
  /// Throws std::invalid_argument without kinematics, or when `config.home` does not have one
  /// angle per joint.
  ArmComponent(ArmDriver& driver, const Clock& clock, const planning::CollisionWorld& collisions,
               WaypointStore& waypoints, FrameLookup frames, std::shared_ptr<const Kinematics> kinematics,
               ArmConfig config, ForceControl force = {});

  world::Report report() const override;

  // --- planning, for the operations and the calibration (other components ask the cell's
  // motion service, arm/motion_service.h, and move the arm with FollowJointPath) -----------
  /// The tool centre point's pose in the world now (from the joint encoders).
  world::Pose endpoint() const;
  /// Every IK solution for a TCP pose in the world, each expressed nearest to `seed` within
  /// the joint limits, nearest first.
  std::vector<JointVector> solutions(const world::Pose& tcp_in_world, const JointVector& seed) const {
    return planner_->solutions(tcp_in_world, seed);
  }
  /// The joint configuration now (from the encoders).
  JointVector joints() const { return checkedRead().position; }
  /// The driver's reading, checked: finite and fresh.
  /// @throws std::runtime_error naming the problem (NaN joints, a state that stopped updating,
  /// or the driver's own error).
  ArmState checkedRead() const { return planner_->checkedRead(); }
  /// Stops any motion now: decelerates along its path within the acceleration limits. Needs
  /// no reading from the driver (it may be the thing that failed). The motion's operation
  /// then fails.
  void stop();
  /// A collision-free motion from the current configuration to the TCP pose.
  MotionPlan planToPose(const world::Pose& tcp_in_world, double speed) const {
    return planner_->planToPose(joints(), tcp_in_world, speed);
  }
  /// A collision-free motion from `from` (default: where the arm is) to `goal`.
  MotionPlan planToJoints(const JointVector& goal, double speed) const { return planToJoints(joints(), goal, speed); }
  MotionPlan planToJoints(const JointVector& from, const JointVector& goal, double speed) const {
    return planner_->planToJoints(from, goal, speed);
  }
  /// A straight Cartesian line of the TCP from where it is (or from `from`) to `tcp_in_world`.
  MotionPlan planLine(const world::Pose& tcp_in_world, double speed) const {
    return planLine(joints(), tcp_in_world, speed);
  }
  MotionPlan planLine(const JointVector& from, const world::Pose& tcp_in_world, double speed) const {
    return planner_->planLine(from, tcp_in_world, speed);
  }
  /// TCP pose in the world at a joint configuration.
  world::Pose toolAt(const JointVector& q) const { return planner_->toolAt(q); }

  /// Runs a plan. Fails at once (nothing moves) when the plan is empty.
  std::unique_ptr<component::RunningOperation> execute(MotionPlan plan, const std::string& what);

  const ArmConfig& config() const { return config_; }
  /// The taught waypoints and recorded trajectories.
  const WaypointStore& waypoints() const { return waypoints_; }
  /// Number of joints of the arm.
  int jointCount() const { return kinematics_->jointCount(); }
  const Kinematics& kinematics() const { return *kinematics_; }
  const JointLimits& limits() const { return kinematics_->limits(); }

  // --- free-drive (arm/free_drive.h; its FreeDrive operation, with the force control) -------
  /// The dead-man: a running FreeDrive moves only while held; this holds it for `duration` more
  /// of the clock's time (the page's pointer or a key held down). False when none runs.
  bool holdFreeDrive(Duration duration);
  /// Lets go: the running FreeDrive stops the arm, which holds where it is, and ends.
  void releaseFreeDrive();
  struct FreeDriveStatus {
    bool active = false;
    std::string mode;       // the guiding mode (GuidingMode::str())
    std::string blocked;    // why the last step was not (wholly) taken: a limit, a contact ahead
    Wrench hand;            // the push it measures (world, at the tool centre point)
    double speed = 0.0;     // m/s of its reference
    double tracking = 0.0;  // m: the tool from its reference, measured (the protective stop's, arm/free_drive.h)
    JointVector checked{};  // the joints its reference was checked at (for collisions, limits, speed)
  };
  FreeDriveStatus freeDriveStatus() const;

  /// The contact threshold of in_contact (N, the force's magnitude).
  static constexpr double kContactForce = 4.0;
  /// The force-controlled operations' ranges (also their parameters' min and max).
  static constexpr double kMaxContactForce = 60.0;  // N: the most MoveUntilContact or PressAndFollow presses with
  static constexpr double kMaxForceLimit = 150.0;   // N: the highest max_force
  /// m/s: the fastest MoveUntilContact approaches. A rigid tool meeting a rigid surface stops in a
  /// few milliseconds, before any controller can act: the arm's momentum alone pushes with about
  /// 1.1 to 1.3 N per mm/s on the simulated cells (docs/FORCE.md "Contact at speed"), so faster
  /// than this the touch itself overshoots 10 N by more than a few newtons.
  static constexpr double kMaxApproachSpeed = 0.01;

 private:
  /// Declares the operations, each with its handler.
  void declareOperations();
  double speedOf(const component::ParamMap& params) const;
  std::optional<world::Pose> waypointPose(const Waypoint& waypoint) const;
  std::optional<world::Pose> frameInWorld(const std::string& frame) const;
  /// Why `name` cannot be a new waypoint's (empty when it can): "world", the arm's own symbols
  /// ("endpoint"), or a frame another component publishes ("camera", "table_center", a part).
  std::string nameTaken(const std::string& name) const;
  // The operations' handlers.
  std::unique_ptr<component::RunningOperation> move(const component::ParamMap& params);
  std::unique_ptr<component::RunningOperation> straightLine(const std::string& operation,
                                                            const component::ParamMap& params);
  std::unique_ptr<component::RunningOperation> jogJoint(const component::ParamMap& params);
  std::unique_ptr<component::RunningOperation> teach(const component::ParamMap& params);
  std::unique_ptr<component::RunningOperation> renameOrDelete(bool rename, const component::ParamMap& params);
  std::unique_ptr<component::RunningOperation> followJointPath(const component::ParamMap& params);
  // The force-controlled operations (arm/force_operations.cpp).
  void declareForceOperations(component::ComponentDescription& description, component::OperationTable& operations);
  void reportForce(world::Report& report) const;
  std::unique_ptr<component::RunningOperation> tare();
  std::unique_ptr<component::RunningOperation> moveUntilContact(const component::ParamMap& params);
  std::unique_ptr<component::RunningOperation> pressAndFollow(const component::ParamMap& params);
  std::unique_ptr<component::RunningOperation> releaseContact(const component::ParamMap& params);
  // Free-drive (arm/free_drive_operation.cpp).
  void declareFreeDrive(component::OperationTable& operations);
  std::unique_ptr<component::RunningOperation> freeDrive(const component::ParamMap& params);
  // Replaying recorded trajectories (arm/follow_trajectory.cpp).
  void declareFollowTrajectory(component::OperationTable& operations);
  std::unique_ptr<component::RunningOperation> followTrajectory(const component::ParamMap& params);
  /// The wrist's wrench in the tool frame about the tool centre point.
  Wrench toolWrench(const Wrench& sensor) const;

  ArmDriver& driver_;
  const Clock& clock_;
  WaypointStore& waypoints_;
  FrameLookup frames_;
  std::shared_ptr<const Kinematics> kinematics_;
  ArmConfig config_;
  std::optional<MotionPlanner> planner_;  // set once the configuration is checked
  std::shared_ptr<ArmMotion> motion_ = std::make_shared<ArmMotion>();
  ForceControl force_;
  /// What the force-controlled operations remember (arm/force_operations.cpp): which waypoints
  /// the tool pressed through, where an interrupted PressAndFollow stopped, which controller
  /// motion is pressing now.
  struct Pressing;
  std::shared_ptr<Pressing> pressing_;
  /// The running FreeDrive's dead-man and state, shared with its operation.
  struct FreeDriving;
  std::shared_ptr<FreeDriving> free_driving_;
};

}  // namespace costar::arm
