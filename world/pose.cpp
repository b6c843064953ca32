#include "world/pose.h"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <vector>

namespace costar::world {

Pose poseFromXyzRpy(double x, double y, double z, double roll, double pitch, double yaw) {
  Pose pose = Pose::Identity();
  pose.translation() = Eigen::Vector3d(x, y, z);
  pose.linear() =
      (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
       Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
          .toRotationMatrix();
  return pose;
}

Eigen::Vector3d rpyOf(const Eigen::Matrix3d& r) {
  const double pitch = std::asin(std::clamp(-r(2, 0), -1.0, 1.0));
  double roll = 0;
  double yaw = 0;
  if (std::abs(std::cos(pitch)) > 1e-9) {
    roll = std::atan2(r(2, 1), r(2, 2));
    yaw = std::atan2(r(1, 0), r(0, 0));
  } else {  // gimbal lock: put everything in yaw
    yaw = std::atan2(-r(0, 1), r(1, 1));
  }
  return {roll, pitch, yaw};
}

std::optional<Pose> parsePose(std::string_view text, std::string* error) {
  std::vector<double> values;
  std::size_t start = 0;
  while (start <= text.size()) {
    std::size_t end = text.find(';', start);
    if (end == std::string_view::npos) {
      end = text.size();
    }
    std::string_view item = text.substr(start, end - start);
    while (!item.empty() && item.front() == ' ') {
      item.remove_prefix(1);
    }
    while (!item.empty() && item.back() == ' ') {
      item.remove_suffix(1);
    }
    double value = 0;
    const auto [ptr, ec] = std::from_chars(item.data(), item.data() + item.size(), value);
    if (item.empty() || ec != std::errc() || ptr != item.data() + item.size() || !std::isfinite(value)) {
      if (error != nullptr) {
        *error = "'" + std::string(text) +
                 "' is not a pose: expected \"x;y;z\" or "
                 "\"x;y;z;roll;pitch;yaw\" (metres, degrees)";
      }
      return std::nullopt;
    }
    values.push_back(value);
    start = end + 1;
  }
  if (values.size() != 3 && values.size() != 6) {
    if (error != nullptr) {
      *error = "'" + std::string(text) + "' has " + std::to_string(values.size()) +
               " numbers: a pose is \"x;y;z\" or \"x;y;z;roll;pitch;yaw\" (metres, degrees)";
    }
    return std::nullopt;
  }
  // A hostile tester's MoveToPose with a roll of 1e308 degrees was accepted (the rotation is
  // all rounding there); a workcell is not kilometres wide either.
  static constexpr const char* kNames[6] = {"x", "y", "z", "roll", "pitch", "yaw"};
  for (std::size_t i = 0; i < values.size(); ++i) {
    const double most = i < 3 ? 100.0 : 360.0;  // metres, degrees
    if (std::abs(values[i]) > most) {
      if (error != nullptr) {
        char range[64];
        std::snprintf(range, sizeof(range), "%g is not within %g %s", values[i], most, i < 3 ? "m" : "degrees");
        *error = "'" + std::string(text) + "': " + kNames[i] + " " + range + " either way";
      }
      return std::nullopt;
    }
  }
  values.resize(6, 0.0);
  constexpr double kDeg = M_PI / 180.0;
  return poseFromXyzRpy(values[0], values[1], values[2], values[3] * kDeg, values[4] * kDeg, values[5] * kDeg);
}

std::string formatPose(const Pose& pose) {
  const Eigen::Vector3d rpy = rpyOf(pose.linear()) * (180.0 / M_PI);
  const double values[6] = {
      pose.translation().x(), pose.translation().y(), pose.translation().z(), rpy.x(), rpy.y(), rpy.z()};
  std::string text;
  for (double value : values) {
    char buffer[32];
    const auto [end, ec] = std::to_chars(buffer, buffer + sizeof buffer, value);
    text += (text.empty() ? "" : ";") + std::string(buffer, end);
  }
  return text;
}

double rotationAngle(const Pose& a, const Pose& b) {
  const Eigen::AngleAxisd delta(a.linear().transpose() * b.linear());
  return std::abs(delta.angle());
}

}  // namespace costar::world
