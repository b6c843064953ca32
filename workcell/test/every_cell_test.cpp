// Every simulated cell of workcells/*.json, found by listing the folder (issue 35): a new cell is
// checked by these tests without a line of test code. Its files load and what it ships exists,
// and the simulator's composed model (arm, gripper on its flange, where the workcell stands it)
// and the planner's composed URDF put the tool centre point at the same place. The paper's plans
// run on every cell in trials/test/trials_test.cpp (PaperTask).

#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "arm/robot_description.h"
#include "core/paths.h"
#include "planning/robot_model.h"
#include "sim/simulation.h"
#include "workcell/grippers.h"
#include "workcell/sim_cell_description.h"

namespace costar::workcell {
namespace {

std::vector<std::string> simulatedCells() {
  std::vector<std::string> names;
  for (const auto& [name, label] : simCells()) {
    names.push_back(name);
  }
  return names;
}

class EveryCell : public ::testing::TestWithParam<std::string> {};

TEST_P(EveryCell, ItsFilesLoadAndWhatItShipsExists) {
  const SimCellDescription cell = loadSimCellDescription(simCellFile(GetParam()));
  const arm::RobotDescription robot = arm::loadRobotDescription(arm::robotDescriptionFile(cell.robot));
  EXPECT_TRUE(std::filesystem::is_regular_file(robot.mjcf)) << robot.mjcf;
  EXPECT_TRUE(std::filesystem::is_regular_file(robot.urdf)) << robot.urdf;
  const GripperModel& gripper = gripperModel(cell.gripper);
  EXPECT_TRUE(std::filesystem::is_regular_file(dataRoot() / gripper.mjcf)) << gripper.mjcf;
  EXPECT_TRUE(std::filesystem::is_regular_file(dataRoot() / gripper.urdf)) << gripper.urdf;
  // Each cell has its own SVM (its own arm and gripper seen as background) and the marker
  // calibration of its gripper, shipped.
  EXPECT_EQ(cell.perception_model, dataRoot() / "data/perception/svm" / (GetParam() + ".json"));
  EXPECT_TRUE(std::filesystem::is_regular_file(cell.perception_model)) << cell.perception_model;
  EXPECT_TRUE(std::filesystem::is_regular_file(cell.calibration)) << cell.calibration;
  EXPECT_TRUE(std::filesystem::is_regular_file(cell.scene)) << cell.scene;
}

TEST_P(EveryCell, TheComposedMujocoModelAndUrdfAgree) {
  const SimCellDescription cell = loadSimCellDescription(simCellFile(GetParam()));
  const arm::RobotDescription arm = arm::loadRobotDescription(arm::robotDescriptionFile(cell.robot));
  const GripperModel& gripper = gripperModel(cell.gripper);
  const auto robot = planning::RobotModel::fromUrdf(arm.urdf, dataRoot() / gripper.urdf, arm.urdf_tool_link,
                                                    arm.urdf_base_link, gripper.tcp_link);
  ASSERT_EQ(static_cast<int>(robot.dof()), arm.jointCount());
  std::mt19937 random(12);
  const sim::Scene empty = sim::parseScene(R"({"parts": []})", "empty");
  for (int trial = 0; trial < 8; ++trial) {
    sim::ArmJoints q = sim::ArmJoints::zero(arm.jointCount());
    for (int j = 0; j < arm.jointCount(); ++j) {
      // Within the limits, and within one turn either way (the UR5's joints turn twice round).
      const double low = std::max(arm.limits.min_position[j], -M_PI);
      const double high = std::min(arm.limits.max_position[j], M_PI);
      q[j] = std::uniform_real_distribution<double>(low, high)(random);
    }
    sim::SimulationOptions options;
    options.robot = arm;
    options.robot_base = cell.robot_base;
    options.gripper_model = dataRoot() / gripper.mjcf;
    options.adaptive_gripper = gripper.adaptive;
    options.initial_arm = q;
    options.settle_seconds = 0.0;
    const auto simulation = sim::Simulation::create(empty, options);
    EXPECT_EQ(simulation->armJointNames(), arm.joint_names);
    const world::Pose urdf = cell.robot_base * robot.forward(q.eigen());
    const world::Pose mujoco = simulation->tcpPose();
    EXPECT_LT((urdf.translation() - mujoco.translation()).norm(), 1e-4) << "trial " << trial;
    EXPECT_LT(world::rotationAngle(urdf, mujoco), 1e-5) << "trial " << trial;
  }
}

INSTANTIATE_TEST_SUITE_P(Workcells, EveryCell, ::testing::ValuesIn(simulatedCells()), [](const auto& test_info) {
  std::string name = test_info.param;
  std::replace_if(
      name.begin(), name.end(), [](char c) { return std::isalnum(static_cast<unsigned char>(c)) == 0; }, '_');
  return name;
});

}  // namespace
}  // namespace costar::workcell
