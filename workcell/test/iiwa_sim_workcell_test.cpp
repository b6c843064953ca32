// The simulated LBR iiwa 14 cell (workcells/iiwa-sim.json), the second robot of the one generic
// simulated workcell, with the 3-finger adaptive gripper on its flange (the composed MuJoCo model
// and URDF agree on every cell: every_cell_test.cpp): random motions stay within the iiwa's limits and off the
// table, the gripper picks a part up in each of its four modes, and one of the paper's UR5
// plans, unchanged, lifts a node (judged from the simulator's true state). One short plan:
// trial batches are measured with `costar trials` (docs/BENCHMARKS.md), not here.

#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <map>
#include <random>
#include <set>

#include "arm/robot_description.h"
#include "bt/builder.h"
#include "bt/executor.h"
#include "bt/plan_xml.h"
#include "core/paths.h"
#include "sim/simulation.h"
#include "smartmove/grasps.h"
#include "workcell/grippers.h"
#include "workcell/sim_cell_description.h"
#include "workcell/workcell.h"

namespace costar::workcell {
namespace {

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

// Each mode of the 3-finger gripper picks a node and a link up on the iiwa: SetMode, then
// SmartGrasp with the class's grasp for that mode (data/grasps.json), the part seen by a TEST
// ONLY oracle. Judged from the simulator's true state: the part is lifted off the table,
// touches at least two fingers (in Scissor mode fingers 1 and 2, not finger_middle) and not the
// table, and stays up for a second, held by contact and friction (the model has no weld).
class IiwaAdaptiveGripper : public ::testing::TestWithParam<std::tuple<const char*, const char*>> {};

TEST_P(IiwaAdaptiveGripper, PicksAPartUpInEachMode) {
  const std::string mode = std::get<0>(GetParam());
  const std::string part_class = std::get<1>(GetParam());
  const auto scene = std::filesystem::temp_directory_path() / ("costar_iiwa_mode_" + mode + "_" + part_class + ".json");
  std::ofstream(scene) << R"({"parts": [{"class": ")" << part_class << R"(", "color": ")"
                       << (part_class == "link" ? "wood" : "red") << R"(", "at": [0.5, -0.15, 30]}]})";
  const auto cell =
      makeWorkcell({.name = "iiwa-3f-sim", .scene = scene, .memory_only = true, .test_oracle_perception = true});
  // The gripper starts in another mode: SmartGrasp sets the one its grasp was taught in.
  const std::string other = mode == "wide" ? "basic" : "wide";
  const std::string body = R"(<Sequence><SetMode mode=")" + other + R"("/><SmartGrasp object_class=")" + part_class +
                           R"(" grasp=")" + mode + R"("/><Sleep msec="1000"/></Sequence>)";
  const auto plan =
      bt::loadPlanText(R"(<root BTCPP_format="4"><BehaviorTree ID="m">)" + body + "</BehaviorTree></root>", "mode.xml");
  bt::Tree tree = bt::buildTree(plan, cell->nodes(), cell->clock());
  bt::Executor executor(tree, cell->clock(), {.time_limit = std::chrono::seconds(90)});
  executor.setBeforeTick([&cell] { cell->beforeTick(); });
  const bt::RunResult result = executor.run();
  ASSERT_EQ(result.status, bt::Status::kSuccess)
      << mode << ": " << result.failure_path << ": " << result.failure_reason;

  sim::Simulation& simulation = *cell->simulation();
  const sim::PartState part = simulation.parts().front();
  EXPECT_GT(part.pose.translation().z(), 0.08) << mode;  // lifted ~10 cm off the table
  EXPECT_LT(part.linear_velocity.norm(), 0.01) << mode;  // and still there after a second
  std::set<std::string> touching;
  for (const auto& [a, b] : simulation.contacts()) {
    if (a == part.name || b == part.name) {
      touching.insert(a == part.name ? b : a);
    }
  }
  EXPECT_FALSE(touching.count("table")) << mode;
  const int fingers =
      static_cast<int>(touching.count("finger_middle") + touching.count("finger_1") + touching.count("finger_2"));
  EXPECT_GE(fingers, 2) << mode;
  if (mode == "scissor") {
    EXPECT_TRUE(touching.count("finger_1") && touching.count("finger_2"));
    EXPECT_FALSE(touching.count("finger_middle"));
  }
  cell->beforeTick();
  EXPECT_TRUE(cell->components().world().holds("gripper_mode", std::vector<std::string>{mode}));
  EXPECT_TRUE(cell->components().world().holds("holding", std::vector<std::string>{part.name}));
  EXPECT_EQ(simulation.armTableContactSteps(), 0u);
}

