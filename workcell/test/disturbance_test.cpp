// The paper's UR5 tasks with real perception when a person interferes: a part taken away
// after DetectObjects saw it makes the next SmartGrasp fail with a reason (it does not hang,
// and the robot stops); looking again shows it is gone. Judged from the simulator's state.

#include <gtest/gtest.h>

#include <fstream>

#include "bt/builder.h"
#include "bt/executor.h"
#include "bt/plan_xml.h"
#include "sim/simulation.h"
#include "workcell/workcell.h"

namespace costar::workcell {
namespace {

constexpr const char* kOneNode = R"({"seed": 5, "parts": [{"class": "node", "color": "red", "at": [0.45, -0.2, 30]}]})";

class Disturbance : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto scene = std::filesystem::temp_directory_path() / "costar_disturbance_scene.json";
    std::ofstream(scene) << kOneNode;
    cell = makeWorkcell({.name = "ur5-sim", .scene = scene, .memory_only = true});
  }

  /// Runs `body`; once some DetectObjects has reported the node, the node is taken off the
  /// table (put down 1 m to the side, out of the robot's reach and the camera's view).
  bt::RunResult runTakingThePartAway(const std::string& body) {
    const auto plan = bt::loadPlanText(
        R"x(<root BTCPP_format="4"><BehaviorTree ID="main">)x" + body + "</BehaviorTree></root>", "test.xml");
    bt::Tree tree = bt::buildTree(plan, cell->nodes(), cell->clock());
    bt::Executor executor(tree, cell->clock(), {.time_limit = std::chrono::seconds(60)});
    executor.setBeforeTick([this] {
      cell->beforeTick();
      if (!taken_away && !cell->components().world().predicates("is_a").empty()) {
        cell->simulation()->movePart("node_0", world::Pose(Eigen::Translation3d(0.4, -1.2, 0.026)));
        taken_away = true;
      }
    });
    return executor.run();
  }

  std::unique_ptr<Workcell> cell;
  bool taken_away = false;
};

TEST_F(Disturbance, APartTakenAwayAfterItWasSeenMakesTheGraspFailWithAReason) {
  const bt::RunResult result = runTakingThePartAway(R"x(<Sequence><Open/><DetectObjects/>
      <SmartGrasp name="grasp the node" object_class="node"/></Sequence>)x");
  ASSERT_TRUE(taken_away);
  EXPECT_EQ(result.status, bt::Status::kFailure);
  EXPECT_NE(result.failure_path.find("SmartGrasp \"grasp the node\""), std::string::npos) << result.failure_path;
  EXPECT_NE(result.failure_reason.find("closed on nothing"), std::string::npos) << result.failure_reason;
  // The robot stopped: the arm is at rest, the part is where the person put it.
  cell->simulation()->stepTo(cell->simulation()->time() + std::chrono::milliseconds(300));
  double speed = 0.0;
  for (const double v : cell->simulation()->armVelocities()) {
    speed = std::max(speed, std::abs(v));
  }
  EXPECT_LT(speed, 0.01);
  EXPECT_LT(cell->simulation()->parts()[0].pose.translation().y(), -1.0);
}

TEST_F(Disturbance, LookingAgainShowsThePartIsGoneAndSmartGraspSaysSo) {
  const bt::RunResult result = runTakingThePartAway(R"x(<Sequence><Open/><DetectObjects/><DetectObjects/>
      <SmartGrasp name="grasp the node" object_class="node"/></Sequence>)x");
  ASSERT_TRUE(taken_away);
  EXPECT_EQ(result.status, bt::Status::kFailure);
  EXPECT_NE(result.failure_path.find("SmartGrasp \"grasp the node\""), std::string::npos) << result.failure_path;
  EXPECT_NE(result.failure_reason.find("no part of the class is known"), std::string::npos) << result.failure_reason;
}

}  // namespace
}  // namespace costar::workcell
