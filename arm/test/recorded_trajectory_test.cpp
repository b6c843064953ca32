// Recorded trajectories (arm/recorded_trajectory.h): their simplification, and their place in the
// waypoint file beside the waypoints (the same lock and merging).
#include "arm/recorded_trajectory.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include <Eigen/Geometry>

#include "arm/waypoints.h"

namespace costar::arm {
namespace {

/// A stroke sampled at 100 Hz: a straight line, then a quarter circle turning the tool, then a hold.
RecordedTrajectory stroke() {
  RecordedTrajectory t;
  t.name = "stroke";
  for (int i = 0; i <= 400; ++i) {
    const double time = 0.01 * i;
    world::Pose pose = world::Pose::Identity();
    if (time <= 1.0) {
      pose.translation() = Eigen::Vector3d(0.1 * time, 0.0, 0.2);
    } else if (time <= 3.0) {
      const double angle = (time - 1.0) / 2.0 * M_PI / 2.0;
      pose.translation() = Eigen::Vector3d(0.1 + 0.1 * std::sin(angle), 0.1 - 0.1 * std::cos(angle), 0.2);
      pose.linear() = Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    } else {
      pose.translation() = Eigen::Vector3d(0.2, 0.1, 0.2);
      pose.linear() = Eigen::AngleAxisd(M_PI / 2.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    }
    t.times.push_back(time);
    t.poses.push_back(pose);
  }
  return t;
}

TEST(RecordedTrajectory, SimplifiedItKeepsEverySampleWithinTheToleranceInPlaceAndTime) {
  const RecordedTrajectory recorded = stroke();
  const SimplifyTolerance tolerance;
  const RecordedTrajectory kept = simplify(recorded, tolerance);
  EXPECT_LT(kept.poses.size(), 40U);
  EXPECT_GE(kept.poses.size(), 4U);
  EXPECT_EQ(kept.times.front(), 0.0);
  EXPECT_EQ(kept.times.back(), 4.0);
  for (std::size_t i = 0; i < recorded.poses.size(); ++i) {
    const world::Pose at = kept.at(recorded.times[i]);
    EXPECT_LE((at.translation() - recorded.poses[i].translation()).norm(), tolerance.position + 1e-12) << i;
    EXPECT_LE(world::rotationAngle(at, recorded.poses[i]), tolerance.angle + 1e-12) << i;
  }
  EXPECT_NEAR(kept.length(), recorded.length(), 0.002);
  RecordedTrajectory bad = recorded;
  bad.times[5] = bad.times[4];
  EXPECT_THROW(simplify(bad), std::invalid_argument);
}

class TrajectoryFile : public ::testing::Test {
 protected:
  void SetUp() override {
    folder_ =
        std::filesystem::temp_directory_path() /
        ("costar_trajectory_file_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    std::filesystem::remove_all(folder_);
    std::filesystem::create_directories(folder_);
  }
  void TearDown() override { std::filesystem::remove_all(folder_); }
  std::filesystem::path folder_;
};

TEST_F(TrajectoryFile, TwoWritersKeepEachOthersTrajectoriesAndWaypoints) {
  const auto file = folder_ / "waypoints.json";
  WaypointStore editor(file, true, 6);
  WaypointStore terminal(file, true, 6);
  RecordedTrajectory t = simplify(stroke());
  t.frame = "node_2";
  editor.putTrajectory(t);
  Waypoint waypoint;
  waypoint.name = "above";
  terminal.put(waypoint);  // read the file anew under its lock: the trajectory stays
  const WaypointStore reader(file, true, 6);
  ASSERT_TRUE(reader.findTrajectory("stroke"));
  EXPECT_TRUE(reader.find("above"));
  const RecordedTrajectory back = *reader.findTrajectory("stroke");
  EXPECT_EQ(back.frame, "node_2");
  ASSERT_EQ(back.poses.size(), t.poses.size());
  for (std::size_t i = 0; i < t.poses.size(); ++i) {
    EXPECT_TRUE(back.poses[i].isApprox(t.poses[i], 1e-12));
    EXPECT_EQ(back.times[i], t.times[i]);
  }
  EXPECT_TRUE(terminal.removeTrajectory("stroke"));
  EXPECT_FALSE(editor.findTrajectory("stroke"));
  EXPECT_TRUE(editor.find("above"));
  // A bad trajectory is refused before anything is written.
  RecordedTrajectory bad = t;
  bad.name = "bad name!";
  EXPECT_THROW(editor.putTrajectory(bad), std::invalid_argument);
}

TEST_F(TrajectoryFile, ABrokenTrajectoryInTheFileIsRefusedNamingItsField) {
  const auto file = folder_ / "waypoints.json";
  std::ofstream(file) << R"({"waypoints": [], "trajectories": [
      {"name": "s", "frame": "world", "times": [0, 0.5, 0.5],
       "poses": [[0,0,0,1,0,0,0], [0.1,0,0,1,0,0,0], [0.2,0,0,1,0,0,0]]}]})";
  try {
    WaypointStore store(file, true, 6);
    FAIL() << "loaded";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("trajectories[0].times[2]: must be later than times[1]"), std::string::npos)
        << e.what();
  }
  std::ofstream(file) << R"({"waypoints": [], "trajectories": [
      {"name": "s", "frame": "world", "times": [0, 1], "poses": [[0,0,0,1,0,0,0], [0.1,0,0,2,0,0,0]]}]})";
  try {
    WaypointStore store(file, true, 6);
    FAIL() << "loaded";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("trajectories[0].poses[1]: its quaternion must have unit length"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace costar::arm
