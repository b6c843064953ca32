// SmartGrasp / SmartRelease / SmartMove in the simulated cell, apart from perception: a TEST
// ONLY oracle reports the true part poses as symbols. Success is judged from the simulator's
// true state.

#include <gtest/gtest.h>

#include <fstream>
#include <functional>
#include <map>

#include "bt/builder.h"
#include "bt/executor.h"
#include "bt/plan_xml.h"
#include "component/component.h"
#include "core/paths.h"
#include "sim/simulation.h"
#include "workcell/workcell.h"

namespace costar::workcell {
namespace {

class SmartMoveSim : public ::testing::Test {
 protected:
  void open(const std::string& scene_json) {
    const auto scene = std::filesystem::temp_directory_path() / "costar_smartmove_scene.json";
    std::ofstream(scene) << scene_json;
    cell = makeWorkcell({.name = "ur5-sim", .scene = scene, .memory_only = true, .test_oracle_perception = true});
  }

  /// `meddle` runs before every tick (a person moving parts under the running plan).
  bt::RunResult run(const std::string& body, const std::function<void()>& meddle = {}) {
    const auto plan = bt::loadPlanText(
        R"x(<root BTCPP_format="4"><BehaviorTree ID="main">)x" + body + "</BehaviorTree></root>", "test.xml");
    bt::Tree tree = bt::buildTree(plan, cell->nodes(), cell->clock());
    bt::Executor executor(tree, cell->clock(), {.time_limit = std::chrono::seconds(60)});
    executor.setBeforeTick([this, &meddle] {
      if (meddle) {
        meddle();
      }
      cell->beforeTick();
    });
    return executor.run();
  }

  sim::PartState part(const std::string& name) {
    for (const auto& state : cell->simulation()->parts()) {
      if (state.name == name) {
        return state;
      }
    }
    ADD_FAILURE() << "no part " << name;
    return {};
  }

  std::unique_ptr<Workcell> cell;
};

TEST_F(SmartMoveSim, GraspsTheNodeThePredicatesSelectAndLiftsIt) {
  open(R"x({"parts": [{"class": "node", "color": "red", "at": [0.45, -0.2, 25]},
                     {"class": "node", "color": "blue", "at": [0.5, 0.2, -40]}]})x");
  const bt::RunResult result =
      run(R"x(<SmartGrasp object_class="node" predicates="left_of(table_center)" grasp="top"/>)x");
  ASSERT_EQ(result.status, bt::Status::kSuccess) << result.failure_path << ": " << result.failure_reason;
  EXPECT_GT(part("node_1").pose.translation().z(), 0.1);  // the left one is up in the gripper
  EXPECT_LT(part("node_0").pose.translation().z(), 0.03);
  cell->beforeTick();
  EXPECT_TRUE(cell->components().world().holds("holding", std::vector<std::string>{"node_1"}));
  EXPECT_EQ(cell->simulation()->armTableContactSteps(), 0u);
}

// SmartMove moves the arm through the arm's FollowJointPath operation: cancelling the SmartGrasp
// cancels that operation, and the arm decelerates along its path and stops.
TEST_F(SmartMoveSim, CancellingASmartGraspStopsTheArmOnItsWay) {
  open(R"x({"parts": [{"class": "node", "color": "red", "at": [0.45, -0.2, 25]}]})x");
  component::Component* smartmove = cell->components().provider("SmartGrasp");
  ASSERT_NE(smartmove, nullptr);
  component::ParamMap params{{"object_class", "node"}, {"predicates", ""}, {"grasp", "top"}};
  for (const auto& spec : smartmove->description().operation("SmartGrasp")->params) {
    if (spec.default_value) {
      params.try_emplace(spec.name, *spec.default_value);
    }
  }
  const auto fastest = [this] {
    double speed = 0.0;
    for (const double v : cell->simulation()->armVelocities()) {
      speed = std::max(speed, std::abs(v));
    }
    return speed;
  };
  cell->beforeTick();
  const component::OperationId id = smartmove->start("SmartGrasp", params);
  // Until the arm is well on its way above the part (the gripper opens first).
  double moving = 0.0;
  for (int tick = 0; tick < 1000 && moving < 0.3; ++tick) {
    ASSERT_EQ(smartmove->poll(id).state, component::OperationState::kRunning);
    cell->clock().sleepUntil(cell->clock().now() + std::chrono::milliseconds(10));
    cell->beforeTick();
    moving = fastest();
  }
  ASSERT_GE(moving, 0.3) << "the arm never moved";
  smartmove->cancel(id);
  cell->clock().sleepUntil(cell->clock().now() + std::chrono::seconds(1));
  cell->beforeTick();
  EXPECT_LT(fastest(), 0.01);
  EXPECT_FALSE(cell->components().world().holds("arm_moving", {}));
  EXPECT_LT(part("node_0").pose.translation().z(), 0.03);  // not grasped
}

