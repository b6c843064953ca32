#pragma once
// The makers' published numbers of the UR5 and the LBR iiwa 14, for tests only: the code reads
// every robot from its description file (robots/NAME/NAME.json); tests hold the file to these
// numbers (arm/test/robot_description_test.cpp, srs_kinematics_test.cpp) and use them where a
// fixed, known arm is the point of the test.

#include <numbers>

#include "arm/joints.h"
#include "arm/srs_kinematics.h"
#include "arm/ur5_kinematics.h"

namespace costar::arm::published {

/// Universal Robots' DH table of the UR5 (CB-series): d = {0.089159, 0, 0, 0.10915, 0.09465,
/// 0.0823}, a = {0, -0.425, -0.39225, 0, 0, 0}, alpha = {pi/2, 0, 0, pi/2, -pi/2, 0}.
inline DhParameters ur5Dh() {
  constexpr double kPi = std::numbers::pi;
  DhParameters parameters;
  parameters.d = {0.089159, 0.0, 0.0, 0.10915, 0.09465, 0.0823};
  parameters.a = {0.0, -0.425, -0.39225, 0.0, 0.0, 0.0};
  parameters.alpha = {kPi / 2, 0.0, 0.0, kPi / 2, -kPi / 2, 0.0};
  return parameters;
}

/// The UR5's data sheet: every joint turns through [-2 pi, 2 pi] at up to pi rad/s; 4 rad/s^2 is
/// the description's choice (UR publishes no acceleration limit).
inline JointLimits ur5Limits() {
  constexpr double kTwoPi = 2.0 * std::numbers::pi;
  constexpr int kJoints = 6;
  return {JointVector(kJoints, -kTwoPi), JointVector(kJoints, kTwoPi), JointVector(kJoints, std::numbers::pi),
          JointVector(kJoints, 4.0)};
}

/// KUKA LBR iiwa 14 R820: 0.360, 0.420, 0.400, flange 0.126 m beyond the wrist; joint 4 turns
/// about -y.
inline SrsGeometry iiwa14Geometry() {
  SrsGeometry geometry;
  geometry.base_to_shoulder = 0.360;
  geometry.shoulder_to_elbow = 0.420;
  geometry.elbow_to_wrist = 0.400;
  geometry.wrist_to_flange = world::Pose(Eigen::Translation3d(0.0, 0.0, 0.126));
  geometry.axis_sign = {1, 1, 1, -1, 1, 1, 1};
  return geometry;
}

/// +/-170, +/-120, +/-170, +/-120, +/-170, +/-120, +/-175 degrees.
inline SrsLimits iiwa14Limits() {
  SrsLimits limits;
  limits.upper << 170, 120, 170, 120, 170, 120, 175;
  limits.upper *= std::numbers::pi / 180.0;
  limits.lower = -limits.upper;
  return limits;
}

}  // namespace costar::arm::published
