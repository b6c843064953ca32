#include "calibration/calibration_file.h"

#include <gtest/gtest.h>

#include <fstream>

namespace costar::calibration {
namespace {

std::filesystem::path tempFile(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / ("costar_calibration_test_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  return dir / name;
}

TEST(CalibrationFile, RoundTrip) {
  CellCalibration c;
  c.marker_in_flange = world::poseFromXyzRpy(0.03, -0.01, 0.07, 0.1, -0.2, 0.3);
  c.marker_method = "daniilidis+reprojection";
  c.marker_views = 12;
  c.marker_residuals.reprojection_rms_px = 0.21;
  c.camera_in_world = world::poseFromXyzRpy(1.2, 0.05, 0.86, 2.0, 0.1, -1.5);
  c.camera_views = 5;
  const auto file = tempFile("round_trip.json");
  saveCalibration(file, c);
  const auto loaded = loadCalibration(file);
  ASSERT_TRUE(loaded.has_value());
  EXPECT_TRUE(loaded->marker_in_flange->isApprox(*c.marker_in_flange, 1e-12));
  EXPECT_TRUE(loaded->camera_in_world->isApprox(*c.camera_in_world, 1e-12));
  EXPECT_EQ(loaded->marker_method, c.marker_method);
  EXPECT_EQ(loaded->marker_views, 12);
  EXPECT_DOUBLE_EQ(loaded->marker_residuals.reprojection_rms_px, 0.21);
}

TEST(CalibrationFile, MissingFileIsNoCalibration) {
  EXPECT_FALSE(loadCalibration(tempFile("absent.json")).has_value());
}

TEST(CalibrationFile, BadFilesNameTheFileAndField) {
  const auto file = tempFile("bad.json");
  std::ofstream(file) << R"({"camera": {"camera_in_world": {"xyz": [1, 2], "quaternion_wxyz": [1, 0, 0, 0]}}})";
  try {
    loadCalibration(file);
    FAIL() << "a 2-number position accepted";
  } catch (const std::runtime_error& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find(file.string()), std::string::npos) << message;
    EXPECT_NE(message.find("camera.camera_in_world"), std::string::npos) << message;
  }
  std::ofstream(file) << "{not json";
  EXPECT_THROW(loadCalibration(file), std::runtime_error);
  std::ofstream(file) << R"({"marker": {"marker_in_flange": {"xyz": [0, 0, 0], "quaternion_wxyz": [0, 0, 0, 0]}}})";
  EXPECT_THROW(loadCalibration(file), std::runtime_error);
}

// Issue 27: a workcell's "calibration" pointing at any JSON object (an object class) was taken
// as an empty calibration.
TEST(CalibrationFile, AnotherJsonFileIsNotACalibration) {
  const auto file = tempFile("object_class.json");
  std::ofstream(file) << R"({"name": "node", "mass": 0.08})";
  try {
    loadCalibration(file);
    FAIL() << "an object class taken as a calibration";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), "calibration '" + file.string() +
                                         "': mass: unknown field: a calibration holds \"marker\" and/or \"camera\" "
                                         "(is this a calibration file?)");
  }
  std::ofstream(file) << R"({"camera": {}, "camera": {}})";
  EXPECT_THROW(loadCalibration(file), std::runtime_error);
}

}  // namespace
}  // namespace costar::calibration
