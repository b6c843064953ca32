// The power tool in the simulated LBR iiwa cell with the 3-finger gripper (sim/scenes/
// polishing.json): it sits on its stand, SmartGrasp picks it up by its knob with the taught
// grasp, ToolOn and ToolOff switch it, the component switches it off when it leaves the hand,
// and the simulator records which texels of the workpiece's marked area the running pad worked.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/paths.h"
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

}  // namespace
}  // namespace costar::workcell
