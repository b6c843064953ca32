#include "perception/pose_seeds.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>

namespace costar::perception {

namespace {

/// An elongated object's points spread along its length over less than this fraction of it:
/// part of it is hidden (restingStarts).
constexpr double kPartlySeenLength = 0.8;

/// The mean of `indices` of `cloud` (not empty).
Eigen::Vector3d meanOf(const Cloud& cloud, const std::vector<int>& indices) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const int i : indices) {
    mean += cloud.points[static_cast<std::size_t>(i)].cast<double>();
  }
  return mean / static_cast<double>(indices.size());
}

}  // namespace

double lowHeight(const Cloud& points, const std::vector<int>& indices, const TablePlane& support) {
  if (indices.empty()) {
    return 0.0;
  }
  std::vector<double> heights;
  heights.reserve(indices.size());
  for (const int i : indices) {
    heights.push_back(support.height(points.points[static_cast<std::size_t>(i)]));
  }
  const auto low = heights.begin() + static_cast<std::ptrdiff_t>(heights.size() / 20);
  std::nth_element(heights.begin(), low, heights.end());
  return *low;
}

std::vector<world::Pose> principalAxisSeeds(const Cloud& cloud, const std::vector<int>& indices,
                                            const world::ObjectClass& object_class) {
  std::vector<world::Pose> seeds;
  if (indices.size() < 10) {
    return seeds;
  }
  const Eigen::Vector3d mean = meanOf(cloud, indices);
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (const int i : indices) {
    const Eigen::Vector3d d = cloud.points[static_cast<std::size_t>(i)].cast<double>() - mean;
    covariance += d * d.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(covariance);
  // Columns: largest, middle, smallest spread; the smallest points away from the camera.
  Eigen::Matrix3d axes;
  axes.col(0) = solver.eigenvectors().col(2);
  axes.col(1) = solver.eigenvectors().col(1);
  axes.col(2) = solver.eigenvectors().col(0);
  if (axes.col(2).dot(mean) < 0) {
    axes.col(2) = -axes.col(2);
  }
  const Eigen::Vector3d half = object_class.bounds().sizes() / 2.0;
  const Eigen::Vector3d centre = object_class.bounds().center();
  // Object axis a goes to axes.col(k) with sign s: all 48 signed permutations, proper ones only.
  const std::array<std::array<int, 3>, 6> permutations = {
      {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}}};
  for (const auto& permutation : permutations) {
    for (int signs = 0; signs < 8; ++signs) {
      Eigen::Matrix3d rotation;  // columns: the object's x, y, z in the camera frame
      for (int a = 0; a < 3; ++a) {
        const double sign = (signs >> a) & 1 ? -1.0 : 1.0;
        rotation.col(a) = sign * axes.col(permutation[static_cast<std::size_t>(a)]);
      }
      if (rotation.determinant() < 0) {
        continue;
      }
      // The object axis along the points' normal: the object lies behind the seen face.
      const int normal_axis =
          static_cast<int>(std::find(permutation.begin(), permutation.end(), 2) - permutation.begin());
      world::Pose seed = world::Pose::Identity();
      seed.linear() = rotation;
      seed.translation() = mean + axes.col(2) * half[normal_axis] - rotation * centre;
      seeds.push_back(seed);
    }
  }
  return seeds;
}

