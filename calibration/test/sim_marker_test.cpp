// The gripper's marker as the simulated camera sees it: found where the simulator says it is.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "calibration/hand_eye.h"
#include "perception/aruco_marker.h"
#include "sim/simulation.h"

namespace costar::calibration {
namespace {

TEST(SimMarker, CornersAreSeenWhereTheSimulatorPutsThem) {
  int seen = 0;
  double worst = 0.0;
  for (const double turn : {0.0, M_PI / 2, M_PI, 3 * M_PI / 2}) {
    sim::SimulationOptions options;
    sim::ArmJoints q = sim::Simulation::homeConfiguration();
    q[5] += turn;  // one of the four turns faces the marker towards the camera
    options.initial_arm = q;
    options.depth_noise.enabled = true;
    const auto simulation = sim::Simulation::create(sim::loadScene("sim/scenes/one_node.json"), options);
    const camera::RgbdFrame frame = simulation->captureRgbd(1);
    const world::Pose marker_in_camera = simulation->rgbdPose().inverse() * simulation->gripperMarkerPose();
    for (const auto& detection : perception::detectArucoMarkers(frame.rgb, frame.intrinsics,
                                                                sim::Simulation::kGripperMarkerSize)) {
      if (detection.id != sim::Simulation::kGripperMarkerId) {
        continue;
      }
      ++seen;
      const auto corners = markerCorners(sim::Simulation::kGripperMarkerSize);
      for (std::size_t k = 0; k < 4; ++k) {
        const Eigen::Vector3d c = marker_in_camera * corners[k];
        const Eigen::Vector2d expected(frame.intrinsics.fx * c.x() / c.z() + frame.intrinsics.cx,
                                       frame.intrinsics.fy * c.y() / c.z() + frame.intrinsics.cy);
        const double error = (expected - detection.corners[k]).norm();
        std::printf("turn %.1f corner %zu: expected %.2f %.2f seen %.2f %.2f (%.2f px)\n", turn, k, expected.x(),
                    expected.y(), detection.corners[k].x(), detection.corners[k].y(), error);
        worst = std::max(worst, error);
      }
    }
  }
  EXPECT_GE(seen, 2);
  EXPECT_LT(worst, 1.0);
}

}  // namespace
}  // namespace costar::calibration
