// Free-drive on both simulated arms (docs/TEACHING.md): the person's hand is a wrench on the tool
// (Simulation::setHandWrench), judged from the simulator's true state.
#include "trials/free_drive_trial.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <optional>

#include <Eigen/Geometry>

#include "arm/arm_component.h"
#include "bt/builder.h"
#include "bt/executor.h"
#include "bt/plan_xml.h"
#include "sim/simulation.h"
#include "workcell/workcell.h"

namespace costar::trials {
namespace {

class FreeDrive : public ::testing::TestWithParam<std::string> {
 protected:
  void SetUp() override {
    workcell::WorkcellOptions options;
    options.name = GetParam();
    options.memory_only = true;
    options.seed = 11;
    cell_ = workcell::makeWorkcell(options);
    simulation_ = cell_->simulation();
    arm_ = dynamic_cast<arm::ArmComponent*>(cell_->components().provider("FreeDrive"));
    ASSERT_NE(arm_, nullptr);
  }

  /// Runs `node`, calling `tick` (with the seconds since the start) before every tick.
  bt::RunResult run(const std::string& node, const std::function<void(double)>& tick) {
    const bt::Plan plan =
        bt::loadPlanText(R"(<root BTCPP_format="4"><BehaviorTree ID="t">)" + node + "</BehaviorTree></root>", "t",
                         {.follow_includes = false});
    bt::Tree tree = bt::buildTree(plan, cell_->nodes(), cell_->clock());
    bt::Executor executor(tree, cell_->clock());
    const TimePoint start = cell_->clock().now();
    executor.setBeforeTick([&] {
      cell_->beforeTick();
      if (tick) {
        tick(toSeconds(cell_->clock().now() - start));
      }
    });
    return executor.run();
  }

  /// Holds the dead-man and pushes with `hand` for `seconds`, then lets go of both.
  bt::RunResult push(const std::string& mode, const arm::Wrench& hand, double seconds, const std::string& locked = "") {
    return run("<FreeDrive mode=\"" + mode + "\" locked=\"" + locked + "\" hold=\"0.2\"/>", [&](double t) {
      if (t < seconds) {
        simulation_->setHandWrench(hand);
        arm_->holdFreeDrive(std::chrono::milliseconds(100));
      } else {
        simulation_->setHandWrench({});
      }
    });
  }