TEST_F(SmartMoveSim, StacksANodeOnAnotherAndALinkOnANode) {
  open(R"x({"parts": [{"class": "node", "color": "red", "at": [0.45, -0.25, 0]},
                     {"class": "node", "color": "blue", "at": [0.5, 0.2, 30]},
                     {"class": "link", "color": "wood", "at": [0.4, -0.1, 70]}]})x");
  // The link on the left node, then the right node on top of the link.
  const bt::RunResult result = run(R"x(<Sequence>
      <SmartGrasp object_class="link" grasp="middle"/>
      <SmartRelease target_class="node" predicates="left_of(table_center)"/>
      <SmartGrasp object_class="node" predicates="right_of(table_center)"/>
      <SmartRelease target_class="link"/>
      <Home/></Sequence>)x");
  ASSERT_EQ(result.status, bt::Status::kSuccess) << result.failure_path << ": " << result.failure_reason;
  cell->simulation()->stepTo(cell->simulation()->time() + std::chrono::seconds(1));
  const auto base = part("node_1");
  const auto link = part("link_0");
  const auto top = part("node_0");
  EXPECT_NEAR(link.pose.translation().z(), 0.05 + 0.0125, 0.004);
  EXPECT_LT((link.pose.translation() - base.pose.translation()).head<2>().norm(), 0.01);
  EXPECT_NEAR(top.pose.translation().z(), 0.075 + 0.025, 0.005);
  EXPECT_LT((top.pose.translation() - base.pose.translation()).head<2>().norm(), 0.015);
  cell->beforeTick();
  EXPECT_TRUE(cell->components().world().holds("on", std::vector<std::string>{"link_0", "node_1"}));
  EXPECT_TRUE(cell->components().world().holds("on", std::vector<std::string>{"node_0", "link_0"}));
}

TEST_F(SmartMoveSim, PutsAPartDownOnAFreeSpotOfTheTableThatSatisfiesThePredicates) {
  open(R"x({"parts": [{"class": "node", "color": "red", "at": [0.45, -0.25, 10]},
                      {"class": "node", "color": "blue", "at": [0.45, 0.12, 0]}]})x");
  const bt::RunResult result = run(R"x(<Sequence>
      <SmartGrasp object_class="node" predicates="right_of(table_center)"/>
      <SmartRelease target="table" predicates="left_of(table_center); behind(table_center)"/></Sequence>)x");
  ASSERT_EQ(result.status, bt::Status::kSuccess) << result.failure_path << ": " << result.failure_reason;
  cell->simulation()->stepTo(cell->simulation()->time() + std::chrono::seconds(1));
  const auto moved = part("node_0");
  EXPECT_GT(moved.pose.translation().y(), 0.02);            // left of table_center
  EXPECT_LT(moved.pose.translation().x(), 0.48);            // behind it (nearer the robot)
  EXPECT_NEAR(moved.pose.translation().z(), 0.025, 0.003);  // resting on the table
  EXPECT_GT((moved.pose.translation() - part("node_1").pose.translation()).head<2>().norm(), 0.07);  // clear
  EXPECT_EQ(run(R"x(<Sequence><SmartGrasp object_class="node" predicates="left_of(table_center)"/>
      <SmartRelease target="table" predicates="on(table_center)"/></Sequence>)x")
                .failure_reason,
            "only left_of, right_of, in_front_of, behind, near(?, frame) can choose a spot on the table: on");
}

