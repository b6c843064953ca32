#include "calibration/view_planner.h"

#include <gtest/gtest.h>

namespace costar::calibration {
namespace {

constexpr double kDeg = M_PI / 180.0;

world::Pose camera() {
  // Across the table, looking back at the workspace: the workcell's drawing (sim/models), as an
  // optical frame (MuJoCo's camera axes x, -y, -z).
  world::Pose pose = world::Pose::Identity();
  const Eigen::Vector3d x(0, 1, 0);
  const Eigen::Vector3d y(-0.7282, 0, 0.6854);
  pose.linear().col(0) = x;
  pose.linear().col(1) = -y;
  pose.linear().col(2) = -x.cross(y);
  pose.translation() = Eigen::Vector3d(1.25, 0, 0.85);
  return pose;
}

TEST(ViewPlanner, FacingCameraPointsTheMarkerAtIt) {
  const world::Pose marker = facingCamera(Eigen::Vector3d(0.5, 0.1, 0.3), camera());
  const Eigen::Vector3d to_camera = (camera().translation() - marker.translation()).normalized();
  EXPECT_NEAR(marker.linear().col(2).dot(to_camera), 1.0, 1e-9);
  EXPECT_GT(marker.linear().col(1).z(), 0.5);  // upright
  EXPECT_NEAR(marker.linear().determinant(), 1.0, 1e-9);
}

TEST(ViewPlanner, CameraStageSpreadsOverTheRegionFacingTheCamera) {
  ViewPlanOptions options;
  const auto poses = candidateMarkerPoses(camera(), options, 9);
  ASSERT_EQ(poses.size(), 9u);
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e9);
  Eigen::Vector3d hi = -lo;
  const camera::Intrinsics in = camera::Intrinsics::fromHorizontalFov(640, 480, 58 * kDeg);
  int in_view = 0;
  for (const auto& pose : poses) {
    lo = lo.cwiseMin(pose.translation());
    hi = hi.cwiseMax(pose.translation());
    const bool seen = markerInView(pose, 0.05, camera(), in, 30, 50);
    in_view += seen ? 1 : 0;
    EXPECT_TRUE(seen) << pose.translation().transpose();
  }
  EXPECT_GT((hi - lo).norm(), 0.5);
  EXPECT_EQ(in_view, 9);
}

TEST(ViewPlanner, CameraStageRollsTheMarkerAboutItsNormalInTurn) {
  ViewPlanOptions options;
  options.facing_roll_deg = 20;
  const auto poses = candidateMarkerPoses(camera(), options, 12);
  ASSERT_EQ(poses.size(), 12u);
  const double expected[] = {20, 20, 10, 10};
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const world::Pose facing = facingCamera(poses[i].translation(), camera());
    // Still facing the camera; turned about the normal only.
    EXPECT_NEAR(poses[i].linear().col(2).dot(facing.linear().col(2)), 1.0, 1e-9);
    const double roll = world::rotationAngle(poses[i], facing) / kDeg;
    if (i < 9) {
      EXPECT_NEAR(roll, expected[i % 4], 1e-6) << i;
    } else {
      EXPECT_LE(roll, 20 + 1e-6) << i;
    }
  }
  // Turned one way, then the other.
  const auto signedRoll = [&](const world::Pose& pose) {
    const world::Pose facing = facingCamera(pose.translation(), camera());
    const Eigen::Vector3d x = facing.linear().transpose() * pose.linear().col(0);
    return std::atan2(x.y(), x.x());
  };
  EXPECT_GT(signedRoll(poses[0]), 0);
  EXPECT_LT(signedRoll(poses[1]), 0);
}

TEST(ViewPlanner, MarkerStageSeparatesRotationsAndIsSeeded) {
  ViewPlanOptions options;
  options.tilt_deg = 35;
  options.roll_deg = 60;
  options.min_separation_deg = 12;
  const auto a = candidateMarkerPoses(camera(), options, 20);
  const auto b = candidateMarkerPoses(camera(), options, 20);
  ASSERT_EQ(a.size(), 20u);
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_TRUE(a[i].isApprox(b[i]));
    for (std::size_t j = 0; j < i; ++j) {
      EXPECT_GE(world::rotationAngle(a[i], a[j]), 12 * kDeg - 1e-9);
    }
  }
  options.seed = 2;
  EXPECT_FALSE(candidateMarkerPoses(camera(), options, 20)[0].isApprox(a[0]));
}

TEST(ViewPlanner, MarkerOutOfViewOrTurnedAwayIsRefused) {
  const camera::Intrinsics in = camera::Intrinsics::fromHorizontalFov(640, 480, 58 * kDeg);
  world::Pose marker = facingCamera(Eigen::Vector3d(0.5, 0, 0.3), camera());
  EXPECT_TRUE(markerInView(marker, 0.05, camera(), in, 30, 50));
  world::Pose away = marker;
  away.linear() = marker.linear() * Eigen::AngleAxisd(70 * kDeg, Eigen::Vector3d::UnitY()).toRotationMatrix();
  EXPECT_FALSE(markerInView(away, 0.05, camera(), in, 30, 50));
  world::Pose aside = facingCamera(Eigen::Vector3d(0.5, 1.5, 0.3), camera());
  EXPECT_FALSE(markerInView(aside, 0.05, camera(), in, 30, 50));
}

}  // namespace
}  // namespace costar::calibration
