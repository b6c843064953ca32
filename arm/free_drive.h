#pragma once
// Free-drive (hand guiding): the abstract Arm's Teach as a person does it with a UR's free-drive
// button or a Franka's guiding mode. The wrist sensor measures the hand's push on the tool; the
// controller keeps compensating gravity and follows a reference that moves as an admittance,
// velocity = push / damping, within the teaching speed (250 mm/s at the tool, as collaborative
// operation standards reduce it), the joint limits and the joints' speed, and never into the
// table or a known part: each step of the reference is checked (inverse kinematics within the
// limits less a margin, the configuration and one a stopping distance ahead free of collisions)
// before the controller gets it, and a step that fails is not taken: the tool stops before the
// contact, and slides along it when pushed aslant. Guiding modes (Franka's): free, translation only,
// rotation only, and any of the six axes locked (world or tool axes).
//
// This file is the arithmetic, with no robot behind it (arm/test/free_drive_test.cpp); the Arm
// component's FreeDrive operation (arm/free_drive_operation.cpp) runs it every tick and holds the
// dead-man (ArmComponent::holdFreeDrive).

#include <array>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "arm/force_torque.h"
#include "arm/joints.h"
#include "world/pose.h"

namespace costar::arm {

/// Which of the tool's six motions the hand may cause.
struct GuidingMode {
  /// x, y, z, then rotations about x, y, z; true: locked (the hand cannot move it).
  std::array<bool, 6> locked{};
  /// The axes are the tool's (true) or the world's.
  bool tool_axes = false;

  /// `mode`: free, translation (rotations locked), rotation (translations locked); `locked`: a
  /// comma-separated list of further axes to lock (x, y, z, rx, ry, rz; empty: none); `axes`:
  /// world or tool. @throws std::invalid_argument naming the field and the value refused.
  static GuidingMode parse(const std::string& mode, const std::string& locked, const std::string& axes);
  /// "free", "translation", "rotation", or the locked axes ("locked z, rx (world)").
  std::string str() const;
};

/// How the reference answers the hand (Franka's and UR's figures are of this order).
struct AdmittanceGains {
  double damping = 100.0;             // N s/m: a push of 15 N beyond the dead band moves the tool at 0.15 m/s
  double rotational_damping = 2.5;    // N m s/rad
  double dead_band = 3.0;             // N: pushes below this do nothing (the sensor's noise, the payload's error)
  double rotational_dead_band = 0.3;  // N m
  double max_speed = 0.15;            // m/s of the reference: the tool stays within 0.25 m/s
  double max_rotation_speed = 0.6;    // rad/s
  double acceleration = 1.5;          // m/s^2 (and rad/s^2 x 4) of the reference
  /// How far ahead along the motion (m) the arm's links must be free too: the tool stops this far
  /// before a contact of the arm's links at most (the collision world pads the arm besides: 5 mm
  /// in the simulated cells). The gripper's links look less far ahead: the distance the
  /// reference needs to stop from its speed (speed^2 / 2 acceleration) and `clearance` along the
  /// motion, plus how far the hand's push moves the tool past the reference (push / stiffness),
  /// within look_ahead (gripperLookAhead()). The whole 4 cm for the gripper too kept its body
  /// 4.5 cm above a part it was guided down onto, and a grasp taught there 3.2 cm higher than
  /// one that holds the part.
  double look_ahead = 0.04;
  /// How stiffly the controller holds the tool to the reference (N/m): a hand that pushes on past
  /// a wall moves the tool push / stiffness beyond the reference (the joints' hold makes it
  /// stiffer still: 40 N moved the UR5's tool 7.5 mm).
  double stiffness = 4000.0;
  double rotational_stiffness = 200.0;  // N m/rad
  /// Kept beyond the stopping distance and the push's give (m).
  double clearance = 0.002;
  /// m/s any point of the arm (an elbow swinging, not only the tool) moves at most: the tool
  /// stays within 0.25 m/s with the controller's lag, and so does every link.
  double max_point_speed = 0.2;
  /// The joints stay this far (rad) inside their limits.
  double joint_margin = 0.05;
  /// The joints turn at most this fraction of their top speed.
  double joint_speed_fraction = 0.5;
  /// Near a singularity (the arm's dexterity, below, under `singular_slow`) a step that brings it
  /// nearer slows in proportion to what is left above `singular_floor`, and none goes below the
  /// floor; a step away from the singularity is free. As a UR's free-drive grows heavy near a
  /// limit: the hand feels it, and the status says why.
  double singular_slow = 0.02;    // m/rad
  double singular_floor = 0.008;  // m/rad
};

/// How far the arm is from a singularity: the smallest singular value of the tool's Jacobian
/// (its rotation rows counted at 0.1 m per rad, so that both are m/rad), and the joints that move
/// most along the direction the tool loses there (1-based), for the status's reason.
struct Dexterity {
  double value = 0.0;
  std::vector<int> joints;
};
/// The dexterity of the arm at `q`, whose tool centre point is at `tool(q)`: the Jacobian by
/// central differences of `tool` (any arm, any number of joints).
Dexterity dexterity(const std::function<world::Pose(const JointVector&)>& tool, const JointVector& q);

/// The hand's push at the tool centre point, in the world: the wrist sensor's reading less what
/// it read when free-drive began, less the change of the payload's weight as the tool turned.
/// `sensor_in_world`: the sensor frame's pose now and at the start; `tcp_in_sensor`: the tool
/// centre point in the sensor frame.
Wrench handWrench(const Wrench& reading, const Wrench& start_reading, const Eigen::Matrix3d& sensor_now,
                  const Eigen::Matrix3d& sensor_at_start, const Eigen::Vector3d& tcp_in_sensor, const Payload& payload);

/// One step of the admittance: from the hand's wrench (world, at the tool centre point), the
/// reference's twist before, and the time step, the twist the reference should move at (masked by
/// the guiding mode, within the dead bands, speeds and acceleration).
struct Twist {
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();
};
Twist admittance(const Wrench& hand, const Twist& before, double dt, const GuidingMode& mode,
                 const Eigen::Matrix3d& tool_rotation, const AdmittanceGains& gains);

/// How far ahead of a step moving at `velocity` (m/s, world) the gripper must be free, with the
/// hand pushing `hand_force` (N, world): AdmittanceGains::look_ahead.
Eigen::Vector3d gripperLookAhead(const Eigen::Vector3d& velocity, const Eigen::Vector3d& hand_force,
                                 const AdmittanceGains& gains);

/// The pose a twist moves `pose` to in `dt`.
world::Pose advance(const world::Pose& pose, const Twist& twist, double dt);

/// Free-drive's protective stop: the hand's push is turned into a reference the arm follows
/// compliantly, so a push harder than a hand's, or a collision, does not show as a force on the
/// wrist (the arm yields instead of pushing back) but as speed and as the tool running away from
/// the reference. Either stops the arm, as a cobot's protective stop does in hand guiding.
struct ProtectiveLimits {
  /// m/s of the tool centre point (measured, not the reference's): the reduced speed of
  /// collaborative teaching; a transient above it shorter than `over_speed_window` (s) is let be.
  double tool_speed = 0.25;
  double over_speed_window = 0.05;
  /// m and rad the tool may be from the reference it is held to: a hand's largest push (60 N,
  /// arm/hand_guiding_limits.h) holds it 10 to 13 mm away on the simulated arms, its largest turn
  /// (3 N m) 1 degree.
  double tracking = 0.025;
  double rotation_tracking = 0.15;
};

class ProtectiveStop {
 public:
  explicit ProtectiveStop(ProtectiveLimits limits = {}) : limits_(limits) {}
  /// One tick `dt` (s) after the last: the tool's measured speed (m/s) and its distance (m) and
  /// turn (rad) from the reference. Returns why the arm must stop, naming the limit and the
  /// value measured, or empty.
  std::string check(double tool_speed, double tracking, double turn, double dt);
  const ProtectiveLimits& limits() const { return limits_; }

