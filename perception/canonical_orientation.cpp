#include "perception/canonical_orientation.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace costar::perception {

namespace {

int axisIndex(char axis) { return axis == 'x' ? 0 : axis == 'y' ? 1 : 2; }

}  // namespace

CanonicalPose setCanonicalOrientation(const world::Pose& pose, const world::ObjectClass& object_class,
                                      const Eigen::Matrix3d& reference, double tolerance) {
  CanonicalPose best;
  best.pose = pose;
  if (object_class.symmetries.size() <= 1) {
    return best;
  }
  const Eigen::Matrix3d rotation = pose.linear();
  std::array<int, 3> order{2, 0, 1};
  if (object_class.axis_priority.size() == 3) {
    for (int i = 0; i < 3; ++i) {
      order[static_cast<std::size_t>(i)] = axisIndex(object_class.axis_priority[static_cast<std::size_t>(i)]);
    }
  }
  // The candidate R S's axis a against the reference's: (R S e_a) . r_a = (R^T r_a) . (S e_a),
  // so one product R^T r_a per axis serves every symmetry.
  std::array<Eigen::Vector3d, 3> seen_reference;
  for (int i = 0; i < 3; ++i) {
    const int axis = order[static_cast<std::size_t>(i)];
    seen_reference[static_cast<std::size_t>(i)] = rotation.transpose() * reference.col(axis);
  }
  std::array<double, 3> best_score{-2.0, -2.0, -2.0};
  for (std::size_t k = 0; k < object_class.symmetries.size(); ++k) {
    const Eigen::Matrix3d& symmetry = object_class.symmetries[k];
    std::array<double, 3> score{};
    for (int i = 0; i < 3; ++i) {
      const int axis = order[static_cast<std::size_t>(i)];
      score[static_cast<std::size_t>(i)] = seen_reference[static_cast<std::size_t>(i)].dot(symmetry.col(axis));
    }
    // Lexicographic comparison with a tolerance: the first axis that differs decides.
    bool better = false;
    for (int i = 0; i < 3; ++i) {
      const double difference = score[static_cast<std::size_t>(i)] - best_score[static_cast<std::size_t>(i)];
      if (difference > tolerance) {
        better = true;
        break;
      }
      if (difference < -tolerance) {
        break;
      }
    }
    if (better) {
      best_score = score;
      best.symmetry = static_cast<int>(k);
    }
  }
  best.pose.linear() = rotation * object_class.symmetries[static_cast<std::size_t>(best.symmetry)];
  return best;
}

double symmetricRotationDistance(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b,
                                 const world::ObjectClass& object_class) {
  double best = std::numeric_limits<double>::max();
  const auto angle = [](const Eigen::Matrix3d& r) { return std::acos(std::clamp((r.trace() - 1.0) / 2.0, -1.0, 1.0)); };
  if (object_class.symmetries.empty()) {
    return angle(a.transpose() * b);
  }
  for (const Eigen::Matrix3d& s : object_class.symmetries) {
    best = std::min(best, angle(a.transpose() * b * s));
  }
  return best;
}

}  // namespace costar::perception
