// The power tool in the simulated LBR iiwa cell with the 3-finger gripper (sim/scenes/
// polishing.json; one test on the UR5 cell with the 2-finger gripper): it sits on its stand,
// SmartGrasp picks it up by its knob with the taught grasp, ToolOn and ToolOff switch it, the
// component switches it off when it leaves the hand, and the simulator records which texels of
// the workpiece's marked area the running pad worked.

#include <algorithm>
#include <cmath>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/paths.h"
#include "sim/power_tool.h"
#include "sim/simulation.h"
#include "workcell/workcell.h"

namespace costar::workcell {
namespace {

using component::OperationResult;
using component::OperationState;
using testing::HasSubstr;

std::unique_ptr<Workcell> polishingCell() {
  return makeWorkcell({.name = "iiwa-3f-sim",
                       .scene = dataRoot() / "sim/scenes/polishing.json",
                       .seed = 21,
                       .memory_only = true,
                       .test_oracle_perception = true});
}

OperationResult run(Workcell& cell, const std::string& operation, const component::ParamMap& params = {}) {
  return runOperation(cell, operation, params, std::chrono::seconds(60));
}

bool holds(Workcell& cell, const std::string& predicate, std::vector<std::string> args = {}) {
  cell.beforeTick();
  return cell.components().world().holds(predicate, args);
}

TEST(Polishing, TheToolSitsOnItsStandAndCannotBeSwitchedOnThere) {
  const auto cell = polishingCell();
  sim::SimPowerTool& tool = *cell->simulation()->powerTool();
  ASSERT_TRUE(tool.hasTool());
  EXPECT_LT((tool.toolPose().translation() - tool.setup()->dockedPose().translation()).norm(), 0.003);
  EXPECT_TRUE(holds(*cell, "tool_docked"));
  EXPECT_TRUE(holds(*cell, "tool_in_position"));
  EXPECT_FALSE(holds(*cell, "tool_held"));
  EXPECT_TRUE(holds(*cell, "is_a", {"power_tool", "orbital_sander"}));
  const OperationResult on = run(*cell, "ToolOn");
  EXPECT_EQ(on.state, OperationState::kFailure);
  EXPECT_THAT(on.reason, HasSubstr("pick it up first"));
}

TEST(Polishing, SmartGraspPicksTheToolUpByItsKnobThenItRunsAndStops) {
  const auto cell = polishingCell();
  const OperationResult grasp = run(*cell, "SmartGrasp", {{"object_class", "orbital_sander"}, {"grasp", "knob"}});
  ASSERT_EQ(grasp.state, OperationState::kSuccess) << grasp.reason;
  EXPECT_TRUE(holds(*cell, "tool_held"));
  EXPECT_FALSE(holds(*cell, "tool_docked"));
  const Eigen::Vector3d lifted = cell->simulation()->powerTool()->toolPose().translation();
  EXPECT_GT(lifted.z(), cell->simulation()->powerTool()->setup()->dockedPose().translation().z() + 0.05);
  const OperationResult on = run(*cell, "ToolOn", {{"speed", 9000.0}});
  ASSERT_EQ(on.state, OperationState::kSuccess) << on.reason;
  EXPECT_TRUE(holds(*cell, "tool_on"));
  EXPECT_TRUE(holds(*cell, "tool_at_speed"));
  ASSERT_EQ(run(*cell, "ToolOff").state, OperationState::kSuccess);
  EXPECT_FALSE(holds(*cell, "tool_on"));
  EXPECT_TRUE(holds(*cell, "tool_held"));
}

TEST(Polishing, ATakenToolIsSwitchedOffAtTheNextTickAndComesBackToItsStand) {
  const auto cell = polishingCell();
  ASSERT_EQ(run(*cell, "SmartGrasp", {{"object_class", "orbital_sander"}, {"grasp", "knob"}}).state,
            OperationState::kSuccess);
  ASSERT_EQ(run(*cell, "ToolOn").state, OperationState::kSuccess);
  sim::SimPowerTool& tool = *cell->simulation()->powerTool();
  tool.take();
  cell->clock().sleepUntil(cell->clock().now() + std::chrono::milliseconds(20));
  EXPECT_FALSE(holds(*cell, "tool_in_position"));
  EXPECT_FALSE(tool.read().powered);
  tool.giveBack();
  cell->clock().sleepUntil(cell->clock().now() + std::chrono::milliseconds(500));
  EXPECT_TRUE(holds(*cell, "tool_docked"));
}

TEST(Polishing, TheRunningPadWorksTheTexelsUnderItAndTheToolOffWorksNone) {
  const auto cell = polishingCell();
  sim::SimPowerTool& tool = *cell->simulation()->powerTool();
  const world::Pose top = sim::workpieceTop(sim::loadScene(dataRoot() / "sim/scenes/polishing.json").workpiece.value());
  // Resting on the middle of the marked area, under its own weight (11.8 N).
  tool.placeTool(top * Eigen::Translation3d(0, 0, 0.001));
  cell->clock().sleepUntil(cell->clock().now() + std::chrono::seconds(1));
  EXPECT_EQ(tool.coverage()->fraction(0.0001), 0.0);  // off: nothing worked
  tool.command(true, 8000.0);
  cell->clock().sleepUntil(cell->clock().now() + std::chrono::seconds(2));
  const sim::Coverage& coverage = *tool.coverage();
  EXPECT_EQ(coverage.columns, 80);
  EXPECT_EQ(coverage.rows, 50);
  // The 10 cm pad (and its orbit) covers all of the 10 cm height and 10.3 of the 16 cm width.
  EXPECT_NEAR(coverage.fraction(), 10.3 / 16.0, 0.02);
  const float force = *std::max_element(coverage.max_force.begin(), coverage.max_force.end());
  EXPECT_NEAR(force, 1.2 * 9.81, 1.0);
  const auto& log = tool.log();
  ASSERT_GT(log.size(), 100u);
  EXPECT_TRUE(log.back().working);
  EXPECT_NEAR(log.back().pad.norm(), 0.0, 0.002);
  EXPECT_NEAR(log[log.size() - 1].time - log[log.size() - 2].time, 0.01, 1e-9);
}

// Held in Basic mode, the sander hung 18 degrees tilted in the fingers and pressed on its pad's
// edge, 3 cm off the path; the pinch grasp holds it straight and the pad presses flat.
TEST(Polishing, TheSanderSitsStraightInTheHandAndItsPadPressesFlatUnderThePath) {
  const auto cell = makeWorkcell({.name = "iiwa-3f-sim",
                                  .scene = dataRoot() / "sim/scenes/polishing.json",
                                  .seed = 21,
                                  .waypoints = dataRoot() / "examples/iiwa/polishing_waypoints.json",
                                  .memory_only = true,
                                  .test_oracle_perception = true});
  sim::Simulation& simulation = *cell->simulation();
  const OperationResult grasp = run(*cell, "SmartGrasp", {{"object_class", "orbital_sander"}, {"grasp", "knob"}});
  ASSERT_EQ(grasp.state, OperationState::kSuccess) << grasp.reason;
  const auto tilt = [](const Eigen::Vector3d& axis, const Eigen::Vector3d& along) {
    return std::acos(std::clamp(axis.dot(along), -1.0, 1.0)) * 180.0 / M_PI;
  };
  // Hanging in the hand: the tool points along the approach, its pad's centre 10.7 cm below the
  // tool centre point (the taught grasp).
  const world::Pose hanging = simulation.tcpPose().inverse() * simulation.powerTool()->toolPose();
  EXPECT_LT(tilt(-hanging.linear().col(2), Eigen::Vector3d::UnitZ()), 2.0);
  EXPECT_LT((hanging.translation() - Eigen::Vector3d(0, 0, 0.107)).norm(), 0.003);
  ASSERT_EQ(run(*cell, "ToolOn", {{"speed", 10000.0}}).state, OperationState::kSuccess);
  const OperationResult press =
      run(*cell, "PressAndFollow",
          {{"path", std::vector<std::string>{"row1_start", "row1_end"}}, {"force", 10.0}, {"speed", 0.03}});
  ASSERT_EQ(press.state, OperationState::kSuccess) << press.reason;
  // Pressed at the end of the pass: the pad flat on the workpiece, under the tool centre point.
  const world::Pose tcp = simulation.tcpPose();
  const world::Pose pad = simulation.powerTool()->toolPose();
  EXPECT_LT(tilt(pad.linear().col(2), Eigen::Vector3d::UnitZ()), 2.0);
  EXPECT_LT((pad.translation() - tcp.translation()).head<2>().norm(), 0.005);
}

// The UR5 cell has the same stand and sander: its 2-finger gripper takes the 36 mm knob between
// its pads, the tool centre point 11.7 cm above the pad (at the 3-finger grasp's 10.7 cm the
// gripper's body sat on the knob's top and the sander hung 11.2 cm below). SmartGrasp measured
// the width between the fingers over the whole tool, the 10 cm pad below the pads' reach
// included, and refused it: "4 candidates, none feasible (4 too wide for the fingers)".
TEST(Polishing, TheUr5TakesTheSanderByItsKnobBetweenItsTwoPadsAndPressesFlat) {
  const auto cell = makeWorkcell({.name = "ur5-sim",
                                  .scene = dataRoot() / "sim/scenes/polishing.json",
                                  .seed = 21,
                                  .waypoints = dataRoot() / "examples/ur5/polishing_waypoints.json",
                                  .memory_only = true,
                                  .test_oracle_perception = true});
  sim::Simulation& simulation = *cell->simulation();
  const OperationResult grasp = run(*cell, "SmartGrasp", {{"object_class", "orbital_sander"}, {"grasp", "knob"}});
  ASSERT_EQ(grasp.state, OperationState::kSuccess) << grasp.reason;
  EXPECT_TRUE(holds(*cell, "tool_held"));
  EXPECT_NEAR(simulation.fingers().opening, 0.036, 0.002);  // on the knob
  const auto tilt = [](const Eigen::Vector3d& axis, const Eigen::Vector3d& along) {
    return std::acos(std::clamp(axis.dot(along), -1.0, 1.0)) * 180.0 / M_PI;
  };
  const world::Pose hanging = simulation.tcpPose().inverse() * simulation.powerTool()->toolPose();
  EXPECT_LT(tilt(-hanging.linear().col(2), Eigen::Vector3d::UnitZ()), 2.0);
  EXPECT_LT((hanging.translation() - Eigen::Vector3d(0, 0, 0.117)).norm(), 0.003) << hanging.translation().transpose();
  ASSERT_EQ(run(*cell, "ToolOn", {{"speed", 10000.0}}).state, OperationState::kSuccess);
  const OperationResult press =
      run(*cell, "PressAndFollow",
          {{"path", std::vector<std::string>{"row1_start", "row1_end"}}, {"force", 10.0}, {"speed", 0.03}});
  ASSERT_EQ(press.state, OperationState::kSuccess) << press.reason;
  const world::Pose pad = simulation.powerTool()->toolPose();
  EXPECT_LT(tilt(pad.linear().col(2), Eigen::Vector3d::UnitZ()), 2.0);
  EXPECT_LT((pad.translation() - simulation.tcpPose().translation()).head<2>().norm(), 0.005);
  EXPECT_TRUE(holds(*cell, "tool_held"));
}

// MuJoCo takes the larger of two geoms' friction: the pad slid with the workpiece's 1.0, not its
// felt's 0.4, until the pad's geom took priority.
TEST(Polishing, ThePadTouchesTheWorkpieceWithItsFeltsFriction) {
  const auto cell = polishingCell();
  sim::SimPowerTool& tool = *cell->simulation()->powerTool();
  const world::Pose top = sim::workpieceTop(sim::loadScene(dataRoot() / "sim/scenes/polishing.json").workpiece.value());
  EXPECT_FALSE(tool.padFriction().has_value());
  tool.placeTool(top * Eigen::Translation3d(0, 0, 0.001));
  cell->clock().sleepUntil(cell->clock().now() + std::chrono::milliseconds(500));
  ASSERT_TRUE(tool.padFriction().has_value());
  EXPECT_NEAR(*tool.padFriction(), tool.setup()->tool.pad_friction, 1e-9);
  EXPECT_NEAR(tool.setup()->tool.pad_friction, 0.4, 1e-9);
}

}  // namespace
}  // namespace costar::workcell
