#include "arm/recorded_trajectory.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <Eigen/Geometry>

#include "arm/waypoints.h"

namespace costar::arm {

namespace {

world::Pose interpolate(const world::Pose& a, const world::Pose& b, double s) {
  world::Pose pose = world::Pose::Identity();
  pose.translation() = a.translation() + s * (b.translation() - a.translation());
  pose.linear() = Eigen::Quaterniond(a.linear()).slerp(s, Eigen::Quaterniond(b.linear())).toRotationMatrix();
  return pose;
}

/// Keeps, between `first` and `last` (kept), the samples needed within the tolerance.
void keep(const RecordedTrajectory& in, std::size_t first, std::size_t last, const SimplifyTolerance& tolerance,
          std::vector<bool>& kept) {
  if (last <= first + 1) {
    return;
  }
  const double span = in.times[last] - in.times[first];
  double worst = 0.0;
  std::size_t worst_index = first;
  for (std::size_t i = first + 1; i < last; ++i) {
    const world::Pose expected = interpolate(in.poses[first], in.poses[last], (in.times[i] - in.times[first]) / span);
    // Both errors on one scale: each over its tolerance.
    const double error = std::max((in.poses[i].translation() - expected.translation()).norm() / tolerance.position,
                                  world::rotationAngle(in.poses[i], expected) / tolerance.angle);
    if (error > worst) {
      worst = error;
      worst_index = i;
    }
  }
  if (worst > 1.0) {
    kept[worst_index] = true;
    keep(in, first, worst_index, tolerance, kept);
    keep(in, worst_index, last, tolerance, kept);
  }
}

}  // namespace

world::Pose RecordedTrajectory::at(double t) const {
  if (poses.empty()) {
    return world::Pose::Identity();
  }
  if (t <= times.front()) {
    return poses.front();
  }
  if (t >= times.back()) {
    return poses.back();
  }
  const auto next = std::upper_bound(times.begin(), times.end(), t);
  const auto i = static_cast<std::size_t>(next - times.begin());
  return interpolate(poses[i - 1], poses[i], (t - times[i - 1]) / (times[i] - times[i - 1]));
}

double RecordedTrajectory::length() const {
  double length = 0.0;
  for (std::size_t i = 1; i < poses.size(); ++i) {
    length += (poses[i].translation() - poses[i - 1].translation()).norm();
  }
  return length;
}

RecordedTrajectory simplify(const RecordedTrajectory& recorded, const SimplifyTolerance& tolerance) {
  if (recorded.times.size() != recorded.poses.size()) {
    throw std::invalid_argument("a recorded trajectory has " + std::to_string(recorded.times.size()) + " times and " +
                                std::to_string(recorded.poses.size()) + " poses");
  }
  for (std::size_t i = 1; i < recorded.times.size(); ++i) {
    if (!(recorded.times[i] > recorded.times[i - 1])) {
      throw std::invalid_argument("a recorded trajectory's times must increase (sample " + std::to_string(i) + ")");
    }
  }
  if (recorded.poses.size() <= 2) {
    return recorded;
  }
  std::vector<bool> kept(recorded.poses.size(), false);
  kept.front() = true;
  kept.back() = true;
  keep(recorded, 0, recorded.poses.size() - 1, tolerance, kept);
  RecordedTrajectory simplified;
  simplified.name = recorded.name;
  simplified.frame = recorded.frame;
  for (std::size_t i = 0; i < kept.size(); ++i) {
    if (kept[i]) {
      simplified.times.push_back(recorded.times[i]);
      simplified.poses.push_back(recorded.poses[i]);
    }
  }
  return simplified;
}

std::string checkRecordedTrajectory(const RecordedTrajectory& trajectory) {
  if (std::string problem = checkWaypointName(trajectory.name); !problem.empty()) {
    return "name: " + problem;
  }
  if (trajectory.frame.empty()) {
    return "frame: must name a frame (\"world\", or a frame symbol such as a detected part)";
  }
  if (trajectory.times.size() != trajectory.poses.size()) {
    return "times: " + std::to_string(trajectory.times.size()) + " times for " +
           std::to_string(trajectory.poses.size()) + " poses";
  }
  if (trajectory.poses.size() < 2) {
    return "poses: a trajectory has two samples at least, not " + std::to_string(trajectory.poses.size());
  }
  for (std::size_t i = 0; i < trajectory.times.size(); ++i) {
    const std::string at = "[" + std::to_string(i) + "]";
    if (!std::isfinite(trajectory.times[i]) || std::abs(trajectory.times[i]) > 1e6) {
      return "times" + at + ": must be a finite number of seconds";
    }
    if (i > 0 && !(trajectory.times[i] > trajectory.times[i - 1])) {
      return "times" + at + ": must be later than times[" + std::to_string(i - 1) + "]";
    }
    const world::Pose& pose = trajectory.poses[i];
    if (!pose.matrix().allFinite() || pose.translation().cwiseAbs().maxCoeff() > 10.0) {
      return "poses" + at + ": must be a finite position within 10 m";
    }
  }
  return {};
}

}  // namespace costar::arm