  std::unique_ptr<workcell::Workcell> cell_;
  sim::Simulation* simulation_ = nullptr;
  arm::ArmComponent* arm_ = nullptr;
};

TEST_P(FreeDrive, APushMovesTheToolAlongItAndLettingGoStopsAndHoldsIt) {
  const world::Pose before = simulation_->tcpPose();
  arm::Wrench hand;
  hand.force = Eigen::Vector3d(0.0, 20.0, 0.0);
  const bt::RunResult result = push("translation", hand, 1.0);
  ASSERT_EQ(result.status, bt::Status::kSuccess) << result.failure_reason;
  const world::Pose let_go = simulation_->tcpPose();
  const Eigen::Vector3d moved = let_go.translation() - before.translation();
  EXPECT_GT(moved.y(), 0.05);  // 17 N beyond the dead band: 0.15 m/s (the most) for about a second
  EXPECT_LT(std::abs(moved.x()), 0.2 * moved.y());
  EXPECT_LT(std::abs(moved.z()), 0.2 * moved.y());
  EXPECT_LT(world::rotationAngle(before, let_go), 1.0 * M_PI / 180.0);  // translation only
  // Let go: it stays where it is.
  run("<Sleep msec=\"500\"/>", {});
  EXPECT_LT((simulation_->tcpPose().translation() - let_go.translation()).norm(), 0.01);
  EXPECT_LT(arm::maxAbs(simulation_->armVelocities()), 0.02);
  EXPECT_FALSE(arm_->freeDriveStatus().active);
}

TEST_P(FreeDrive, APushHarderThanAHandTripsTheProtectiveStopNamingTheLimitAndTheArmComesToRest) {
  // The compliant arm yields to a push instead of pushing back, so the wrist's 150 N stop never
  // fired: 200 N moved the UR5's tool 0.8 m at 3.9 m/s, 140 N 0.13 m at 0.6 m/s, and free-drive
  // went on. Now the tool's measured speed and its distance from the reference stop it too.
  double fastest = 0.0;
  world::Pose last = simulation_->tcpPose();
  double last_t = 0.0;
  const auto watch = [&](double t) {
    const world::Pose now = simulation_->tcpPose();
    if (t > last_t) {
      fastest = std::max(fastest, (now.translation() - last.translation()).norm() / (t - last_t));
    }
    last = now;
    last_t = t;
  };
  // Pushes with `force` along y until the operation ends and `after` s more (a person's reaction),
  // then lets go; the tool's fastest speed (10 ms differences of the true pose) in `fastest`.
  const auto shove = [&](double force, double seconds, double after) {
    fastest = 0.0;
    last = simulation_->tcpPose();
    last_t = 0.0;
    arm::Wrench hand;
    hand.force = Eigen::Vector3d(0.0, force, 0.0);
    const bt::RunResult result = run("<FreeDrive hold=\"0.2\"/>", [&](double t) {
      watch(t);
      if (t < seconds) {
        simulation_->setHandWrench(hand);
        arm_->holdFreeDrive(std::chrono::milliseconds(100));
      } else {
        simulation_->setHandWrench({});
      }
    });
    if (after > 0.0) {
      run("<Sleep msec=\"" + std::to_string(static_cast<int>(after * 1000.0)) + "\"/>",
          [&](double t) { simulation_->setHandWrench(t < after ? hand : arm::Wrench{}); });
    }
    simulation_->setHandWrench({});
    return result;
  };
  // The largest push a hand may make (60 N) guides it, within the teaching speed.
  const world::Pose start = simulation_->tcpPose();
  const bt::RunResult firm = shove(60.0, 0.8, 0.0);
  ASSERT_EQ(firm.status, bt::Status::kSuccess) << firm.failure_reason;
  EXPECT_GT((simulation_->tcpPose().translation() - start.translation()).norm(), 0.04);
  EXPECT_LE(fastest, 0.25);
  run("<Sleep msec=\"300\"/>", {});
  // 140 N, below the wrist's limit: stopped by the tool's speed or its distance from the reference.
  const world::Pose before = simulation_->tcpPose();
  const bt::RunResult hard = shove(140.0, 5.0, 0.2);
  ASSERT_EQ(hard.status, bt::Status::kFailure);
  EXPECT_TRUE(hard.failure_reason.starts_with("FreeDrive: protective stop: the tool ")) << hard.failure_reason;
  EXPECT_TRUE(hard.failure_reason.ends_with("; the arm was stopped and holds")) << hard.failure_reason;
  EXPECT_LT(toSeconds(hard.elapsed), 1.0);  // of the 5 s push
  // Let go, it is at rest and stays there.
  run("<Sleep msec=\"500\"/>", {});
  const world::Pose stopped = simulation_->tcpPose();
  EXPECT_LT(arm::maxAbs(simulation_->armVelocities()), 0.02);
  EXPECT_LT((stopped.translation() - before.translation()).norm(), 0.15);
  run("<Sleep msec=\"500\"/>", {});
  EXPECT_LT((simulation_->tcpPose().translation() - stopped.translation()).norm(), 0.002);
  EXPECT_FALSE(arm_->freeDriveStatus().active);
  // 200 N: the wrist's own limit, read before the next reference clears it.
  const bt::RunResult harder = shove(200.0, 5.0, 0.0);
  ASSERT_EQ(harder.status, bt::Status::kFailure);
  EXPECT_TRUE(harder.failure_reason.starts_with("FreeDrive: protective stop: ")) << harder.failure_reason;
  EXPECT_LT(toSeconds(harder.elapsed), 0.1);
}

TEST_P(FreeDrive, RotationModeTurnsTheToolAboutItsCentrePointAndKeepsItThere) {
  const world::Pose before = simulation_->tcpPose();
  arm::Wrench hand;
  hand.force = Eigen::Vector3d(15.0, 0.0, 0.0);
  hand.torque = Eigen::Vector3d(0.0, 0.0, 1.0);
  ASSERT_EQ(push("rotation", hand, 1.0).status, bt::Status::kSuccess);
  const world::Pose after = simulation_->tcpPose();
  EXPECT_GT(world::rotationAngle(before, after), 10.0 * M_PI / 180.0);
  EXPECT_LT((after.translation() - before.translation()).norm(), 0.01);
}

TEST_P(FreeDrive, ALockedAxisDoesNotMove) {
  const world::Pose before = simulation_->tcpPose();
  arm::Wrench hand;
  hand.force = Eigen::Vector3d(12.0, 12.0, 12.0);
  ASSERT_EQ(push("translation", hand, 1.0, "z").status, bt::Status::kSuccess);
  const Eigen::Vector3d moved = simulation_->tcpPose().translation() - before.translation();
  EXPECT_GT(moved.head<2>().norm(), 0.05);
  EXPECT_LT(std::abs(moved.z()), 0.005);
}

TEST_P(FreeDrive, PushingIntoTheTableStopsTheToolAboveItAndSaysWhy) {
  // From 12 cm above the table, 15 cm further out (the iiwa's elbow is near its limit below home).
  const double down = simulation_->tcpPose().translation().z() - 0.12;
  const bt::RunResult lowered = run("<MoveRelative offset=\"0.15;0;" + std::to_string(-down) + "\"/>", {});
  ASSERT_EQ(lowered.status, bt::Status::kSuccess) << lowered.failure_reason;
  const std::uint64_t contacts = simulation_->armTableContactSteps();
  arm::Wrench hand;
  hand.force = Eigen::Vector3d(0.0, 0.0, -40.0);
  std::string blocked;
  const bt::RunResult result = run("<FreeDrive mode=\"translation\" hold=\"0.2\"/>", [&](double t) {
    if (t < 5.0) {
      simulation_->setHandWrench(hand);
      arm_->holdFreeDrive(std::chrono::milliseconds(100));
      if (!arm_->freeDriveStatus().blocked.empty()) {
        blocked = arm_->freeDriveStatus().blocked;
      }
    } else {
      simulation_->setHandWrench({});
    }
  });
  ASSERT_EQ(result.status, bt::Status::kSuccess) << result.failure_reason;
  EXPECT_EQ(simulation_->armTableContactSteps(), contacts);
  EXPECT_GT(simulation_->tcpPose().translation().z(), 0.0);
  EXPECT_NE(blocked.find("table"), std::string::npos) << blocked;
}

TEST_P(FreeDrive, WithoutTheDeadManItEndsAndNothingMoves) {
  const world::Pose before = simulation_->tcpPose();
  arm::Wrench hand;
  hand.force = Eigen::Vector3d(30.0, 0.0, 0.0);
  simulation_->setHandWrench(hand);
  const bt::RunResult result = run("<FreeDrive hold=\"0.1\"/>", {});
  simulation_->setHandWrench({});
  ASSERT_EQ(result.status, bt::Status::kSuccess) << result.failure_reason;
  EXPECT_LT(toSeconds(result.elapsed), 0.2);
  EXPECT_LT((simulation_->tcpPose().translation() - before.translation()).norm(), 0.03);
  EXPECT_FALSE(arm_->holdFreeDrive(std::chrono::milliseconds(100)));  // none runs to hold
}

TEST_P(FreeDrive, ARandomDragKeepsTheLimitsTheSpeedAndClearOfTheTableAndParts) {
  FreeDriveTrialOptions options;
  options.seconds = 40.0;
  options.seed = 5;
  const FreeDriveTrialResult result = runFreeDriveTrial(*cell_, options);
  EXPECT_EQ(result.failure, "");
  EXPECT_GE(result.holds, 2);
  EXPECT_GT(result.travelled, 0.5);
  EXPECT_EQ(result.joint_limit_violations, 0U);
  EXPECT_EQ(result.table_contact_steps, 0U);
  EXPECT_EQ(result.part_contact_ticks, 0U);
  EXPECT_LE(result.max_tool_speed, 0.25);
  EXPECT_LE(result.max_stop_time, 0.5);
  // The arm is where its steps were checked, its elbow too (a UR5 near its elbow's singularity
  // folded 1.6 rad away from it with the tool within 1 cm, and its forearm reached the table).
  EXPECT_LE(result.max_departure, 0.1);
}

TEST_P(FreeDrive, ARecordedStrokeIsReplayedWithinTwoMillimetresAndOneDegree) {
  const ReplayTrialResult result = runReplayTrial(*cell_, 3);
  ASSERT_EQ(result.failure, "");
  EXPECT_GT(result.length, 0.1);
  EXPECT_LT(result.kept, result.samples / 4);  // simplified
  EXPECT_GE(result.kept, 3U);
  EXPECT_LE(result.rms_position, 0.002);
  EXPECT_LE(result.max_angle, 1.0 * M_PI / 180.0);
  EXPECT_GE(result.replay_seconds, 0.95 * result.recorded_seconds);  // at the recorded pace or slower
}

TEST_P(FreeDrive, PulledOutToItsReachTheArmStaysInTheConfigurationItsStepsWereCheckedAt) {
  // The tool pulled straight out from the base until the arm is stretched: near the elbow's
  // singularity the tool's impedance alone barely holds the elbow (a UR5's folded 1.6 rad away
  // from the checked configuration, the tool within 1 cm), and the collisions checked were
  // those of an arm somewhere else.
  const Eigen::Vector3d base = simulation_->tcpPose().translation();
  Eigen::Vector3d out(base.x(), base.y(), 0.0);
  out.normalize();
  double departure = 0.0;
  const bt::RunResult result = run("<FreeDrive mode=\"translation\" hold=\"0.2\"/>", [&](double t) {
    const arm::ArmComponent::FreeDriveStatus status = arm_->freeDriveStatus();
    const arm::JointVector q = simulation_->armPositions();
    if (status.active && status.checked.size() == q.size()) {
      for (int j = 0; j < q.size(); ++j) {
        departure = std::max(departure, std::abs(q[j] - status.checked[j]));
      }
    }
    if (t < 8.0) {
      arm::Wrench hand;
      hand.force = 40.0 * out + Eigen::Vector3d(0.0, 0.0, 10.0);
      simulation_->setHandWrench(hand);
      arm_->holdFreeDrive(std::chrono::milliseconds(100));
    } else {
      simulation_->setHandWrench({});
    }
  });
  EXPECT_EQ(result.status, bt::Status::kSuccess) << result.failure_reason;
  EXPECT_GT((simulation_->tcpPose().translation() - base).norm(), 0.1);
  EXPECT_LE(departure, 0.1) << departure;
}

INSTANTIATE_TEST_SUITE_P(BothArms, FreeDrive, ::testing::Values("ur5-sim", "iiwa-sim"),
                         [](const auto& cell) { return cell.param == "ur5-sim" ? "UR5" : "Iiwa"; });

/// A grasp taught by guiding the tool down onto a part (docs/TEACHING.md), on every arm and gripper.
class TaughtByGuiding : public FreeDrive {};

TEST_P(TaughtByGuiding, AGraspTaughtByPushingTheToolDownOntoANodeIsAtItsGraspHeightAndLiftsIt) {
  // Free-drive kept every link the whole 4 cm look-ahead off every part: a grasp taught by pushing
  // the gripper down around a node came out 36 to 39 mm above the node's centre (data/grasps.json:
  // 5 mm), where SmartGrasp with it does not hold the node.
  ASSERT_EQ(run("<DetectObjects/>", {}).status, bt::Status::kSuccess);
  // The node farthest from the arm's base: the arms' elbows reach down there from above.
  const Eigen::Vector3d base = arm_->config().base_in_world.translation();
  std::optional<sim::PartState> node;
  for (const sim::PartState& part : simulation_->parts()) {
    if (part.object_class == "node" && (!node || (part.pose.translation() - base).head<2>().norm() >
                                                     (node->pose.translation() - base).head<2>().norm())) {
      node = part;
    }
  }
  const Eigen::Vector3d tool = simulation_->tcpPose().translation();
  ASSERT_TRUE(node.has_value());
  // Over it (the tool's height kept), the fingers square to its faces.
  const Eigen::Vector3d over = node->pose.translation() - tool;
  const auto heading = [](const Eigen::Matrix3d& r) { return std::atan2(r(1, 0), r(0, 0)) * 180.0 / M_PI; };
  double turn = heading(node->pose.linear()) - heading(simulation_->tcpPose().linear());
  turn = std::remainder(turn, 90.0);
  const bt::RunResult moved =
      run("<Sequence><MoveRelative offset=\"" + std::to_string(over.x()) + ";" + std::to_string(over.y()) +
              ";0\"/><MoveRelative offset=\"0;0;0;0;0;" + std::to_string(turn) + "\"/></Sequence>",
          {});
  ASSERT_EQ(moved.status, bt::Status::kSuccess) << moved.failure_reason;
  // Pushed straight down with 40 N until free-drive holds it back.
  arm::Wrench hand;
  hand.force = Eigen::Vector3d(0.0, 0.0, -40.0);
  std::string blocked;
  const bt::RunResult pushed = run("<FreeDrive mode=\"translation\" hold=\"0.2\"/>", [&](double t) {
    if (t < 4.0) {
      simulation_->setHandWrench(hand);
      arm_->holdFreeDrive(std::chrono::milliseconds(100));
      blocked = arm_->freeDriveStatus().blocked.empty() ? blocked : arm_->freeDriveStatus().blocked;
    } else {
      simulation_->setHandWrench({});
    }
  });
  ASSERT_EQ(pushed.status, bt::Status::kSuccess) << pushed.failure_reason;
  EXPECT_EQ(simulation_->armTableContactSteps(), 0U);
  const world::Pose part_now = [&] {
    for (const sim::PartState& part : simulation_->parts()) {
      if (part.name == node->name) {
        return part.pose;
      }
    }
    return world::Pose::Identity();
  }();
  EXPECT_LT((part_now.translation() - node->pose.translation()).norm(), 0.002) << "the fingers pushed the node";
  const Eigen::Vector3d held = part_now.inverse() * simulation_->tcpPose().translation();
  // data/grasps.json's node grasps hold the tool centre point 0 (Basic, Wide, Scissor) to 5 mm
  // above the node's centre.
  std::printf("[ %s ] the tool centre point %.1f %.1f %.1f mm from %s's centre (held back: %s)\n", GetParam().c_str(),
              1000.0 * held.x(), 1000.0 * held.y(), 1000.0 * held.z(), node->name.c_str(), blocked.c_str());
  EXPECT_LT(held.head<2>().norm(), 0.005);
  EXPECT_LT(std::abs(held.z() - 0.005), 0.010);
  ASSERT_EQ(run("<TeachGrasp object_class=\"node\" grasp=\"guided\"/>", {}).status, bt::Status::kSuccess);
  // SmartGrasp with it, from above: the node lifted, judged on the simulator's truth.
  const bt::RunResult picked =
      run("<Sequence><MoveRelative offset=\"0;0;0.1\"/><SmartGrasp object_class=\"node\" grasp=\"guided\"/>"
          "<MoveRelative offset=\"0;0;0.1\"/></Sequence>",
          {});
  ASSERT_EQ(picked.status, bt::Status::kSuccess) << picked.failure_reason;
  for (const sim::PartState& part : simulation_->parts()) {
    if (part.name == node->name) {
      EXPECT_GT(part.pose.translation().z() - node->pose.translation().z(), 0.05) << "the node was not lifted";
    }
  }
}

INSTANTIATE_TEST_SUITE_P(EveryArm, TaughtByGuiding,
                         ::testing::Values("ur5-sim", "iiwa-sim", "iiwa-3f-sim", "panda-sim"));

}  // namespace
}  // namespace costar::trials
