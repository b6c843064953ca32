#pragma once
// Test helper: organized RGB-D frames ray-cast from boxes (object classes) on a table plane,
// seen by the workcell's camera (640 x 480, 1.25 m from the table centre), with optional
// Gaussian depth noise. No simulator: the pipeline's stages can be tested on exact geometry.

#include <optional>
#include <random>
#include <vector>

#include "camera/rgbd.h"
#include "perception/cloud.h"
#include "world/object_class.h"
#include "world/pose.h"

namespace costar::perception::test {

struct SyntheticObject {
  const world::ObjectClass* object_class = nullptr;
  world::Pose pose = world::Pose::Identity();  // world frame
  Rgb color{200, 30, 30};
};

/// The workcell's RGB-D camera pose (optical frame in the world), as in sim/models.
inline world::Pose workcellCameraPose() {
  world::Pose pose = world::Pose::Identity();
  pose.translation() = Eigen::Vector3d(1.25, 0.0, 0.85);
  pose.linear().col(0) = Eigen::Vector3d(0, 1, 0);
  pose.linear().col(1) = Eigen::Vector3d(0.7282, 0, -0.6854).normalized();
  pose.linear().col(2) = pose.linear().col(0).cross(pose.linear().col(1));
  return pose;
}

inline camera::Intrinsics workcellIntrinsics() {
  camera::Intrinsics in = camera::Intrinsics::fromHorizontalFov(640, 480, 58.0 * M_PI / 180.0);
  in.fy = 480 / (2.0 * std::tan(45.09 * M_PI / 360.0));
  in.fx = in.fy;
  return in;
}

/// Ray-casts `objects` and (unless `table` is false) the table top z = 0, x in [-0.3, 1.1],
/// y in [-0.6, 0.6], from `camera_pose`. Depth gets Gaussian noise of `sigma` (m).
inline camera::RgbdFrame renderSynthetic(const std::vector<SyntheticObject>& objects, double sigma = 0.0,
                                         std::uint64_t seed = 1, bool table = true,
                                         const world::Pose& camera_pose = workcellCameraPose()) {
  camera::RgbdFrame frame;
  frame.intrinsics = workcellIntrinsics();
  frame.camera_pose = camera_pose;
  const camera::Intrinsics& in = frame.intrinsics;
  frame.rgb = RgbImage(in.width, in.height);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  frame.points.assign(static_cast<std::size_t>(in.width) * in.height, Eigen::Vector3f(nan, nan, nan));
  std::mt19937_64 random(seed);
  std::normal_distribution<double> noise(0.0, 1.0);
  const Eigen::Vector3d origin = camera_pose.translation();
  for (int v = 0; v < in.height; ++v) {
    for (int u = 0; u < in.width; ++u) {
      const Eigen::Vector3d ray_camera((u - in.cx) / in.fx, (v - in.cy) / in.fy, 1.0);
      const Eigen::Vector3d ray = camera_pose.linear() * ray_camera;
      double best = std::numeric_limits<double>::max();
      Rgb color{0, 0, 0};
      if (table && ray.z() < 0) {
        const double t = -origin.z() / ray.z();
        const Eigen::Vector3d hit = origin + t * ray;
        if (hit.x() > -0.3 && hit.x() < 1.1 && std::abs(hit.y()) < 0.6) {
          best = t;
          color = {199, 194, 184};
        }
      }
      for (const SyntheticObject& object : objects) {
        const world::Pose inverse = object.pose.inverse();
        const Eigen::Vector3d o = inverse * origin;
        const Eigen::Vector3d d = inverse.linear() * ray;
        for (const world::Box& box : object.object_class->boxes) {
          double t_near = -std::numeric_limits<double>::max();
          double t_far = std::numeric_limits<double>::max();
          bool miss = false;
          for (int a = 0; a < 3 && !miss; ++a) {
            const double low = box.center[a] - box.half_size[a];
            const double high = box.center[a] + box.half_size[a];
            if (std::abs(d[a]) < 1e-12) {
              miss = o[a] < low || o[a] > high;
              continue;
            }
            double t1 = (low - o[a]) / d[a];
            double t2 = (high - o[a]) / d[a];
            if (t1 > t2) {
              std::swap(t1, t2);
            }
            t_near = std::max(t_near, t1);
            t_far = std::min(t_far, t2);
            miss = t_near > t_far;
          }
          if (!miss && t_near > 0 && t_near < best) {
            best = t_near;
            color = object.color;
          }
        }
      }
      if (best == std::numeric_limits<double>::max()) {
        continue;
      }
      double z = best;  // ray_camera has z = 1: t is the depth
      z += sigma * noise(random);
      frame.points[static_cast<std::size_t>(v) * in.width + u] = (ray_camera * z).cast<float>();
      std::uint8_t* pixel = frame.rgb.at(u, v);
      pixel[0] = color[0];
      pixel[1] = color[1];
      pixel[2] = color[2];
    }
  }
  return frame;
}

}  // namespace costar::perception::test