 private:
  ProtectiveLimits limits_;
  double over_for_ = 0.0;  // s the tool has been faster than the limit, up to now
  double fastest_ = 0.0;   // m/s: the most it measured in that time
};

/// What a step of the reference is checked against: the Arm's planner (its kinematics and the
/// collision world the planner uses), or a test's toy arm.
struct StepChecks {
  /// The joints that reach `pose` nearest `seed` within the joint limits less the margin, or
  /// nullopt with why (out of the arm's reach, a joint at its limit).
  std::function<std::optional<JointVector>(const world::Pose& pose, const JointVector& seed, std::string& why)> reach;
  /// Whether every configuration of the straight joint motion from `from` to `to` is free of
  /// collisions (each link, the gripper and the tool against the table, the known parts and the
  /// arm itself), else false with the contact in `why`.
  std::function<bool(const JointVector& from, const JointVector& to, std::string& why)> sweep;
  /// The same for the arm's links other than the gripper's (the gripper's may touch anything in
  /// it: they look less far ahead, in `sweep`); empty: `sweep`.
  std::function<bool(const JointVector& from, const JointVector& to, std::string& why)> sweep_arm;
  /// How far (m) the point of the arm that moves most (a link's, not only the tool's) moves from
  /// `from` to `to`.
  std::function<double(const JointVector& from, const JointVector& to)> displacement;
  /// The arm's dexterity at a configuration (dexterity() above); empty: not checked.
  std::function<Dexterity(const JointVector& q)> dexterity;
};

struct FreeDriveStep {
  world::Pose reference = world::Pose::Identity();  // where the reference is after the step
  JointVector joints{};                             // the joints there
  Twist twist;                                      // what it moves at now
  /// Empty when the step was taken as the hand asked; else why (part of) it was not.
  std::string blocked;
};

/// The step the reference takes from (`reference`, `joints`) with `twist` over `dt`, the hand
/// pushing the tool with `hand_force` (world, N): the whole twist when the joints there turn
/// within `max_joint_step`, no point of the arm moves faster than `gains.max_point_speed`, and
/// the arm's sweep from there to the look-ahead is free: the gripper's to gripperLookAhead()
/// (0.4 rad along a turn), the other links' to where the tool is `look_ahead` further along its
/// motion and to where the joints' motion carries the arm's fastest point `look_ahead` further
/// (an elbow moving faster than the tool looks as far ahead as it moves); otherwise its
/// translation alone, or
/// its rotation alone, or the translation less its part along one world axis (sliding along a wall, where the hand's
/// push less its part along that axis is beyond the dead band: a hand pushing into a wall a degree aslant does not
/// creep along it), or none (the reference holds and the twist is zero). A step too fast is slowed, and so is one
/// toward a singularity (`gains.singular_slow`, `singular_floor`).
FreeDriveStep stepReference(const world::Pose& reference, const JointVector& joints, const Twist& twist, double dt,
                            const JointVector& max_joint_step, const AdmittanceGains& gains, const StepChecks& check,
                            const Eigen::Vector3d& hand_force);

}  // namespace costar::arm
