// The workcell description files: both cells load, bad files are refused naming the file, the
// field and the problem.

#include "workcell/sim_cell_description.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "core/paths.h"
#include "workcell/workcell.h"

namespace costar::workcell {
namespace {

using nlohmann::json;

TEST(SimCellDescription, BothCellsLoadAndAreListed) {
  const SimCellDescription ur5 = loadSimCellDescription(simCellFile("ur5-sim"));
  EXPECT_EQ(ur5.robot, "ur5");
  EXPECT_EQ(ur5.gripper, "parallel-2f");
  // Bit for bit the base the UR5 cell always had: turned 180 degrees about z.
  EXPECT_TRUE(ur5.robot_base.isApprox(world::Pose(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitZ())), 0.0));
  const SimCellDescription iiwa = loadSimCellDescription(simCellFile("iiwa-sim"));
  EXPECT_EQ(iiwa.robot, "iiwa14");
  EXPECT_TRUE(std::filesystem::is_regular_file(iiwa.cell_model));
  // Both keep Calibrate's arm out of the table's part area (the scenes' "table" region with a
  // part's reach around it).
  ASSERT_TRUE(ur5.part_area && iiwa.part_area);
  EXPECT_TRUE(ur5.part_area->contains(Eigen::Vector3d(0.5, -0.3, 0.05)));
  EXPECT_FALSE(iiwa.part_area->contains(Eigen::Vector3d(0.5, -0.3, 0.2)));
  // The marker is on the gripper, so the cells with the same gripper share its calibration.
  EXPECT_EQ(ur5.calibration, iiwa.calibration);
  EXPECT_EQ(ur5.calibration.filename(), "parallel-2f_marker.json");
  std::vector<std::string> names;
  for (const auto& info : knownWorkcells()) {
    names.push_back(info.name);
  }
  // Every file of workcells/ (no list to keep by hand), the default first, then the built-in cells.
  std::vector<std::string> files;
  for (const auto& entry : std::filesystem::directory_iterator(simCellFile("ur5-sim").parent_path())) {
    if (entry.path().extension() == ".json" && entry.path().stem() != "ur5-sim") {
      files.push_back(entry.path().stem().string());
    }
  }
  std::sort(files.begin(), files.end());
  files.insert(files.begin(), "ur5-sim");
  files.insert(files.end(), {"test", "none"});
  EXPECT_GE(files.size(), 6U);  // ur5-sim, iiwa-sim, iiwa-3f-sim, panda-sim at least
  EXPECT_EQ(names, files);
}

class BadCellFile : public ::testing::Test {
 protected:
  void SetUp() override {
    folder_ = std::filesystem::temp_directory_path() /
              ("costar_cell_test_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "_" +
               ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::create_directories(folder_);
    std::ifstream in(simCellFile("iiwa-sim"));
    good_ = json::parse(in);
  }
  void TearDown() override { std::filesystem::remove_all(folder_); }

  /// The error loading `content` as iiwa-sim.json, without "workcell description 'PATH': ".
  std::string problem(const std::string& content) {
    const auto file = folder_ / "iiwa-sim.json";
    std::ofstream(file) << content;
    const std::string prefix = "workcell description '" + file.string() + "': ";
    try {
      loadSimCellDescription(file);
    } catch (const std::runtime_error& e) {
      const std::string message = e.what();
      return message.rfind(prefix, 0) == 0 ? message.substr(prefix.size()) : "(no file named) " + message;
    }
    return "no error";
  }
  std::string problem(const json& content) { return problem(content.dump(2)); }

  std::filesystem::path folder_;
  json good_;
};

TEST_F(BadCellFile, EachProblemNamesItsField) {
  EXPECT_EQ(problem(good_), "no error");
  json j = good_;
  j.erase("robot");
  EXPECT_EQ(problem(j), "robot: missing");
  j = good_;
  j["gripper"] = 3;
  EXPECT_EQ(problem(j), "gripper: must be a non-empty string, not 3");
  j = good_;
  j["robot_base"]["rpy"] = {0, 0};
  EXPECT_EQ(problem(j), "robot_base.rpy: must be 3 finite numbers [x, y, z], not [0,0]");
  j = good_;
  j["table"]["size"] = {1, -1, 1};
  EXPECT_EQ(problem(j), "table.size: must be positive (m), not [1,-1,1]");
  j = good_;
  j["workspace"]["min"] = {2, 0, 0};
  EXPECT_EQ(problem(j), "workspace: min must be below max on every axis");
  j = good_;
  j["part_area"]["max"] = {0.8, 0.5, -0.1};
  EXPECT_EQ(problem(j), "part_area: min must be below max on every axis");
  j = good_;
  j["part_area"] = {{"min", {0, 0, 0}}, {"max", {1, 1, 1}}, {"height", 1}};
  EXPECT_EQ(problem(j).rfind("part_area.height: unknown field (known: ", 0), 0u) << problem(j);
  j = good_;
  j.erase("part_area");
  EXPECT_EQ(problem(j), "no error");  // optional: nothing kept out while calibrating
  j = good_;
  j["scene"] = "sim/scenes/no_such_scene.json";
  EXPECT_EQ(problem(j).rfind("scene: no such file '", 0), 0u) << problem(j);
  j = good_;
  j["waypoints"] = "examples/ur5/blind_waypoints.json";
  EXPECT_EQ(problem(j), "no error");
  j = good_;
  j["camera"] = "rgbd";
  EXPECT_EQ(problem(j).rfind("camera: unknown field (known: ", 0), 0u) << problem(j);
  j = good_;
  j["name"] = "other";
  EXPECT_EQ(problem(j), "name: 'other' must be the file's name without .json ('iiwa-sim')");
  EXPECT_EQ(problem(std::string("{\"name\": ")).rfind("not valid JSON: ", 0), 0u);
}

TEST(SimCellDescription, AMissingFileIsNamed) {
  try {
    loadSimCellDescription("/nonexistent/cell.json");
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "cannot read workcell description '/nonexistent/cell.json': No such file or directory");
  }
}

// A hostile tester's `costar perception detect -w none` answered "cannot read workcell
// description '.../workcells/none.json'".
TEST(SimCellDescription, ANameThatIsNotASimulatedCellListsThoseThatAre) {
  try {
    simCellFile("none");
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()).rfind("'none' is not a simulated workcell (those are: ", 0), 0u) << e.what();
    EXPECT_NE(std::string(e.what()).find("ur5-sim"), std::string::npos) << e.what();
  }
}

