#pragma once
// Point sets that flow between the stages of the perception pipeline. Plain Eigen and
// standard containers only: PCL, OpenCV and libsvm stay inside perception/*.cpp.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

namespace costar::perception {

using Rgb = std::array<std::uint8_t, 3>;

/// An unorganized point set, structure of arrays. Points are in the frame the producing
/// function documents (the camera OPTICAL frame unless said otherwise), metres. Optional
/// attributes are either empty or have one entry per point.
struct Cloud {
  std::vector<Eigen::Vector3f> points;
  /// Unit surface normals, oriented towards the camera (n . p < 0 in the optical frame).
  std::vector<Eigen::Vector3f> normals;
  std::vector<Rgb> colors;
  /// Index v * width + u of the pixel each point came from in the organized frame.
  std::vector<int> pixels;

  std::size_t size() const { return points.size(); }
  bool empty() const { return points.empty(); }
  /// Appends point `index` of `other` (with whatever attributes both clouds carry).
  void append(const Cloud& other, std::size_t index);
};

/// A rectangle of pixels [u_min, u_max) x [v_min, v_max).
struct PixelRect {
  int u_min = 0;
  int v_min = 0;
  int u_max = 0;
  int v_max = 0;

  int width() const { return u_max - u_min; }
  int height() const { return v_max - v_min; }
  bool empty() const { return u_max <= u_min || v_max <= v_min; }
};

}  // namespace costar::perception
