#include "camera/rgbd.h"

#include <algorithm>

namespace costar::camera {

Intrinsics Intrinsics::fromHorizontalFov(int width, int height, double horizontal_fov_rad) {
  Intrinsics intrinsics;
  intrinsics.width = width;
  intrinsics.height = height;
  intrinsics.fx = width / (2.0 * std::tan(horizontal_fov_rad / 2.0));
  intrinsics.fy = intrinsics.fx;
  intrinsics.cx = (width - 1) / 2.0;
  intrinsics.cy = (height - 1) / 2.0;
  return intrinsics;
}

std::size_t RgbdFrame::validCount() const {
  return static_cast<std::size_t>(
      std::count_if(points.begin(), points.end(), [](const Eigen::Vector3f& p) { return std::isfinite(p.z()); }));
}

bool RgbdFrame::anyValid() const {
  return std::any_of(points.begin(), points.end(), [](const Eigen::Vector3f& p) { return std::isfinite(p.z()); });
}

}  // namespace costar::camera