// Issue 27: numbers of 1e308 were accepted (a robot standing 1e308 m away); a key given twice
// was taken silently.
TEST_F(BadCellFile, NumbersBeyondACellsSizeAndKeysGivenTwiceAreRefused) {
  json j = good_;
  j["robot_base"]["position"] = {1e308, 0, 0};
  EXPECT_EQ(problem(j), "robot_base.position: must be 3 numbers from -10 to 10 m, not [1e+308,0,0]");
  j = good_;
  j["table"]["size"] = {1.2, 1e308, 0.1};
  EXPECT_EQ(problem(j).rfind("table.size: must be 3 numbers from -10 to 10 m, not ", 0), 0u) << problem(j);
  j = good_;
  j["workspace"]["max"] = {0.5, 0.5, 11};
  EXPECT_EQ(problem(j).rfind("workspace.max: must be 3 numbers from -10 to 10 m", 0), 0u) << problem(j);
  j = good_;
  j["robot_base"]["rpy"] = {0, 0, 1e300};
  EXPECT_EQ(problem(j).rfind("robot_base.rpy: must be 3 numbers from -7 to 7 rad", 0), 0u) << problem(j);
  std::string twice = good_.dump();
  twice.insert(1, R"("label": "one", )");
  EXPECT_EQ(problem(twice), "(top level): key 'label' appears twice (a key may appear once in an object)");
}

}  // namespace
}  // namespace costar::workcell
