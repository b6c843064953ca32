#include "perception/depth_check.h"

#include <algorithm>
#include <cmath>

namespace costar::perception {

DepthAgreement compareWithDepth(const ObjectModel& model, const world::Pose& pose, const camera::RgbdFrame& frame,
                                double tolerance, int stride, const std::vector<std::uint8_t>* claimed) {
  DepthAgreement agreement;
  const camera::Intrinsics& in = frame.intrinsics;
  const Eigen::Isometry3f transform = pose.cast<float>();
  const Eigen::Matrix3f rotation = transform.linear();
  const float tol = static_cast<float>(tolerance);
  const std::size_t step = static_cast<std::size_t>(std::max(1, stride));
  for (std::size_t i = 0; i < model.surface.size(); i += step) {
    const Eigen::Vector3f p = transform * model.surface.points[i];
    const Eigen::Vector3f n = rotation * model.surface.normals[i];
    // Facing the camera at less than about 80 degrees of incidence.
    if (n.dot(p) > -0.17f * p.norm() || p.z() <= 0.0f) {
      continue;
    }
    const int u = static_cast<int>(std::lround(in.fx * p.x() / p.z() + in.cx));
    const int v = static_cast<int>(std::lround(in.fy * p.y() / p.z() + in.cy));
    if (u < 0 || v < 0 || u >= in.width || v >= in.height) {
      continue;
    }
    ++agreement.facing;
    const float depth = frame.points[static_cast<std::size_t>(v) * in.width + u].z();
    if (!(depth == depth)) {
      continue;  // no reading: cannot judge
    }
    if (std::abs(depth - p.z()) <= tol) {
      if (claimed == nullptr || (*claimed)[static_cast<std::size_t>(v) * in.width + u] == 0) {
        ++agreement.confirmed;
      } else {
        ++agreement.contradicted;  // another detection's surface: the two would overlap
      }
    } else if (depth > p.z() + tol) {
      ++agreement.contradicted;  // the camera sees through where the model has surface
    }
    // depth < p.z() - tol: something in front (occlusion, or the object's own far side).
  }
  return agreement;
}

double overlapFraction(const ObjectModel& a, const world::Pose& pose_a, const ObjectModel& b, const world::Pose& pose_b,
                       double margin) {
  if (a.interior.empty()) {
    return 0.0;
  }
  // Far apart: no overlap.
  if ((pose_a.translation() - pose_b.translation()).norm() > a.radius + b.radius) {
    return 0.0;
  }
  const Eigen::Isometry3f a_to_b = (pose_b.inverse() * pose_a).cast<float>();
  int inside = 0;
  for (const Eigen::Vector3f& interior : a.interior) {
    const Eigen::Vector3d p = (a_to_b * interior).cast<double>();
    for (const world::Box& box : b.object_class.boxes) {
      if (((p - box.center).cwiseAbs() - box.half_size).maxCoeff() < -margin) {
        ++inside;
        break;
      }
    }
  }
  return static_cast<double>(inside) / static_cast<double>(a.interior.size());
}

}  // namespace costar::perception
