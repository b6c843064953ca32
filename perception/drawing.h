#pragma once
// Pictures for people: detections drawn over a camera image (OpenCV stays in drawing.cpp).

#include <string>
#include <vector>

#include "camera/rgbd.h"
#include "core/image.h"
#include "perception/cloud.h"
#include "world/object_class.h"
#include "world/pose.h"

namespace costar::perception {

struct Overlay {
  /// Object frame in the world.
  world::Pose pose = world::Pose::Identity();
  /// Boxes to outline (object frame).
  std::vector<world::Box> boxes;
  Rgb color{0, 255, 0};
  /// Written next to the object (empty: none).
  std::string label;
  /// Also draw the object frame's axes (x red, y green, z blue), 3 cm long.
  bool draw_axes = false;
};

/// Draws `overlays` into `image` as seen by a pinhole camera (`intrinsics`, optical frame at
/// `camera_pose` in the world). Lines behind the camera are skipped.
void drawOverlays(RgbImage& image, const camera::Intrinsics& intrinsics, const world::Pose& camera_pose,
                  const std::vector<Overlay>& overlays);

/// `image` cut to `region` and enlarged `scale` times, with `overlays` drawn at that resolution
/// (a close-up of the workspace that people can read).
RgbImage drawOverlaysZoomed(const RgbImage& image, const camera::Intrinsics& intrinsics, const world::Pose& camera_pose,
                            const std::vector<Overlay>& overlays, PixelRect region, double scale);

}  // namespace costar::perception
