#include "perception/drawing.h"

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>

namespace costar::perception {

void drawOverlays(RgbImage& image, const camera::Intrinsics& intrinsics, const world::Pose& camera_pose,
                  const std::vector<Overlay>& overlays) {
  if (image.width <= 0 || image.height <= 0) {
    return;
  }
  cv::Mat canvas(image.height, image.width, CV_8UC3, image.pixels.data());
  const world::Pose world_to_camera = camera_pose.inverse();
  const auto project = [&](const Eigen::Vector3d& world_point, cv::Point2d& pixel) {
    const Eigen::Vector3d p = world_to_camera * world_point;
    if (p.z() < 0.05) {
      return false;
    }
    pixel = {intrinsics.fx * p.x() / p.z() + intrinsics.cx, intrinsics.fy * p.y() / p.z() + intrinsics.cy};
    return true;
  };
  const auto line = [&](const Eigen::Vector3d& a, const Eigen::Vector3d& b, const cv::Scalar& color, int thickness) {
    cv::Point2d pa;
    cv::Point2d pb;
    if (project(a, pa) && project(b, pb)) {
      cv::line(canvas, pa, pb, color, thickness, cv::LINE_AA);
    }
  };
  for (const Overlay& overlay : overlays) {
    const cv::Scalar color(overlay.color[0], overlay.color[1], overlay.color[2]);  // the image is RGB
    for (const world::Box& box : overlay.boxes) {
      std::array<Eigen::Vector3d, 8> corners;
      for (int i = 0; i < 8; ++i) {
        const Eigen::Vector3d sign((i & 1) ? 1 : -1, (i & 2) ? 1 : -1, (i & 4) ? 1 : -1);
        corners[static_cast<std::size_t>(i)] = overlay.pose * (box.center + sign.cwiseProduct(box.half_size));
      }
      for (int i = 0; i < 8; ++i) {
        for (int bit : {1, 2, 4}) {
          if ((i & bit) == 0) {
            line(corners[static_cast<std::size_t>(i)], corners[static_cast<std::size_t>(i | bit)], color, 1);
          }
        }
      }
    }
    if (overlay.draw_axes) {
      const Eigen::Vector3d origin = overlay.pose.translation();
      line(origin, overlay.pose * Eigen::Vector3d(0.03, 0, 0), cv::Scalar(255, 0, 0), 2);
      line(origin, overlay.pose * Eigen::Vector3d(0, 0.03, 0), cv::Scalar(0, 200, 0), 2);
      line(origin, overlay.pose * Eigen::Vector3d(0, 0, 0.03), cv::Scalar(0, 80, 255), 2);
    }
    cv::Point2d at;
    if (!overlay.label.empty() && project(overlay.pose.translation(), at)) {
      cv::putText(canvas, overlay.label, at + cv::Point2d(6, -6), cv::FONT_HERSHEY_SIMPLEX, 0.38, cv::Scalar(0, 0, 0),
                  3, cv::LINE_AA);
      cv::putText(canvas, overlay.label, at + cv::Point2d(6, -6), cv::FONT_HERSHEY_SIMPLEX, 0.38, color, 1,
                  cv::LINE_AA);
    }
  }
}

RgbImage drawOverlaysZoomed(const RgbImage& image, const camera::Intrinsics& intrinsics, const world::Pose& camera_pose,
                            const std::vector<Overlay>& overlays, PixelRect region, double scale) {
  region.u_min = std::clamp(region.u_min, 0, image.width);
  region.u_max = std::clamp(region.u_max, 0, image.width);
  region.v_min = std::clamp(region.v_min, 0, image.height);
  region.v_max = std::clamp(region.v_max, 0, image.height);
  if (region.empty() || scale <= 0) {
    RgbImage copy = image;
    drawOverlays(copy, intrinsics, camera_pose, overlays);
    return copy;
  }
  const cv::Mat source(image.height, image.width, CV_8UC3, const_cast<std::uint8_t*>(image.pixels.data()));
  RgbImage out(static_cast<int>(std::lround(region.width() * scale)),
               static_cast<int>(std::lround(region.height() * scale)));
  cv::Mat target(out.height, out.width, CV_8UC3, out.pixels.data());
  cv::resize(source(cv::Rect(region.u_min, region.v_min, region.width(), region.height())), target, target.size(), 0, 0,
             cv::INTER_LINEAR);
  camera::Intrinsics zoomed = intrinsics;
  zoomed.width = out.width;
  zoomed.height = out.height;
  zoomed.fx = intrinsics.fx * scale;
  zoomed.fy = intrinsics.fy * scale;
  zoomed.cx = (intrinsics.cx - region.u_min + 0.5) * scale - 0.5;
  zoomed.cy = (intrinsics.cy - region.v_min + 0.5) * scale - 0.5;
  drawOverlays(out, zoomed, camera_pose, overlays);
  return out;
}

}  // namespace costar::perception
