#pragma once
// RGB-D frames and the camera interface. A camera is simulated (sim/) or, on hardware, a
// driver; perception sees only this interface.

#include <Eigen/Core>
#include <cmath>
#include <cstddef>
#include <optional>
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
  /// Whether any point is valid (stops at the first).
  bool anyValid() const;
};

/// What a camera's stream says about its newest frame, without the frame itself.
struct StreamStatus {
  /// When the newest frame was taken.
  TimePoint stamp{};
  /// Its pixels (0: an empty frame), and how many of them hold a valid depth reading.
  std::size_t points = 0;
  std::size_t valid = 0;
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
  /// The stream's health between the frames taken, for a monitor that asks often (the
  /// perception component, every tick): a camera streams whether or not anyone takes its
  /// frames (30 a second for a Carmine), and its driver knows the newest one's stamp and
  /// validity. Must be cheap. Empty: this camera cannot tell; it is then judged only by the
  /// frames taken. @throws std::exception when the camera cannot be reached.
  virtual std::optional<StreamStatus> streamStatus() { return std::nullopt; }
};

}  // namespace costar::camera
