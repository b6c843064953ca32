#pragma once
// RGB-D frames and the camera interface. A camera is simulated (sim/) or, on hardware, a
// driver; perception sees only this interface.

#include <Eigen/Core>
#include <cmath>
#include <string>
#include <vector>

#include "core/clock.h"
#include "core/image.h"
#include "world/pose.h"

namespace costar::camera {

/// Pinhole intrinsics of the depth (and registered colour) image, in pixels.
struct Intrinsics {
  int width = 0;
  int height = 0;
  double fx = 0, fy = 0, cx = 0, cy = 0;

  /// Square pixels, principal point at the centre (OpenGL-style rendering).
  static Intrinsics fromHorizontalFov(int width, int height, double horizontal_fov_rad);
  double horizontalFov() const { return 2.0 * std::atan(width / (2.0 * fx)); }
};

/// One frame. Points are organized (row-major, width x height) in the camera's OPTICAL
/// frame: x right, y down, z forward along the viewing direction, metres. A pixel without a
/// valid depth reading holds NaN coordinates.
struct RgbdFrame {
  Intrinsics intrinsics;
  std::vector<Eigen::Vector3f> points;
  RgbImage rgb;
  /// Pose of the optical frame in the world when the frame was taken: the true pose in
  /// simulation, the calibrated pose on hardware.
  world::Pose camera_pose = world::Pose::Identity();
  TimePoint stamp{};

  const Eigen::Vector3f& point(int u, int v) const {
    return points[static_cast<std::size_t>(v) * intrinsics.width + u];
  }
  bool valid(int u, int v) const { return std::isfinite(point(u, v).z()); }
  std::size_t validCount() const;
};

class RgbdCamera {
 public:
  virtual ~RgbdCamera() = default;
  virtual std::string name() const = 0;
  virtual const Intrinsics& intrinsics() const = 0;
  /// Time between frames (1/30 s for a Carmine).
  virtual Duration framePeriod() const = 0;
  /// The current frame. In simulation it is rendered from the world's present state.
  virtual RgbdFrame capture() = 0;
  /// The current frame for a user that needs its points only: the colour image may be left
  /// empty (a simulated camera then skips rendering colour). The points are as capture()'s.
  virtual RgbdFrame captureDepth() { return capture(); }
};

}  // namespace costar::camera
