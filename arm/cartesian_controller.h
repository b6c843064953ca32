#pragma once
// What an arm's controller offers for motions that touch things: Cartesian impedance (the LBR
// iiwa's CartesianImpedanceControlMode: stiffness and damping per Cartesian axis, a force limit
// that stops the motion) with one axis along which it regulates a force (the iiwa's desired
// force, a UR's force mode). The Arm component's MoveUntilContact, PressAndFollow and
// ReleaseContact are made of these motions; a technician never sees the gains (docs/FORCE.md).
//
// A motion follows a Cartesian path of the tool centre point (arm/cartesian_path.h) with the
// impedance: the tool is pulled toward the path's pose by the stiffness and slowed by the
// damping, so that it gives way when it meets something. Along the force axis, when there is
// one, the controller moves the path's pose (its offset, at most max_speed) until the tool
// pushes with the target force along it (an admittance): before contact the tool advances at
// max_speed, in contact it presses with the force. A force above force_limit stops the motion:
// the controller then holds the tool where it is, without pressing, and says so (state()).
// ArmDriver::execute() (a joint trajectory) ends a Cartesian motion at once.

#include <cstdint>
#include <memory>
#include <optional>

#include <Eigen/Core>

#include "arm/cartesian_path.h"
#include "arm/joints.h"
#include "core/clock.h"

namespace costar::arm {

/// The LBR iiwa's ranges: 0 to 5000 N/m, 0 to 300 N m/rad, damping ratio 0.1 to 1.
struct CartesianImpedance {
  Eigen::Vector3d stiffness = Eigen::Vector3d::Constant(2000.0);            // N/m along the tool's x, y, z
  Eigen::Vector3d rotational_stiffness = Eigen::Vector3d::Constant(200.0);  // N m/rad about them
  double damping_ratio = 0.7;

  static constexpr double kMaxStiffness = 5000.0;
  static constexpr double kMaxRotationalStiffness = 300.0;
};

/// The axis along which the controller regulates a force.
struct ForceAxis {
  Eigen::Vector3d direction = Eigen::Vector3d::UnitZ();  // unit vector in the world
  double force = 0.0;       // N the tool should push with along `direction` (0: touch lightly, let go)
  double max_speed = 0.02;  // m/s the controller may move the tool along it to get there
};

struct CartesianMotion {
  std::shared_ptr<const CartesianPath> path;  // the tool centre point's poses in the world
  CartesianImpedance impedance;
  std::optional<ForceAxis> force;
  /// N: a force (magnitude) above this stops the motion.
  double force_limit = 50.0;
  /// Redundant arms: the joints' configuration the controller keeps in the null space of the
  /// tool's motion (the elbow's); empty: where the joints are when the motion starts.
  JointVector posture{};
  /// Every joint held to `posture` too, not only in the null space, with this stiffness (N m/rad,
  /// damped critically on the joint's own inertia about `posture_velocity`): free-drive's
  /// configuration checked for collisions, which near a singularity the tool's impedance alone
  /// lets the arm leave (a UR5's elbow folded 1.6 rad away with the tool within 1 cm). 0: none.
  double joint_stiffness = 0.0;
  /// rad/s the posture moves at with the drift (empty: it holds).
  JointVector posture_velocity{};
  /// A streamed reference (free-drive's admittance, arm/free_drive.h): the path's pose moves on
  /// at this twist (world, m/s and rad/s) from the start for at most `horizon`, then holds, so
  /// that a stream of motions that stops leaves the tool held.
  struct Drift {
    Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
    Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();
    Duration horizon{};
  };
  std::optional<Drift> drift;
};

struct CartesianState {
  /// A Cartesian motion is in control (false: joint trajectories, ArmDriver::execute()).
  bool following = false;
  /// Counts follow() calls: which motion this state is of.
  std::uint64_t motion = 0;
  /// How far along its path the motion's pose is (m of CartesianPath::length()).
  double arc = 0.0;
  bool path_done = false;
  /// How far (m) the controller moved the path's pose along the force axis, toward the force.
  double offset = 0.0;
  /// The force (N, the tool's push along the force axis) the controller measures now.
  double axis_force = 0.0;
  /// The motion was stopped because the force exceeded its limit; `stop_force` is that force (N).
  bool force_limit_stop = false;
  double stop_force = 0.0;
  TimePoint stamp{};
};

class CartesianController {
 public:
  virtual ~CartesianController() = default;
  /// Follows `motion` from clock time `start`, replacing any motion (joint or Cartesian). The
  /// offset along the force axis starts where the tool is (no jump toward the path).
  virtual void follow(CartesianMotion motion, TimePoint start) = 0;
  /// Changes the target force along the force axis of the motion being followed (N).
  virtual void setForce(double force) = 0;
  virtual CartesianState state() const = 0;
  /// The most torque each joint's motor gives (N m).
  virtual JointVector torqueLimits() const = 0;
};

}  // namespace costar::arm
