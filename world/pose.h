#pragma once
// 6-DOF poses. Convention everywhere: metres, radians internally; a pose maps points of the
// child frame into the parent frame (p_parent = pose * p_child).

#include <Eigen/Geometry>
#include <optional>
#include <string>
#include <string_view>

namespace costar::world {

using Pose = Eigen::Isometry3d;

/// Position plus roll, pitch, yaw (radians; R = Rz(yaw) * Ry(pitch) * Rx(roll)).
Pose poseFromXyzRpy(double x, double y, double z, double roll, double pitch, double yaw);
/// Roll, pitch, yaw (radians) of a rotation, inverse of the composition above.
Eigen::Vector3d rpyOf(const Eigen::Matrix3d& rotation);

/// Text form used in plan attributes: "x;y;z" or "x;y;z;roll;pitch;yaw", metres and DEGREES
/// (people write degrees). Empty optional + `error` on bad text.
std::optional<Pose> parsePose(std::string_view text, std::string* error = nullptr);
/// Inverse of parsePose (6 values, shortest round-trip formatting).
std::string formatPose(const Pose& pose);

/// Angle of the rotation between two poses' orientations, radians in [0, pi].
double rotationAngle(const Pose& a, const Pose& b);

}  // namespace costar::world
