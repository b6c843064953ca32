#include "calibration/hand_eye.h"

#include <gtest/gtest.h>

#include <random>

namespace costar::calibration {
namespace {

constexpr double kDeg = M_PI / 180.0;

camera::Intrinsics intrinsics() { return camera::Intrinsics::fromHorizontalFov(640, 480, 58.0 * kDeg); }

/// The workcell's set-up: a camera across the table looking at the arm; the marker on the
/// gripper's side.
struct Synthetic {
  world::Pose camera = world::Pose::Identity();  // Y
  world::Pose marker = world::Pose::Identity();  // X
  std::vector<MarkerView> views;
};

world::Pose facing(const Eigen::Vector3d& p, const Eigen::Vector3d& camera) {
  const Eigen::Vector3d z = (camera - p).normalized();
  const Eigen::Vector3d y = (Eigen::Vector3d::UnitZ() - Eigen::Vector3d::UnitZ().dot(z) * z).normalized();
  world::Pose pose = world::Pose::Identity();
  pose.linear().col(0) = y.cross(z);
  pose.linear().col(1) = y;
  pose.linear().col(2) = z;
  pose.translation() = p;
  return pose;
}

/// Views with the marker at random places facing the camera, tilted by up to `tilt_deg`;
/// corner noise `pixel_sigma`, ArUco pose noise as ArUco has it (mm in depth, a degree).
Synthetic makeViews(int count, double tilt_deg, double pixel_sigma, std::uint64_t seed, bool one_axis = false,
                    double spread = 1.0) {
  Synthetic s;
  s.camera = world::poseFromXyzRpy(1.25, 0.02, 0.85, 0, 0, 0);
  s.camera.linear() = facing(Eigen::Vector3d(1.25, 0.02, 0.85), Eigen::Vector3d(0.3, 0, 0)).linear() *
                      Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()).toRotationMatrix();
  // The optical frame looks along +z at the workspace: z towards (0.3, 0, 0).
  {
    const Eigen::Vector3d z = (Eigen::Vector3d(0.4, 0, 0) - s.camera.translation()).normalized();
    const Eigen::Vector3d x = Eigen::Vector3d::UnitZ().cross(z).normalized() * -1.0;
    s.camera.linear().col(0) = x;
    s.camera.linear().col(2) = z;
    s.camera.linear().col(1) = z.cross(x);
  }
  s.marker = world::poseFromXyzRpy(0.0353, 0.002, 0.075 - 0.14, -M_PI / 2, 0, -M_PI / 2);
  std::mt19937_64 random(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::normal_distribution<double> noise(0.0, 1.0);
  const auto corners = markerCorners(0.05);
  const camera::Intrinsics in = intrinsics();
  for (int i = 0; i < count; ++i) {
    const Eigen::Vector3d p(0.475 + spread * 0.15 * unit(random), spread * 0.25 * unit(random),
                            0.3 + spread * 0.12 * unit(random));
    world::Pose marker_in_world = facing(p, s.camera.translation());
    if (one_axis) {
      marker_in_world.linear() =
          marker_in_world.linear() * Eigen::AngleAxisd(tilt_deg * kDeg * unit(random), Eigen::Vector3d::UnitZ());
    } else {
      marker_in_world.linear() =
          marker_in_world.linear() * (Eigen::AngleAxisd(tilt_deg * kDeg * unit(random), Eigen::Vector3d::UnitX()) *
                                      Eigen::AngleAxisd(tilt_deg * kDeg * unit(random), Eigen::Vector3d::UnitY()) *
                                      Eigen::AngleAxisd(tilt_deg * kDeg * unit(random), Eigen::Vector3d::UnitZ()))
                                         .toRotationMatrix();
    }
    MarkerView view;
    view.flange_in_world = marker_in_world * s.marker.inverse();
    const world::Pose in_camera = s.camera.inverse() * marker_in_world;
    for (std::size_t k = 0; k < 4; ++k) {
      const Eigen::Vector3d c = in_camera * corners[k];
      view.corners[k] = Eigen::Vector2d(in.fx * c.x() / c.z() + in.cx + pixel_sigma * noise(random),
                                        in.fy * c.y() / c.z() + in.cy + pixel_sigma * noise(random));
    }
    view.marker_in_camera = in_camera;
    if (pixel_sigma > 0) {
      view.marker_in_camera.translation() += in_camera.translation().normalized() * 0.003 * noise(random);
      view.marker_in_camera.linear() =
          view.marker_in_camera.linear() *
          Eigen::AngleAxisd(0.5 * kDeg * noise(random), Eigen::Vector3d(unit(random), unit(random), 1).normalized())
              .toRotationMatrix();
    }
    s.views.push_back(view);
  }
  return s;
}

double millimetres(const world::Pose& a, const world::Pose& b) {
  return (a.translation() - b.translation()).norm() * 1000;
}
double degrees(const world::Pose& a, const world::Pose& b) { return world::rotationAngle(a, b) / kDeg; }

TEST(HandEye, EveryMethodIsExactWithoutNoise) {
  const Synthetic s = makeViews(15, 30, 0.0, 1);
  for (const HandEyeMethod method : allMethods()) {
    const MarkerCalibration result = solveMarker(s.views, intrinsics(), method, false);
    EXPECT_LT(millimetres(result.camera_in_world, s.camera), 0.5) << methodName(method);
    EXPECT_LT(degrees(result.camera_in_world, s.camera), 0.05) << methodName(method);
    EXPECT_LT(millimetres(result.marker_in_flange, s.marker), 0.5) << methodName(method);
    EXPECT_LT(result.residuals.reprojection_rms_px, 0.05) << methodName(method);
  }
}

TEST(HandEye, RefinementOnCornersBeatsNoisyArucoPoses) {
  const Synthetic s = makeViews(15, 30, 0.2, 2);
  const MarkerCalibration raw =
      solveMarker(s.views, intrinsics(), HandEyeMethod::kDaniilidis, false, {.max_reprojection_rms_px = 100});
  const MarkerCalibration refined = solveMarker(s.views, intrinsics(), HandEyeMethod::kDaniilidis, true);
  EXPECT_TRUE(refined.refined);
  EXPECT_LT(millimetres(refined.marker_in_flange, s.marker), 1.0);
  EXPECT_LT(millimetres(refined.camera_in_world, s.camera), 2.0);
  EXPECT_LT(degrees(refined.camera_in_world, s.camera), 0.1);
  EXPECT_LT(refined.residuals.reprojection_rms_px, raw.residuals.reprojection_rms_px);
  EXPECT_LT(refined.residuals.reprojection_rms_px, 0.4);
}

TEST(HandEye, CameraFromAFewViewsOnceTheMarkerIsKnown) {
  const Synthetic s = makeViews(5, 0, 0.2, 3);
  const CameraCalibration result = solveCamera(s.views, intrinsics(), s.marker);
  EXPECT_LT(millimetres(result.camera_in_world, s.camera), 2.0);
  EXPECT_LT(degrees(result.camera_in_world, s.camera), 0.1);
  EXPECT_EQ(result.views, 5);
}

TEST(HandEye, AViewThatDoesNotFitIsLeftOut) {
  Synthetic s = makeViews(10, 0, 0.2, 11);
  // One misdetection: a corner 6 px off.
  s.views[3].corners[2] += Eigen::Vector2d(6, -3);
  const CameraCalibration kept = solveCamera(s.views, intrinsics(), s.marker, {.outlier_factor = 0});
  const CameraCalibration cleaned = solveCamera(s.views, intrinsics(), s.marker);
  EXPECT_EQ(kept.rejected, 0);
  EXPECT_EQ(kept.views, 10);
  EXPECT_EQ(cleaned.rejected, 1);
  EXPECT_EQ(cleaned.views, 9);
  EXPECT_LT(cleaned.residuals.reprojection_rms_px, kept.residuals.reprojection_rms_px);
  EXPECT_LT(millimetres(cleaned.camera_in_world, s.camera), millimetres(kept.camera_in_world, s.camera));
  // Clean views: none left out.
  const Synthetic clean = makeViews(10, 0, 0.2, 12);
  EXPECT_EQ(solveCamera(clean.views, intrinsics(), clean.marker).rejected, 0);
  // The marker stage too.
  Synthetic tilted = makeViews(15, 30, 0.2, 13);
  tilted.views[5].corners[1] += Eigen::Vector2d(-7, 5);
  const MarkerCalibration marker = solveMarker(tilted.views, intrinsics(), HandEyeMethod::kDaniilidis, true);
  EXPECT_EQ(marker.rejected, 1);
  EXPECT_LT(millimetres(marker.marker_in_flange, tilted.marker), 1.0);
}

TEST(HandEye, TooFewViewsFailWithTheReason) {
  const Synthetic s = makeViews(4, 30, 0.0, 4);
  try {
    solveMarker(s.views, intrinsics(), HandEyeMethod::kDaniilidis, true);
    FAIL() << "4 views accepted";
  } catch (const CalibrationError& e) {
    EXPECT_NE(std::string(e.what()).find("at least 6"), std::string::npos) << e.what();
  }
  const Synthetic two = makeViews(2, 0, 0.0, 4);
  EXPECT_THROW(solveCamera(two.views, intrinsics(), two.marker), CalibrationError);
}

TEST(HandEye, TooSimilarPosesFail) {
  const Synthetic s = makeViews(10, 3, 0.0, 5, false, 0.05);
  try {
    solveMarker(s.views, intrinsics(), HandEyeMethod::kDaniilidis, true);
    FAIL() << "poses within a few degrees accepted";
  } catch (const CalibrationError& e) {
    EXPECT_NE(std::string(e.what()).find("too similar"), std::string::npos) << e.what();
  }
}

TEST(HandEye, RotationAboutOneAxisIsDegenerate) {
  Synthetic s = makeViews(10, 60, 0.0, 6, /*one_axis=*/true);
  // Keep the marker's normal fixed in the world: every flange turns about the same axis.
  const world::Pose first = s.views.front().flange_in_world * s.marker;
  const Eigen::Vector3d axis = first.linear().col(2);
  for (std::size_t i = 0; i < s.views.size(); ++i) {
    world::Pose marker = first;
    marker.linear() = Eigen::AngleAxisd(0.1 * static_cast<double>(i), axis) * first.linear();
    s.views[i].flange_in_world = marker * s.marker.inverse();
    s.views[i].marker_in_camera = s.camera.inverse() * marker;
  }
  try {
    solveMarker(s.views, intrinsics(), HandEyeMethod::kDaniilidis, true);
    FAIL() << "a single rotation axis accepted";
  } catch (const CalibrationError& e) {
    EXPECT_NE(std::string(e.what()).find("degenerate"), std::string::npos) << e.what();
  }
}

TEST(HandEye, LargeResidualsFail) {
  Synthetic s = makeViews(5, 0, 0.0, 7);
  // The marker is not where the calibration says (it slipped 2 cm on the gripper).
  world::Pose wrong = s.marker;
  wrong.translation().z() += 0.02;
  const Synthetic other = makeViews(5, 0, 0.0, 8);
  std::vector<MarkerView> mixed = s.views;
  for (auto& view : mixed) {
    view.corners[0] += Eigen::Vector2d(15, -12);
  }
  try {
    solveCamera(mixed, intrinsics(), s.marker);
    FAIL() << "corners off by 20 px accepted";
  } catch (const CalibrationError& e) {
    EXPECT_NE(std::string(e.what()).find("px"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(other.views.empty());
}

TEST(HandEye, MethodNames) {
  for (const HandEyeMethod method : allMethods()) {
    EXPECT_EQ(methodFromName(methodName(method)), method);
  }
  EXPECT_THROW(methodFromName("magic"), std::invalid_argument);
}

}  // namespace
}  // namespace costar::calibration
