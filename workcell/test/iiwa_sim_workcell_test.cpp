// The simulated LBR iiwa 14 cell (workcells/iiwa-sim.json), the second robot of the one generic
// simulated workcell: the composed MuJoCo model and the composed URDF agree, random motions stay
// within the iiwa's limits and off the table, and one of the paper's UR5 plans, unchanged, lifts
// a node (judged from the simulator's true state). One short plan: trial batches are measured
// with `costar trials` (docs/BENCHMARKS.md), not here.

#include <gtest/gtest.h>

#include <random>

#include "arm/robot_description.h"
#include "bt/builder.h"
#include "bt/executor.h"
#include "bt/plan_xml.h"
#include "core/paths.h"
#include "planning/robot_model.h"
#include "sim/simulation.h"
#include "workcell/sim_cell_description.h"
#include "workcell/workcell.h"

namespace costar::workcell {
namespace {

TEST(IiwaSimWorkcell, TheComposedMujocoModelAndUrdfAgree) {
  const SimCellDescription cell = loadSimCellDescription(simCellFile("iiwa-sim"));
  const arm::RobotDescription iiwa = arm::loadRobotDescription(arm::robotDescriptionFile(cell.robot));
  const auto robot = planning::RobotModel::fromUrdf(iiwa.urdf, dataRoot() / "sim/models/gripper_parallel-2f.urdf",
                                                    iiwa.urdf_tool_link, iiwa.urdf_base_link, "tcp");
  ASSERT_EQ(robot.dof(), 7u);
  std::mt19937 random(12);
  const sim::Scene empty = sim::parseScene(R"({"parts": []})", "empty");
  for (int trial = 0; trial < 8; ++trial) {
    sim::ArmJoints q = sim::ArmJoints::zero(7);
    for (int j = 0; j < 7; ++j) {
      q[j] = std::uniform_real_distribution<double>(iiwa.limits.min_position[j], iiwa.limits.max_position[j])(random);
    }
    sim::SimulationOptions options;
    options.robot = iiwa;
    options.robot_base = cell.robot_base;
    options.initial_arm = q;
    options.settle_seconds = 0.0;
    const auto simulation = sim::Simulation::create(empty, options);
    EXPECT_EQ(simulation->armJointNames(), iiwa.joint_names);
    const world::Pose urdf = cell.robot_base * robot.forward(q.eigen());
    const world::Pose mujoco = simulation->tcpPose();
    EXPECT_LT((urdf.translation() - mujoco.translation()).norm(), 1e-4) << "trial " << trial;
    EXPECT_LT(world::rotationAngle(urdf, mujoco), 1e-5);
  }
}

TEST(IiwaSimWorkcell, RandomMotionsStayWithinTheLimitsAndNeverTouchTheTable) {
  const auto cell =
      makeWorkcell({.name = "iiwa-sim", .scene = dataRoot() / "sim/scenes/one_node.json", .memory_only = true});
  EXPECT_EQ(cell->name(), "iiwa-sim");
  const arm::RobotDescription iiwa = arm::loadRobotDescription(arm::robotDescriptionFile("iiwa14"));
  sim::Simulation& simulation = *cell->simulation();
  std::mt19937 random(22);
  std::uniform_real_distribution<double> x(0.1, 0.8);
  std::uniform_real_distribution<double> y(-0.6, 0.6);
  std::uniform_real_distribution<double> z(-0.1, 0.6);  // some goals are inside the table
  std::uniform_real_distribution<double> angle(-M_PI, M_PI);
  int refused = 0;
  int moved = 0;
  double worst_speed_ratio = 0.0;
  for (int trial = 0; trial < 24; ++trial) {
    const world::Pose goal =
        world::poseFromXyzRpy(x(random), y(random), z(random), angle(random), angle(random) / 2, angle(random));
    const std::string body = R"(<MoveToPose pose=")" + world::formatPose(goal) + R"(" speed="1.0"/>)";
    const auto plan = bt::loadPlanText(
        R"(<root BTCPP_format="4"><BehaviorTree ID="m">)" + body + "</BehaviorTree></root>", "random.xml");
    bt::Tree tree = bt::buildTree(plan, cell->nodes(), cell->clock());
    bt::Executor executor(tree, cell->clock());
    executor.setBeforeTick([&] {
      cell->beforeTick();
      const sim::ArmJoints v = simulation.armVelocities();
      const sim::ArmJoints q = simulation.armPositions();
      for (int j = 0; j < 7; ++j) {
        worst_speed_ratio = std::max(worst_speed_ratio, std::abs(v[j]) / iiwa.limits.max_velocity[j]);
        EXPECT_GE(q[j], iiwa.limits.min_position[j] - 1e-3);
        EXPECT_LE(q[j], iiwa.limits.max_position[j] + 1e-3);
      }
    });
    const bt::RunResult result = executor.run();
    if (result.status == bt::Status::kSuccess) {
      ++moved;
      EXPECT_LT((simulation.tcpPose().translation() - goal.translation()).norm(), 0.002);
    } else {
      ++refused;
      EXPECT_FALSE(result.failure_reason.empty());
    }
  }
  EXPECT_GT(moved, 4);
  EXPECT_GT(refused, 4);
  EXPECT_LE(worst_speed_ratio, 1.02);  // joint speed limits (a little tracking overshoot allowed)
  EXPECT_EQ(simulation.armTableContactSteps(), 0u);
}

// The paper's first task, the UR5's plan file unchanged: pick up any feasible node and lift it.
TEST(IiwaSimWorkcell, ThePapersPickUpPlanLiftsANode) {
  const auto cell = makeWorkcell({.name = "iiwa-sim", .seed = 3, .memory_only = true});
  bt::Tree tree =
      bt::buildTree(bt::loadPlan(dataRoot() / "examples/ur5/pick_up_node.xml"), cell->nodes(), cell->clock());
  bt::Executor executor(tree, cell->clock(), {.time_limit = std::chrono::seconds(120)});
  executor.setBeforeTick([&cell] { cell->beforeTick(); });
  const bt::RunResult result = executor.run();
  ASSERT_EQ(result.status, bt::Status::kSuccess) << result.failure_path << ": " << result.failure_reason;
  double highest = 0.0;
  for (const sim::PartState& part : cell->simulation()->parts()) {
    if (part.object_class == "node") {
      highest = std::max(highest, part.pose.translation().z());
    }
  }
  EXPECT_GT(highest, 0.12);  // lifted 0.15 m from the table, held by friction
  EXPECT_EQ(cell->simulation()->armTableContactSteps(), 0u);
}

}  // namespace
}  // namespace costar::workcell