RestingStarts restingStarts(const Cloud& cloud, const std::vector<int>& indices, const TablePlane& support,
                            const world::ObjectClass& object_class) {
  RestingStarts starts;
  if (indices.size() < 10) {
    return starts;
  }
  const Eigen::Vector3d normal = support.normal.normalized();  // out of the table, toward the camera
  const Eigen::Vector3d mean = meanOf(cloud, indices);
  // The points' spread in the plane: its main axis is a first guess of the object's x.
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (const int i : indices) {
    Eigen::Vector3d d = cloud.points[static_cast<std::size_t>(i)].cast<double>() - mean;
    d -= d.dot(normal) * normal;
    covariance += d * d.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(covariance);
  Eigen::Vector3d axis = solver.eigenvectors().col(2);
  axis -= axis.dot(normal) * normal;
  if (axis.norm() < 1e-9) {
    return starts;
  }
  axis.normalize();
  const Eigen::Vector3d side = normal.cross(axis);
  // Under the points, on the plane: the seen faces are the top and the side facing the camera,
  // so the middle lies a little further away, horizontally.
  const Eigen::AlignedBox3d bounds = object_class.bounds();
  const auto onPlane = [&](const Eigen::Vector3d& point) {
    Eigen::Vector3d on_plane = point - support.height(point.cast<float>()) * normal;
    const Eigen::Vector3d away = on_plane - on_plane.dot(normal) * normal;  // the camera is at the origin
    if (away.norm() > 1e-9) {
      on_plane += away.normalized() * (0.25 * std::min(bounds.sizes().x(), bounds.sizes().y()));
    }
    return on_plane;
  };
  // Points spread along their main axis over more than one and a half objects are more than one
  // (touching parts of a class): their mean lies between them; the ends' starts stand half an
  // object in from the points' extremes (their 2nd and 98th percentiles).
  std::vector<Eigen::Vector3d> ends;
  {
    const double span = bounds.sizes().head<2>().maxCoeff();
    std::vector<double> along;
    along.reserve(indices.size());
    for (const int i : indices) {
      along.push_back((cloud.points[static_cast<std::size_t>(i)].cast<double>() - mean).dot(axis));
    }
    const auto first = along.begin() + static_cast<std::ptrdiff_t>(along.size() / 50);
    const auto last = along.begin() + static_cast<std::ptrdiff_t>(along.size() - 1 - along.size() / 50);
    std::nth_element(along.begin(), first, along.end());
    const double from = *first;
    std::nth_element(along.begin(), last, along.end());
    const double to = *last;
    // An elongated object seen over less than most of its length (one end hidden under a part
    // lying across it or behind a node) has its middle nearer its hidden end than its points'
    // mean: the ends' starts stand with the object's end at either extreme of the points too.
    const bool elongated = span >= 1.5 * bounds.sizes().head<2>().minCoeff();
    if (to - from > 1.5 * span || (elongated && to - from < kPartlySeenLength * span)) {
      ends = {onPlane(mean + (from + 0.5 * span) * axis), onPlane(mean + (to - 0.5 * span) * axis)};
    }
  }
  // What it rests on: the table, and, when even its lowest points are well above the table (a
  // link on a node), a level under those points as well (their 5th percentile height).
  std::vector<double> levels{0.0};
  if (const double low = lowHeight(cloud, indices, support); low > kRaisedSupport) {
    levels.push_back(low);
  }
  constexpr double kStep = 15.0 * M_PI / 180.0;
  const auto addStarts = [&](const Eigen::Vector3d& on_plane, std::vector<world::Pose>& seeds) {
    for (const double level : levels) {
      for (int k = 0; k < 12; ++k) {  // 0 .. 165 degrees: a turn of 180 more is the same box
        const double yaw = k * kStep;
        Eigen::Matrix3d rotation;  // columns: the object's x, y, z in the camera frame
        rotation.col(0) = std::cos(yaw) * axis + std::sin(yaw) * side;
        rotation.col(2) = normal;
        rotation.col(1) = rotation.col(2).cross(rotation.col(0));
        world::Pose seed = world::Pose::Identity();
        seed.linear() = rotation;
        // The object's bottom face on the level, its footprint's middle above on_plane.
        const Eigen::Vector3d footprint_middle(bounds.center().x(), bounds.center().y(), bounds.min().z());
        seed.translation() = on_plane + level * normal - rotation * footprint_middle;
        seeds.push_back(seed);
      }
    }
  };
  // The mean of a part's points is not its middle's projection when only part of it is in
  // view (a node behind a link lying on it shows its front face and a strip of its top): the
  // same starts a quarter of the footprint's width along and across the main axis as well.
  const Eigen::Vector3d middle = onPlane(mean);
  addStarts(middle, starts.middle);
  const double shift = 0.25 * std::min(bounds.sizes().x(), bounds.sizes().y());
  for (const Eigen::Vector3d& offset : {Eigen::Vector3d(shift * axis), Eigen::Vector3d(-shift * axis),
                                        Eigen::Vector3d(shift * side), Eigen::Vector3d(-shift * side)}) {
    addStarts(middle + offset, starts.middle);
  }
  for (const Eigen::Vector3d& end : ends) {
    addStarts(end, starts.ends);
  }
  return starts;
}

std::vector<world::Pose> restingSeeds(const Cloud& cloud, const std::vector<int>& indices, const TablePlane& support,
                                      const world::ObjectClass& object_class) {
  return restingStarts(cloud, indices, support, object_class).middle;
}

std::vector<world::Pose> restingSeedsAtEnds(const Cloud& cloud, const std::vector<int>& indices,
                                            const TablePlane& support, const world::ObjectClass& object_class) {
  return restingStarts(cloud, indices, support, object_class).ends;
}

}  // namespace costar::perception
