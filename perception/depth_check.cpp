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
    // Facing the camera at less than about 80 degrees of incidence: n.p <= -0.17 |p|, squared
    // (no square root per sample).
    const float facing = n.dot(p);
    if (facing >= 0.0f || facing * facing < 0.0289f * p.squaredNorm() || p.z() <= 0.0f) {
      continue;
    }
    // The nearest pixel, if in the image: for x >= -0.5, x + 0.5 truncated is x rounded (no
    // library rounding call per sample).
    const double pixel_u = in.fx * p.x() / p.z() + in.cx;
    const double pixel_v = in.fy * p.y() / p.z() + in.cy;
    if (!(pixel_u >= -0.5 && pixel_u < in.width - 0.5 && pixel_v >= -0.5 && pixel_v < in.height - 0.5)) {
      continue;
    }
    const int u = static_cast<int>(pixel_u + 0.5);
    const int v = static_cast<int>(pixel_v + 0.5);
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

double overlapFraction(const ObjectModel& a, const world::Pose& pose_a, const std::vector<PlacedModel>& others,
                       double margin) {
  if (a.interior.empty()) {
    return 0.0;
  }
  std::vector<Eigen::Isometry3f> a_to_other;
  std::vector<const ObjectModel*> near;
  for (const PlacedModel& other : others) {
    if ((pose_a.translation() - other.pose.translation()).norm() <= a.radius + other.model->radius) {
      a_to_other.push_back((other.pose.inverse() * pose_a).cast<float>());
      near.push_back(other.model);
    }
  }
  if (near.empty()) {
    return 0.0;
  }
  int inside = 0;
  for (const Eigen::Vector3f& interior : a.interior) {
    bool claimed = false;
    for (std::size_t k = 0; k < near.size() && !claimed; ++k) {
      const Eigen::Vector3d p = (a_to_other[k] * interior).cast<double>();
      claimed = std::any_of(
          near[k]->object_class.boxes.begin(), near[k]->object_class.boxes.end(),
          [&](const world::Box& box) { return ((p - box.center).cwiseAbs() - box.half_size).maxCoeff() < -margin; });
    }
    inside += claimed ? 1 : 0;
  }
  return static_cast<double>(inside) / static_cast<double>(a.interior.size());
}

}  // namespace costar::perception
