#include "smartmove/footprint.h"

#include <algorithm>
#include <limits>
#include <vector>

namespace costar::smartmove {

namespace {

std::vector<Eigen::Vector2d> corners(const world::ObjectClass& object_class, const world::Pose& pose) {
  const Eigen::AlignedBox3d box = object_class.bounds();
  std::vector<Eigen::Vector2d> points;
  for (int i = 0; i < 8; ++i) {
    points.push_back((pose * box.corner(static_cast<Eigen::AlignedBox3d::CornerType>(i))).head<2>());
  }
  return points;
}

}  // namespace

double footprintGap(const world::ObjectClass& a, const world::Pose& pose_a, const world::ObjectClass& b,
                    const world::Pose& pose_b) {
  const std::vector<Eigen::Vector2d> points_a = corners(a, pose_a);
  const std::vector<Eigen::Vector2d> points_b = corners(b, pose_b);
  std::vector<Eigen::Vector2d> axes;
  for (const world::Pose* pose : {&pose_a, &pose_b}) {
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector2d axis = pose->linear().col(k).head<2>();
      if (axis.norm() > 1e-6) {
        axes.push_back(axis.normalized());
        axes.emplace_back(-axes.back().y(), axes.back().x());
      }
    }
  }
  double gap = -std::numeric_limits<double>::infinity();
  for (const Eigen::Vector2d& axis : axes) {
    const auto project = [&axis](const std::vector<Eigen::Vector2d>& points) {
      double low = std::numeric_limits<double>::infinity();
      double high = -low;
      for (const auto& p : points) {
        low = std::min(low, axis.dot(p));
        high = std::max(high, axis.dot(p));
      }
      return std::pair{low, high};
    };
    const auto [a_low, a_high] = project(points_a);
    const auto [b_low, b_high] = project(points_b);
    gap = std::max(gap, std::max(b_low - a_high, a_low - b_high));
  }
  return gap;
}

double distanceToFootprint(const Eigen::Vector2d& point, const world::ObjectClass& b, const world::Pose& pose_b) {
  const Eigen::Vector3d in_b = pose_b.inverse() * Eigen::Vector3d(point.x(), point.y(), pose_b.translation().z());
  const Eigen::AlignedBox3d box = b.bounds();
  const Eigen::Vector3d nearest = in_b.cwiseMax(box.min()).cwiseMin(box.max());
  return (pose_b * nearest - pose_b * in_b).head<2>().norm();
}

}  // namespace costar::smartmove