// Issue 12: a node boxed in by four links 30 mm from its faces (a pinwheel). A box over the
// fingers' whole travel (60 mm either side of the centre line, plus padding) reaches every link
// from every side, so all grasps were refused as "collision at the goal"; fingers opened only
// as far as the node needs (its 50 mm + margin) fit between it and the links.
TEST_F(SmartMoveSim, GraspsANodeBoxedInByLinksWithTheFingersOpenedOnlyAsFarAsItNeeds) {
  open(R"x({"parts": [{"class": "node", "color": "red", "at": [0.45, -0.2, 0]},
                     {"class": "link", "at": [0.42, -0.1325, 0]},
                     {"class": "link", "at": [0.5175, -0.17, 90]},
                     {"class": "link", "at": [0.48, -0.2675, 0]},
                     {"class": "link", "at": [0.3825, -0.23, 90]}]})x");
  std::map<std::string, Eigen::Vector3d> before;
  for (const auto& state : cell->simulation()->parts()) {
    before[state.name] = state.pose.translation();
  }
  const bt::RunResult result = run(R"x(<SmartGrasp object_class="node"/>)x");
  ASSERT_EQ(result.status, bt::Status::kSuccess) << result.failure_path << ": " << result.failure_reason;
  EXPECT_GT(part("node_0").pose.translation().z(), 0.1);  // up in the gripper
  for (const char* link : {"link_0", "link_1", "link_2", "link_3"}) {
    EXPECT_LT((part(link).pose.translation() - before[link]).norm(), 0.003) << link << " was pushed";
  }
  const sim::FingerState fingers = cell->simulation()->fingers();
  EXPECT_NEAR(fingers.opening, 0.05, 0.004);  // squeezing the node
  EXPECT_EQ(cell->simulation()->armTableContactSteps(), 0u);
}

// Issue 12: a node slid 15 mm along the pads as the gripper goes down to it is gripped where it
// now lies, off the pads' centre; put down by where it was seen it lands 15 mm beside the node it
// goes on. SmartGrasp centre="true" squares it up a quarter turn round, which centres it along
// the pads too, so it lands centred.
TEST_F(SmartMoveSim, ANodeSlidAlongThePadsBeforeTheCloseIsSquaredUpAndPlacedCentred) {
  const auto stack = [this](const char* grasp, double along) {
    open(R"x({"parts": [{"class": "node", "color": "red", "at": [0.45, -0.2, 20]},
                       {"class": "node", "color": "blue", "at": [0.5, 0.2, 0]}]})x");
    bool slid = false;
    const auto slide = [this, &slid, along] {
      sim::Simulation& simulation = *cell->simulation();
      const world::Pose tcp = simulation.tcpPose();
      const sim::PartState node = part("node_0");
      const Eigen::Vector3d offset = tcp.translation() - node.pose.translation();
      if (!slid && along > 0.0 && simulation.fingers().opening > 0.04 && offset.head<2>().norm() < 0.005 &&
          offset.z() < 0.07) {
        world::Pose moved = node.pose;
        moved.translation() += along * tcp.linear().col(0);  // along the pads
        simulation.movePart("node_0", moved);
        slid = true;
      }
    };
    const bt::RunResult result =
        run(std::string("<Sequence>") + grasp + R"x(<SmartRelease target_class="node"/></Sequence>)x", slide);
    EXPECT_EQ(slid, along > 0.0);
    EXPECT_EQ(result.status, bt::Status::kSuccess) << result.failure_path << ": " << result.failure_reason;
    cell->simulation()->stepTo(cell->simulation()->time() + std::chrono::seconds(1));
    return (part("node_0").pose.translation() - part("node_1").pose.translation()).head<2>().norm();
  };
  const char* plain = R"x(<SmartGrasp object_class="node" predicates="right_of(table_center)"/>)x";
  const char* centred = R"x(<SmartGrasp object_class="node" predicates="right_of(table_center)" centre="true"/>)x";
  const double undisturbed = stack(plain, 0.0);
  const double slid = stack(plain, 0.015);
  const double squared = stack(centred, 0.015);
  EXPECT_LT(undisturbed, 0.003);
  EXPECT_GT(slid, 0.01);                                             // put down by where it was seen
  EXPECT_LT(squared, 0.003);                                         // as if it had not moved
  EXPECT_NEAR(part("node_0").pose.translation().z(), 0.075, 0.004);  // resting on node_1
}

