#pragma once
// Joint-space trajectories for the arm: time-parameterized motions that start and end at rest
// and never exceed the joints' velocity and acceleration limits. Units: radians, rad/s, rad/s^2;
// time is costar::Duration (integer nanoseconds) from the start of the trajectory.
//
// Every trajectory is a sequence of phases of constant joint acceleration (piecewise-quadratic
// positions, piecewise-linear and continuous velocities). The generators choose the phases so
// that each one respects the limits throughout, not only at sample times: the guarantees hold
// by construction for every t. The limits are JointLimits (arm/joints.h; a robot's from its description).

#include <string>
#include <vector>

#include "arm/joints.h"
#include "core/clock.h"

namespace costar::arm {

/// The state of the arm at one instant.
struct TrajectoryPoint {
  JointVector position{};      // radians
  JointVector velocity{};      // rad/s
  JointVector acceleration{};  // rad/s^2
};

/// A timed joint motion. Copyable value type; immutable after construction.
class JointTrajectory {
 public:
  /// Default path tolerance of alongPath(), radians (Euclidean distance in joint space).
  static constexpr double kDefaultPathTolerance = 1e-3;

  /// Zero-duration trajectory holding all joints at 0 rad.
  JointTrajectory() : JointTrajectory(hold(JointVector{})) {}

  /// Zero-duration trajectory at rest at `position`. Throws std::invalid_argument when
  /// `position` has a non-finite entry.
  static JointTrajectory hold(const JointVector& position);

  /// Straight line in joint space from `from` to `to`, at rest at both ends: a synchronized
  /// trapezoidal velocity profile (triangular when the distance is too short to reach full
  /// speed). Every joint starts and stops at the same time and moves the same fraction of its
  /// distance at every instant; the most constrained joint sets the duration, which is the
  /// shortest possible for such a synchronized straight-line motion.
  /// `speed_scale` in (0, 1] scales both the velocity and the acceleration limits.
  /// Throws std::invalid_argument for a non-finite input, invalid `limits` (see validate()),
  /// `speed_scale` outside (0, 1], or `from` or `to` outside the position limits (the message
  /// names the joint and by how much).
  static JointTrajectory pointToPoint(const JointVector& from, const JointVector& to, const JointLimits& limits,
                                      double speed_scale);

  /// Through every point of `path` (dense, e.g. a Cartesian line converted point by point, or
  /// sparse, e.g. a planner's via points), at rest at the first and last point, with
  /// continuous velocity.
  ///
  /// Construction: the piecewise-linear path through the points, traversed straight along each
  /// segment with a trapezoidal speed profile, with a parabolic blend (constant acceleration,
  /// the same path speed in and out) around each interior point where the direction changes.
  /// Each blend is sized so that:
  /// - it stays within `path_tolerance` (radians, Euclidean in joint space) of the
  ///   piecewise-linear path and passes within `path_tolerance` of the point (the deviation of
  ///   a blend of duration b between velocities v_in and v_out is at most |v_out - v_in| b / 8);
  /// - it uses each joint's full acceleration limit on the joint that turns most;
  /// - it reaches at most half-way into each adjacent segment.
  /// The speed through each point is then the largest that these and the velocity limits
  /// allow, reduced by a forward and a backward pass so that what the blends leave of every
  /// segment suffices to change speed within its acceleration limit. On a dense path the speed
  /// through a curve is thus limited to about sqrt(a / k) for joint-space curvature k, and sharp
  /// corners are taken slowly enough to stay within the tolerance (a reversal nearly stops). A path of collinear points
  /// gives the same motion as pointToPoint() between its ends. Consecutive duplicate points are skipped; a path of a
  /// single point gives a zero-duration trajectory.
  /// `speed_scale` in (0, 1] scales both the velocity and the acceleration limits.
  /// Throws std::invalid_argument for an empty path, a non-finite value, a point outside the
  /// position limits (naming the point, the joint and by how much), invalid `limits`,
  /// `speed_scale` outside (0, 1], or `path_tolerance` not positive and finite.
  static JointTrajectory alongPath(const std::vector<JointVector>& path, const JointLimits& limits, double speed_scale,
                                   double path_tolerance = kDefaultPathTolerance);

  /// Brings the arm from `state` (typically a sample of a trajectory being cancelled) to rest
  /// as fast as the acceleration limits (unscaled) allow, all joints stopping at the same time
  /// and moving along the current direction of motion: a constant deceleration -v/T with
  /// T = max_j |v_j| / max_acceleration_j. `state.acceleration` is not used. The rest position
  /// is state.position + v T / 2; it is not checked against the position limits (stopping is
  /// always allowed): a state sampled from a trajectory of this file stops no further along
  /// that trajectory's straight segment than the trajectory itself would have.
  /// Throws std::invalid_argument for a non-finite position or velocity, or invalid `limits`.
  static JointTrajectory stopFrom(const TrajectoryPoint& state, const JointLimits& limits);

  /// Throws std::invalid_argument unless every limit is finite, min_position <= max_position,
  /// and the velocity and acceleration limits are positive. `who` prefixes the message.
  static void validate(const JointLimits& limits, const std::string& who = "JointLimits");

  /// Time from the start to the end of the motion (rounded up to whole nanoseconds).
  Duration duration() const { return duration_; }
  /// State at time `t` from the start; `t` is clamped into [0, duration()]; at and after the
  /// end the arm is at rest at finalPosition(). Does not allocate; O(log phases).
  TrajectoryPoint sample(Duration t) const;
  /// Where the motion ends.
  const JointVector& finalPosition() const { return final_position_; }
  /// Where the motion starts.
  const JointVector& initialPosition() const { return phases_.front().position; }

 private:
  // Constant acceleration from start_time (seconds) until the next phase's start time, or the
  // end of the motion for the last phase.
  struct Phase {
    double start_time;
    JointVector position;
    JointVector velocity;
    JointVector acceleration;
  };
  class Builder;  // trajectory.cpp

  JointTrajectory(std::vector<Phase> phases, double total_seconds, const JointVector& final_position);

  std::vector<Phase> phases_;  // never empty
  double total_seconds_ = 0.0;
  Duration duration_{0};
  JointVector final_position_{};
};

}  // namespace costar::arm
