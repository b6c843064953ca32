// The gripper's marker as the simulated camera sees it: found where the simulator says it is.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "arm/test/published_arms.h"
#include "arm/ur5_kinematics.h"
#include "calibration/hand_eye.h"
#include "calibration/marker_corners.h"
#include "calibration/view_planner.h"
#include "perception/aruco_marker.h"
#include "sim/simulation.h"

namespace costar::calibration {
namespace {

TEST(SimMarker, CornersAreSeenWhereTheSimulatorPutsThem) {
  int seen = 0;
  double worst = 0.0;
  double worst_refined = 0.0;
  double worst_pose_mm = 0.0;
  double worst_pose_deg = 0.0;
  const world::Pose base_in_world(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitZ()));
  const world::Pose marker_in_flange = world::poseFromXyzRpy(0.0353, 0, 0.075, -M_PI / 2, 0, -M_PI / 2);
  const arm::Ur5Kinematics kinematics(arm::published::ur5Dh(), arm::published::ur5Limits());
  for (const Eigen::Vector3d& place :
       {Eigen::Vector3d(0.45, -0.15, 0.25), Eigen::Vector3d(0.55, 0.15, 0.3), Eigen::Vector3d(0.5, 0.0, 0.2)}) {
    // The marker facing the drawn camera there; the arm's configuration from the UR5's IK.
    sim::SimulationOptions options;
    {
      const auto probe = sim::Simulation::create(sim::loadScene("sim/scenes/one_node.json"), options);
      const world::Pose marker = facingCamera(place, probe->rgbdNominalPose());
      const world::Pose flange_in_base = base_in_world.inverse() * marker * marker_in_flange.inverse();
      std::array<arm::JointVector, arm::Ur5Kinematics::kMaxSolutions> solutions;
      const int count = kinematics.inverse(flange_in_base, solutions, 0.0);
      ASSERT_GT(count, 0);
      // The elbow-up solution with the wrist nearest the home configuration.
      const sim::ArmJoints home = sim::Simulation::homeConfiguration();
      int best = 0;
      double nearest = 1e9;
      for (int s = 0; s < count; ++s) {
        double d = 0;
        for (int j = 0; j < 6; ++j) {
          d += std::pow(std::remainder(solutions[s][j] - home[j], 2 * M_PI), 2);
        }
        if (d < nearest) {
          nearest = d;
          best = s;
        }
      }
      sim::ArmJoints q = home;
      for (int j = 0; j < 6; ++j) {
        q[j] = home[j] + std::remainder(solutions[best][j] - home[j], 2 * M_PI);
      }
      options.initial_arm = q;
    }
    options.depth_noise.enabled = true;
    const auto simulation = sim::Simulation::create(sim::loadScene("sim/scenes/one_node.json"), options);
    const camera::RgbdFrame frame = simulation->captureRgbd(1);
    const world::Pose marker_in_camera = simulation->rgbdPose().inverse() * simulation->gripperMarkerPose();
    for (const auto& detection :
         perception::detectArucoMarkers(frame.rgb, frame.intrinsics, sim::Simulation::kGripperMarkerSize)) {
      if (detection.id != sim::Simulation::kGripperMarkerId) {
        continue;
      }
      ++seen;
      const auto corners = markerCorners(sim::Simulation::kGripperMarkerSize);
      std::array<Eigen::Vector2d, 4> aruco;
      for (std::size_t k = 0; k < 4; ++k) {
        aruco[k] = detection.corners[k];
      }
      const std::array<Eigen::Vector2d, 4> refined = refineMarkerCorners(frame.rgb, aruco);
      for (std::size_t k = 0; k < 4; ++k) {
        const Eigen::Vector3d c = marker_in_camera * corners[k];
        const Eigen::Vector2d expected(frame.intrinsics.fx * c.x() / c.z() + frame.intrinsics.cx,
                                       frame.intrinsics.fy * c.y() / c.z() + frame.intrinsics.cy);
        const double error = (expected - aruco[k]).norm();
        const double refined_error = (expected - refined[k]).norm();
        std::printf(
            "place %.2f %.2f corner %zu: expected %.2f %.2f, ArUco %.2f %.2f (%.2f px), refined %.2f %.2f "
            "(%.2f px)\n",
            place.x(), place.y(), k, expected.x(), expected.y(), aruco[k].x(), aruco[k].y(), error, refined[k].x(),
            refined[k].y(), refined_error);
        worst = std::max(worst, error);
        worst_refined = std::max(worst_refined, refined_error);
      }
      const auto pose = markerPoseFromCorners(refined, frame.intrinsics, sim::Simulation::kGripperMarkerSize);
      ASSERT_TRUE(pose.has_value());
      const double pose_mm = (pose->translation() - marker_in_camera.translation()).norm() * 1000;
      const double pose_deg = world::rotationAngle(*pose, marker_in_camera) * 180 / M_PI;
      std::printf("place %.2f %.2f: marker pose from the refined corners %.2f mm / %.2f deg off\n", place.x(),
                  place.y(), pose_mm, pose_deg);
      worst_pose_mm = std::max(worst_pose_mm, pose_mm);
      worst_pose_deg = std::max(worst_pose_deg, pose_deg);
    }
  }
  EXPECT_EQ(seen, 3);
  // Measured: ArUco's corners 0.25 to 3.7 px off (the rendering has no anti-aliasing and the
  // 5 cm marker is ~30 px wide, so they snap to whole pixels and one may be off by pixels);
  // refined on the marker's edges (marker_corners.h), 0.12 to 0.33 px.
  EXPECT_LT(worst, 5.0);
  EXPECT_LT(worst_refined, 0.6);
  // One small marker's own pose stays weak even so (measured 3.8 to 6.7 mm, 5.9 to 6.3 deg,
  // facing the camera squarely): the reason Calibrate fits one PnP over many views' corners.
  EXPECT_LT(worst_pose_mm, 15.0);
  EXPECT_LT(worst_pose_deg, 10.0);
}

}  // namespace
}  // namespace costar::calibration