// Issue 12: a link with a node 10 mm from either side of its middle. The centred grasp has no
// room for the pads; the link is taken 40 mm off its middle, and put down centred on a node all
// the same (the grasp is remembered as it was).
TEST_F(SmartMoveSim, TakesALinkOffItsMiddleWhenNeighboursLeaveNoRoomThereAndPlacesItCentred) {
  open(R"x({"parts": [{"class": "link", "at": [0.45, -0.2, 0]},
                     {"class": "node", "color": "red", "at": [0.44, -0.1525, 0]},
                     {"class": "node", "color": "blue", "at": [0.44, -0.2475, 0]},
                     {"class": "node", "color": "green", "at": [0.45, 0.2, 20]}]})x");
  const bt::RunResult result = run(R"x(<Sequence>
      <SmartGrasp object_class="link" grasp="middle"/>
      <SmartRelease target_class="node" predicates="left_of(table_center)"/>
      <Home/></Sequence>)x");
  ASSERT_EQ(result.status, bt::Status::kSuccess) << result.failure_path << ": " << result.failure_reason;
  cell->simulation()->stepTo(cell->simulation()->time() + std::chrono::seconds(1));
  const auto link = part("link_0");
  const auto base = part("node_2");
  EXPECT_NEAR(link.pose.translation().z(), 0.05 + 0.0125, 0.004);
  EXPECT_LT((link.pose.translation() - base.pose.translation()).head<2>().norm(), 0.015);
  EXPECT_LT((part("node_0").pose.translation() - Eigen::Vector3d(0.44, -0.1525, 0.025)).norm(), 0.003);
  EXPECT_LT((part("node_1").pose.translation() - Eigen::Vector3d(0.44, -0.2475, 0.025)).norm(), 0.003);
}

// Issue 12: two links lying side by side 15 mm apart leave no room for a pad between them:
// no grasp is feasible. SmartPush slides one along its neighbour with the closed fingers until
// its middle is clear; then it is taken by the middle.
TEST_F(SmartMoveSim, PushesALinkClearOfItsNeighbourWhenNoGraspIsFeasibleThenGraspsIt) {
  open(R"x({"parts": [{"class": "link", "at": [0.50, -0.20, 0]},
                     {"class": "link", "at": [0.50, -0.24, 0]}]})x");
  const bt::RunResult blocked = run(R"x(<SmartGrasp object_class="link" grasp="middle"/>)x");
  ASSERT_EQ(blocked.status, bt::Status::kFailure);
  EXPECT_NE(blocked.failure_reason.find("no feasible link"), std::string::npos) << blocked.failure_reason;
  std::map<std::string, Eigen::Vector3d> before;
  for (const auto& state : cell->simulation()->parts()) {
    before[state.name] = state.pose.translation();
  }
  const bt::RunResult pushed = run(R"x(<SmartPush object_class="link" distance="0.1"/>)x");
  ASSERT_EQ(pushed.status, bt::Status::kSuccess) << pushed.failure_path << ": " << pushed.failure_reason;
  cell->simulation()->stepTo(cell->simulation()->time() + std::chrono::milliseconds(500));
  // One link slid along (at least 5 cm), still lying flat; the other barely moved.
  const double moved_0 = (part("link_0").pose.translation() - before["link_0"]).head<2>().norm();
  const double moved_1 = (part("link_1").pose.translation() - before["link_1"]).head<2>().norm();
  EXPECT_GT(std::max(moved_0, moved_1), 0.05) << moved_0 << " " << moved_1;
  EXPECT_LT(std::min(moved_0, moved_1), 0.005) << moved_0 << " " << moved_1;
  for (const char* link : {"link_0", "link_1"}) {
    EXPECT_NEAR(part(link).pose.translation().z(), 0.0125, 0.003) << link;
  }
  const bt::RunResult grasped =
      run(R"x(<Sequence><Home/><Open/><SmartGrasp object_class="link" grasp="middle"/></Sequence>)x");
  ASSERT_EQ(grasped.status, bt::Status::kSuccess) << grasped.failure_path << ": " << grasped.failure_reason;
  EXPECT_GT(std::max(part("link_0").pose.translation().z(), part("link_1").pose.translation().z()), 0.08);
}

