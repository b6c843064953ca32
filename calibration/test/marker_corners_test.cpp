#include "calibration/marker_corners.h"

#include <gtest/gtest.h>

#include <cmath>

#include "calibration/hand_eye.h"

namespace costar::calibration {
namespace {

constexpr double kDeg = M_PI / 180.0;

/// A square marker drawn as a renderer without anti-aliasing draws it: a pixel is black when
/// its centre lies inside the square `corners`, white inside the quiet zone around it (the
/// square grown by `quiet` times its side), mid grey beyond.
RgbImage drawSquare(int width, int height, const std::array<Eigen::Vector2d, 4>& corners, double quiet) {
  RgbImage image(width, height);
  const Eigen::Vector2d centre = 0.25 * (corners[0] + corners[1] + corners[2] + corners[3]);
  const auto inside = [&](const Eigen::Vector2d& p, double grow) {
    for (std::size_t k = 0; k < 4; ++k) {
      const Eigen::Vector2d a = centre + (1 + grow) * (corners[k] - centre);
      const Eigen::Vector2d b = centre + (1 + grow) * (corners[(k + 1) % 4] - centre);
      const Eigen::Vector2d edge = b - a;
      const Eigen::Vector2d to_p = p - a;
      const Eigen::Vector2d to_c = centre - a;
      const double side_p = edge.x() * to_p.y() - edge.y() * to_p.x();
      const double side_c = edge.x() * to_c.y() - edge.y() * to_c.x();
      if (side_p * side_c < 0) {
        return false;
      }
    }
    return true;
  };
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const Eigen::Vector2d p(x, y);
      const std::uint8_t value = inside(p, 0.0) ? 20 : inside(p, 2 * quiet) ? 235 : 120;
      std::uint8_t* pixel = image.at(x, y);
      pixel[0] = pixel[1] = pixel[2] = value;
    }
  }
  return image;
}

/// A 32 px square turned by `angle`, its centre at (cx, cy), in ArUco's corner order.
std::array<Eigen::Vector2d, 4> square(double cx, double cy, double side, double angle) {
  const Eigen::Rotation2Dd turn(angle);
  const double h = side / 2;
  // Image coordinates (y down): top-left, top-right, bottom-right, bottom-left.
  return {
      Eigen::Vector2d(cx, cy) + turn * Eigen::Vector2d(-h, -h), Eigen::Vector2d(cx, cy) + turn * Eigen::Vector2d(h, -h),
      Eigen::Vector2d(cx, cy) + turn * Eigen::Vector2d(h, h), Eigen::Vector2d(cx, cy) + turn * Eigen::Vector2d(-h, h)};
}

// Measured (these cases): 0.03 to 0.31 px, mean 0.13 px, from starts 0.6 to 2.2 px off. Edges
// within a few degrees of the pixel grid have too few steps along them to place the line (3
// degrees: up to 1.2 px off), so Calibrate turns the marker about its normal between views.
TEST(MarkerCorners, EdgesPutTheCornersOfAnAliasedSquareWithinAThirdOfAPixel) {
  double worst_start = 0.0;
  double worst = 0.0;
  double sum = 0.0;
  int cases = 0;
  for (const double angle : {11.0, 17.0, 28.0, 41.0, -23.0}) {
    for (const Eigen::Vector2d& centre : {Eigen::Vector2d(60.3, 50.7), Eigen::Vector2d(71.85, 44.12)}) {
      const auto truth = square(centre.x(), centre.y(), 31.7, angle * kDeg);
      const RgbImage image = drawSquare(140, 110, truth, 1.0 / 6.0);
      // ArUco's corners on whole pixels, each up to ~1.5 px off.
      std::array<Eigen::Vector2d, 4> start;
      for (std::size_t k = 0; k < 4; ++k) {
        const Eigen::Vector2d push(k % 2 == 0 ? 1.2 : -0.9, k < 2 ? 0.8 : -1.1);
        start[k] = (truth[k] + push).array().round();
        worst_start = std::max(worst_start, (start[k] - truth[k]).norm());
      }
      const auto refined = refineMarkerCorners(image, start);
      for (std::size_t k = 0; k < 4; ++k) {
        worst = std::max(worst, (refined[k] - truth[k]).norm());
        sum += (refined[k] - truth[k]).norm();
      }
      ++cases;
    }
  }
  EXPECT_EQ(cases, 10);
  EXPECT_GT(worst_start, 1.0);  // the start was really off
  EXPECT_LT(worst, 0.35) << "refined corners off by up to " << worst << " px";
  EXPECT_LT(sum / (4 * cases), 0.2);
}

TEST(MarkerCorners, WithoutEdgesTheCornersAreKept) {
  const auto truth = square(60, 50, 30, 10 * kDeg);
  RgbImage flat(140, 110);
  std::fill(flat.pixels.begin(), flat.pixels.end(), 128);
  const auto refined = refineMarkerCorners(flat, truth);
  for (std::size_t k = 0; k < 4; ++k) {
    EXPECT_EQ(refined[k], truth[k]);
  }
  // Corners in the image's border region, and an empty image: unchanged, no crash.
  const auto outside = square(2, 2, 30, 0);
  const auto kept = refineMarkerCorners(flat, outside);
  EXPECT_EQ(kept[2], outside[2]);
  EXPECT_EQ(refineMarkerCorners(RgbImage{}, truth)[0], truth[0]);
}

TEST(MarkerCorners, PoseFromCornersIsExactOnExactCornersAndEmptyOnNonsense) {
  const camera::Intrinsics in = camera::Intrinsics::fromHorizontalFov(640, 480, 58 * kDeg);
  const world::Pose marker = world::poseFromXyzRpy(0.1, -0.05, 0.9, 160 * kDeg, 10 * kDeg, 25 * kDeg);
  std::array<Eigen::Vector2d, 4> corners;
  const auto points = markerCorners(0.05);
  for (std::size_t k = 0; k < 4; ++k) {
    const Eigen::Vector3d c = marker * points[k];
    corners[k] = Eigen::Vector2d(in.fx * c.x() / c.z() + in.cx, in.fy * c.y() / c.z() + in.cy);
  }
  const auto pose = markerPoseFromCorners(corners, in, 0.05);
  ASSERT_TRUE(pose.has_value());
  EXPECT_LT((pose->translation() - marker.translation()).norm(), 1e-6);
  EXPECT_LT(world::rotationAngle(*pose, marker), 1e-6);
  const std::array<Eigen::Vector2d, 4> nonsense = {Eigen::Vector2d(1, 1), Eigen::Vector2d(1, 1), Eigen::Vector2d(1, 1),
                                                   Eigen::Vector2d(1, 1)};
  EXPECT_FALSE(markerPoseFromCorners(nonsense, in, 0.05).has_value());
}

}  // namespace
}  // namespace costar::calibration
