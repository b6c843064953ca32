#pragma once
// Joint-space vocabulary shared by the arm's kinematics and trajectories: a six-joint vector,
// the joint limits, and angle helpers. Units: radians, rad/s, rad/s^2.

#include <array>
#include <cmath>
#include <numbers>

namespace costar::arm {

/// Number of joints of the arms handled here (UR5 and its siblings).
inline constexpr int kJointCount = 6;

/// One value per joint, joint 1 (base) first. Radians for positions, rad/s for velocities,
/// rad/s^2 for accelerations.
using JointVector = std::array<double, kJointCount>;

/// Limits of each joint. Positions in radians, velocities in rad/s, accelerations in rad/s^2.
/// Velocity and acceleration limits are magnitudes (> 0) and apply symmetrically.
struct JointLimits {
  JointVector min_position;
  JointVector max_position;
  JointVector max_velocity;
  JointVector max_acceleration;

  /// Universal Robots UR5: every joint turns through [-2*pi, 2*pi] at up to pi rad/s (the
  /// 180 deg/s of the data sheet). UR publishes no joint acceleration limit; 4.0 rad/s^2 on
  /// every joint is a conservative choice (well below what the controller accepts), so that
  /// trajectories planned with it can be followed with a payload.
  static JointLimits ur5() {
    constexpr double kTwoPi = 2.0 * std::numbers::pi;
    JointLimits limits;
    limits.min_position.fill(-kTwoPi);
    limits.max_position.fill(kTwoPi);
    limits.max_velocity.fill(std::numbers::pi);
    limits.max_acceleration.fill(4.0);
    return limits;
  }
};

/// `angle` wrapped into (-pi, pi]. Finite input only (NaN stays NaN).
inline double wrapAngle(double angle) {
  if (angle > -std::numbers::pi && angle <= std::numbers::pi) {
    return angle;  // the common case, without the division
  }
  constexpr double kTwoPi = 2.0 * std::numbers::pi;
  double wrapped = std::remainder(angle, kTwoPi);  // in [-pi, pi]
  if (wrapped <= -std::numbers::pi) {
    wrapped += kTwoPi;
  }
  return wrapped;
}

/// Every element of `q` wrapped into (-pi, pi].
inline JointVector wrapAngles(const JointVector& q) {
  JointVector wrapped;
  for (int j = 0; j < kJointCount; ++j) {
    wrapped[j] = wrapAngle(q[j]);
  }
  return wrapped;
}

/// Largest absolute element-wise difference between two joint vectors, each difference wrapped
/// into (-pi, pi] first: the distance between two configurations modulo 2*pi per joint.
inline double maxWrappedDifference(const JointVector& a, const JointVector& b) {
  double largest = 0.0;
  for (int j = 0; j < kJointCount; ++j) {
    largest = std::fmax(largest, std::abs(wrapAngle(a[j] - b[j])));
  }
  return largest;
}

/// True when every element of `q` is finite (no NaN, no infinity).
inline bool allFinite(const JointVector& q) {
  for (double value : q) {
    if (!std::isfinite(value)) {
      return false;
    }
  }
  return true;
}

}  // namespace costar::arm
