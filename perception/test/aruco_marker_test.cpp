// The workspace centre from the ArUco marker, on a synthetic image of a marker on the table.

#include "perception/aruco_marker.h"

#include <gtest/gtest.h>

#include "perception/test/synthetic_scene.h"

namespace costar::perception {
namespace {

/// The synthetic table with the marker image (13.33 cm with its quiet zone, i.e. a 10 cm
/// marker) lying at `center`, image right along center's x, image up along its y.
camera::RgbdFrame markerOnTable(const world::Pose& center) {
  camera::RgbdFrame frame = test::renderSynthetic({}, 0.0005, 4);
  const RgbImage marker = arucoMarkerImage(0, 40, 1);
  const double side = 0.1 * marker.width / 240.0;
  const world::Pose to_marker = center.inverse();
  const camera::Intrinsics& in = frame.intrinsics;
  for (int v = 0; v < in.height; ++v) {
    for (int u = 0; u < in.width; ++u) {
      if (!frame.valid(u, v)) {
        continue;
      }
      // Where the pixel's ray meets the marker's plane (the table: z = 0).
      const Eigen::Vector3d ray =
          frame.camera_pose.linear() * Eigen::Vector3d((u - in.cx) / in.fx, (v - in.cy) / in.fy, 1);
      const double t = -frame.camera_pose.translation().z() / ray.z();
      const Eigen::Vector3d on_marker = to_marker * (frame.camera_pose.translation() + t * ray);
      const double mx = (on_marker.x() / side + 0.5) * marker.width;
      const double my = (0.5 - on_marker.y() / side) * marker.height;
      if (mx < 0 || my < 0 || mx >= marker.width || my >= marker.height) {
        continue;
      }
      const std::uint8_t* texel = marker.at(static_cast<int>(mx), static_cast<int>(my));
      std::copy(texel, texel + 3, frame.rgb.at(u, v));
    }
  }
  return frame;
}

TEST(ArucoMarker, TheMarkerImageHasItsQuietZone) {
  const RgbImage image = arucoMarkerImage(0, 10, 1);
  EXPECT_EQ(image.width, 80);
  EXPECT_EQ(image.at(5, 5)[0], 255);  // quiet zone: white
  EXPECT_EQ(image.at(12, 12)[0], 0);  // the marker's black border
}

TEST(ArucoMarker, FindsTheWorkspaceCentre) {
  const world::Pose center = world::poseFromXyzRpy(0.5, 0.02, 0.0, 0, 0, 0.15);
  const camera::RgbdFrame frame = markerOnTable(center);
  const auto markers = detectArucoMarkers(frame.rgb, frame.intrinsics, 0.1);
  ASSERT_EQ(markers.size(), 1u);
  EXPECT_EQ(markers[0].id, 0);
  EXPECT_EQ(markers[0].corners.size(), 4u);
  const std::optional<world::Pose> found = locateWorkspaceCenter(frame);
  ASSERT_TRUE(found.has_value());
  EXPECT_LT((found->translation() - center.translation()).norm(), 0.002);
  EXPECT_LT(world::rotationAngle(*found, center), 0.5 * M_PI / 180);
}

TEST(ArucoMarker, NoMarkerNoCentre) {
  const camera::RgbdFrame frame = test::renderSynthetic({});
  EXPECT_FALSE(locateWorkspaceCenter(frame).has_value());
  MarkerOptions other;
  other.id = 7;
  EXPECT_FALSE(locateWorkspaceCenter(markerOnTable(world::Pose(Eigen::Translation3d(0.5, 0, 0))), other).has_value());
}

}  // namespace
}  // namespace costar::perception