TEST_F(SmartMoveSim, NoMatchingPartFailsWithTheReasonsOfEveryCandidate) {
  open(R"x({"parts": [{"class": "node", "color": "red", "at": [0.45, -0.2, 0]},
                     {"class": "node", "color": "blue", "at": [0.95, 0.45, 0]}]})x");
  const bt::RunResult none =
      run(R"x(<SmartGrasp object_class="node" predicates="left_of(table_center); behind(table_center)"/>)x");
  ASSERT_EQ(none.status, bt::Status::kFailure);
  EXPECT_NE(none.failure_reason.find("no feasible node"), std::string::npos) << none.failure_reason;
  EXPECT_NE(none.failure_reason.find("predicate false: "), std::string::npos) << none.failure_reason;
  EXPECT_NE(none.failure_reason.find(",table_center) is false"), std::string::npos) << none.failure_reason;
  const bt::RunResult far = run(R"x(<SmartMove object_class="node" predicates="left_of(table_center)"/>)x");
  ASSERT_EQ(far.status, bt::Status::kFailure);  // the blue node is out of the arm's reach
  EXPECT_NE(far.failure_reason.find("no IK solution"), std::string::npos) << far.failure_reason;
  EXPECT_EQ(run(R"x(<SmartRelease target_class="node"/>)x").failure_reason,
            "nothing to release: no part was grasped with SmartGrasp");
}

TEST_F(SmartMoveSim, APlanNamingAnUnknownClassOrBadPredicatesFailsValidation) {
  open(R"x({"parts": []})x");
  const auto problems = [this](const std::string& body) {
    return bt::validatePlan(
        bt::loadPlanText(R"x(<root BTCPP_format="4"><BehaviorTree ID="m">)x" + body + "</BehaviorTree></root>",
                         "v.xml"),
        cell->nodes());
  };
  auto found = problems(R"x(<SmartGrasp object_class="gear"/>)x");
  ASSERT_EQ(found.size(), 1u);
  EXPECT_NE(found[0].message.find("'gear' is not one of: link, node"), std::string::npos) << found[0].message;
  found = problems(R"x(<SmartGrasp object_class="node" predicates="left_of(table_center"/>)x");
  ASSERT_EQ(found.size(), 1u);
  EXPECT_NE(found[0].message.find("must look like name(arg"), std::string::npos) << found[0].message;
  found = problems(R"x(<SmartGrasp object_class="node" predicates="leftof(table_center)"/>)x");
  ASSERT_EQ(found.size(), 1u);
  EXPECT_NE(found[0].message.find("unknown predicate 'leftof'"), std::string::npos) << found[0].message;
  found = problems(R"x(<SmartGrasp object_class="node" predicates="left_of(table_centre)"/>)x");
  ASSERT_EQ(found.size(), 1u);
  EXPECT_NE(found[0].message.find("unknown reference frame 'table_centre'"), std::string::npos) << found[0].message;
  found = problems(R"x(<SmartGrasp object_class="node" predicates="near"/>)x");
  ASSERT_EQ(found.size(), 1u);
  EXPECT_NE(found[0].message.find("takes 2 argument(s), 1 given"), std::string::npos) << found[0].message;
  EXPECT_TRUE(
      problems(R"x(<SmartGrasp object_class="node" predicates="right_of(table_center); is_a(node)"/>)x").empty());
}

}  // namespace
}  // namespace costar::workcell