// A grasp taught on the 3-finger gripper with the mode chosen (as the editor's Teach grasp row
// offers it), not the mode the gripper is in: the grasp file keeps that mode, which SmartGrasp
// sets. A mode the gripper lacks is refused naming its modes when the plan is built.
TEST(IiwaAdaptiveGripperTeaching, AGraspTaughtWithAModeChosenKeepsThatMode) {
  const auto folder = std::filesystem::temp_directory_path() / "costar_iiwa_teach_mode";
  std::filesystem::remove_all(folder);
  std::filesystem::create_directories(folder);
  setenv("XDG_STATE_HOME", folder.c_str(), 1);  // where the taught grasps are written
  const auto scene = folder / "scene.json";
  std::ofstream(scene) << R"({"parts": [{"class": "node", "color": "red", "at": [0.5, -0.15, 30]}]})";
  const auto cell = makeWorkcell(
      {.name = "iiwa-3f-sim", .scene = scene, .waypoints = folder / "waypoints.json", .test_oracle_perception = true});
  const auto run = [&cell](const std::string& body) {
    const auto plan = bt::loadPlanText(
        R"(<root BTCPP_format="4"><BehaviorTree ID="m"><Sequence>)" + body + "</Sequence></BehaviorTree></root>",
        "teach.xml");
    bt::Tree tree = bt::buildTree(plan, cell->nodes(), cell->clock());
    bt::Executor executor(tree, cell->clock(), {.time_limit = std::chrono::seconds(90)});
    executor.setBeforeTick([&cell] { cell->beforeTick(); });
    return executor.run();
  };
  // The gripper around the node in Pinch mode.
  ASSERT_EQ(run(R"(<SmartGrasp object_class="node" grasp="pinch"/>)").status, bt::Status::kSuccess);
  try {
    run(R"(<TeachGrasp object_class="node" grasp="demo" mode="sideways"/>)");
    ADD_FAILURE() << "a mode the gripper lacks was taken";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("parameter 'mode' of TeachGrasp: 'sideways' is not one of: basic, pinch, "
                                         "wide, scissor"),
              std::string::npos)
        << e.what();
  }
  ASSERT_EQ(run(R"(<TeachGrasp object_class="node" grasp="demo" mode="wide"/>)").status, bt::Status::kSuccess);
  ASSERT_EQ(run(R"(<TeachGrasp object_class="node" grasp="as_it_is"/>)").status, bt::Status::kSuccess);
  const smartmove::GraspLibrary taught(dataRoot() / "data/grasps.json", defaultGraspFile("iiwa-3f-sim"), "robotiq3f");
  ASSERT_TRUE(taught.find("node", "demo"));
  EXPECT_EQ(taught.find("node", "demo")->mode, "wide");
  ASSERT_TRUE(taught.find("node", "as_it_is"));
  EXPECT_EQ(taught.find("node", "as_it_is")->mode, "pinch");
  unsetenv("XDG_STATE_HOME");
  std::filesystem::remove_all(folder);
}

INSTANTIATE_TEST_SUITE_P(Modes, IiwaAdaptiveGripper,
                         ::testing::Combine(::testing::Values("basic", "pinch", "wide", "scissor"),
                                            ::testing::Values("node", "link")));

// A link with a node beside it, 3.5 cm from its middle along it: the 3-finger gripper's
// centred Pinch grasp puts a finger on the node either way round, so the link is taken off its
// middle (the fingertips kept on the link), and put down centred on another node all the same
// (the grasp is remembered as it was). The parts seen by a TEST ONLY oracle.
TEST(IiwaSimWorkcell, TheThreeFingerGripperTakesALinkOffItsMiddleBesideANeighbourAndPlacesItCentred) {
  const auto scene = std::filesystem::temp_directory_path() / "costar_iiwa_3f_shifted_link.json";
  std::ofstream(scene) << R"({"parts": [{"class": "link", "color": "wood", "at": [0.50, -0.15, 0]},
                                       {"class": "node", "color": "red", "at": [0.535, -0.0925, 0]},
                                       {"class": "node", "color": "blue", "at": [0.45, 0.2, 20]}]})";
  const auto cell =
      makeWorkcell({.name = "iiwa-3f-sim", .scene = scene, .memory_only = true, .test_oracle_perception = true});
  const auto plan = bt::loadPlanText(R"x(<root BTCPP_format="4"><BehaviorTree ID="m"><Sequence>
      <SmartGrasp object_class="link" grasp="middle"/>
      <SmartRelease target_class="node" predicates="left_of(table_center)"/>
      <Home/></Sequence></BehaviorTree></root>)x",
                                     "shifted.xml");
  bt::Tree tree = bt::buildTree(plan, cell->nodes(), cell->clock());
  bt::Executor executor(tree, cell->clock(), {.time_limit = std::chrono::seconds(120)});
  executor.setBeforeTick([&cell] { cell->beforeTick(); });
  const bt::RunResult result = executor.run();
  ASSERT_EQ(result.status, bt::Status::kSuccess) << result.failure_path << ": " << result.failure_reason;
  sim::Simulation& simulation = *cell->simulation();
  simulation.stepTo(simulation.time() + std::chrono::seconds(1));
  std::map<std::string, sim::PartState> parts;
  for (const sim::PartState& part : simulation.parts()) {
    parts[part.name] = part;
  }
  const sim::PartState& link = parts.at("link_0");
  EXPECT_NEAR(link.pose.translation().z(), 0.05 + 0.0125, 0.004);  // on the blue node
  EXPECT_LT((link.pose.translation() - parts.at("node_1").pose.translation()).head<2>().norm(), 0.015);
  EXPECT_LT((parts.at("node_0").pose.translation() - Eigen::Vector3d(0.535, -0.0925, 0.025)).norm(), 0.003);
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
