// The simulated workcell: kinematics agree with the DH model, parts settle, the arm tracks
// its setpoints, grasps are physical, the RGB-D camera sees the scene.

#include "sim/simulation.h"

#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <filesystem>
#include <random>

#include "core/paths.h"

namespace costar::sim {
namespace {

// --- an independent DH model of the UR5 (world = base turned 180 deg about z) ----------------

world::Pose dhForward(const ArmJoints& q) {
  const double d[6] = {0.089159, 0, 0, 0.10915, 0.09465, 0.0823};
  const double a[6] = {0, -0.425, -0.39225, 0, 0, 0};
  const double alpha[6] = {M_PI / 2, 0, 0, M_PI / 2, -M_PI / 2, 0};
  world::Pose pose(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitZ()));
  for (int i = 0; i < 6; ++i) {
    pose = pose * Eigen::AngleAxisd(q[i], Eigen::Vector3d::UnitZ()) * Eigen::Translation3d(a[i], 0, d[i]) *
           Eigen::AngleAxisd(alpha[i], Eigen::Vector3d::UnitX());
  }
  return pose * Eigen::Translation3d(0, 0, 0.14);  // the tool centre point
}

/// Tool pointing straight down with the TCP at `target` and the fingers closing along world
/// x: Newton on (q1, q2, q3) with q4 = -pi/2 - q2 - q3, q5 = -pi/2, q6 = q1 (undoing q1's yaw).
ArmJoints toolDownAt(const Eigen::Vector3d& target) {
  ArmJoints q = Simulation::homeConfiguration();
  const auto complete = [](ArmJoints& j) {
    j[3] = -M_PI / 2 - j[1] - j[2];
    j[4] = -M_PI / 2;
    j[5] = j[0];
  };
  for (int iteration = 0; iteration < 50; ++iteration) {
    complete(q);
    const Eigen::Vector3d error = target - dhForward(q).translation();
    if (error.norm() < 1e-10) {
      break;
    }
    Eigen::Matrix3d jacobian;
    for (int k = 0; k < 3; ++k) {
      ArmJoints dq = q;
      dq[k] += 1e-7;
      complete(dq);
      jacobian.col(k) = (dhForward(dq).translation() - dhForward(q).translation()) / 1e-7;
    }
    const Eigen::Vector3d step = jacobian.colPivHouseholderQr().solve(error);
    for (int k = 0; k < 3; ++k) {
      q[k] += step[k];
    }
  }
  complete(q);
  return q;
}

Scene sceneOf(const std::string& json) { return parseScene(json, "test"); }

/// Moves the arm from its current setpoint to `goal` along a smooth (cubic) joint path of
/// `seconds`, simulating it; returns the largest TCP tracking error seen.
double moveArm(Simulation& sim, const ArmJoints& goal, double seconds) {
  const ArmJoints start = sim.armPositions();
  const TimePoint t0 = sim.time();
  sim.setArmSetpointSource([=](TimePoint t) {
    const double s = std::clamp(toSeconds(t - t0) / seconds, 0.0, 1.0);
    const double blend = 3 * s * s - 2 * s * s * s;
    const double rate = (6 * s - 6 * s * s) / seconds;
    const double accel = (6 - 12 * s) / (seconds * seconds) * (s < 1.0 ? 1.0 : 0.0);
    ArmSetpoint setpoint{ArmJoints::zero(6), ArmJoints::zero(6), ArmJoints::zero(6)};
    for (int i = 0; i < 6; ++i) {
      setpoint.position[i] = start[i] + (goal[i] - start[i]) * blend;
      setpoint.velocity[i] = (goal[i] - start[i]) * rate;
      setpoint.acceleration[i] = (goal[i] - start[i]) * accel;
    }
    return setpoint;
  });
  double worst = 0.0;
  const Duration step = std::chrono::milliseconds(10);
  for (TimePoint t = t0 + step; t <= t0 + fromSeconds(seconds + 0.3); t += step) {
    sim.stepTo(t);
    const double s = std::clamp(toSeconds(t - t0) / seconds, 0.0, 1.0);
    ArmJoints expected = ArmJoints::zero(6);
    for (int i = 0; i < 6; ++i) {
      expected[i] = start[i] + (goal[i] - start[i]) * (3 * s * s - 2 * s * s * s);
    }
    worst = std::max(worst, (dhForward(expected).translation() - sim.tcpPose().translation()).norm());
  }
  sim.setArmSetpointSource(nullptr);
  return worst;
}

void waitSeconds(Simulation& sim, double seconds) { sim.stepTo(sim.time() + fromSeconds(seconds)); }

TEST(Simulation, MujocoKinematicsMatchTheDhModelToATenthOfAMillimetre) {
  std::mt19937 random(7);
  std::uniform_real_distribution<double> angle(-M_PI, M_PI);
  const Scene empty = sceneOf(R"({"parts": []})");
  for (int trial = 0; trial < 10; ++trial) {
    ArmJoints q = ArmJoints::zero(6);
    for (double& joint : q) {
      joint = angle(random);
    }
    SimulationOptions options;
    options.initial_arm = q;
    options.settle_seconds = 0.0;
    const auto sim = Simulation::create(empty, options);
    const world::Pose expected = dhForward(q);
    EXPECT_LT((sim->tcpPose().translation() - expected.translation()).norm(), 1e-4);
    EXPECT_LT(world::rotationAngle(sim->tcpPose(), expected), 1e-6);
  }
}

// A hostile tester found MUJOCO_LOG.TXT in the folder they ran costar from: MuJoCo's default
// warning handler appends to that file in the working directory.
TEST(Simulation, MujocoWarningsGoToStandardErrorNotToAFileInTheWorkingDirectory) {
  const auto sim = Simulation::create(sceneOf(R"({"parts": []})"));
  const std::filesystem::path before = std::filesystem::current_path();
  const std::filesystem::path folder = std::filesystem::temp_directory_path() / "mujoco_warning";
  std::filesystem::create_directories(folder);
  std::filesystem::current_path(folder);
  ::testing::internal::CaptureStderr();
  mju_warning("a test warning");
  const std::string printed = ::testing::internal::GetCapturedStderr();
  std::filesystem::current_path(before);
  EXPECT_FALSE(std::filesystem::exists(folder / "MUJOCO_LOG.TXT"));
  EXPECT_NE(printed.find("MuJoCo warning: a test warning"), std::string::npos) << printed;
}

TEST(Simulation, PartsSettleOnTheTable) {
  const auto sim = Simulation::create(loadScene(dataRoot() / "sim/scenes/clutter.json"));
  waitSeconds(*sim, 0.5);
  for (const PartState& part : sim->parts()) {
    const double rest = part.object_class == "node" ? 0.025 : 0.0125;
    EXPECT_NEAR(part.pose.translation().z(), rest, 0.002) << part.name;
    EXPECT_LT(part.linear_velocity.norm(), 0.005) << part.name;
  }
  EXPECT_EQ(sim->armTableContactSteps(), 0u);
}

TEST(Simulation, TheArmTracksItsSetpointsAndHoldsStill) {
  const auto sim = Simulation::create(sceneOf(R"({"parts": []})"));
  const ArmJoints goal = toolDownAt({0.55, -0.15, 0.15});
  const double worst = moveArm(*sim, goal, 2.0);
  EXPECT_LT(worst, 0.002);  // 2 mm while moving at up to ~0.6 m/s
  EXPECT_LT((sim->tcpPose().translation() - Eigen::Vector3d(0.55, -0.15, 0.15)).norm(), 2e-4);
  waitSeconds(*sim, 1.0);
  EXPECT_LT((sim->tcpPose().translation() - Eigen::Vector3d(0.55, -0.15, 0.15)).norm(), 2e-4);
  EXPECT_EQ(sim->armTableContactSteps(), 0u);
}

// A steady load the controller's model does not know (a wire being bent, a person's hand)
// deflects the arm at first, and the controller's integral action takes the error away once the
// setpoint rests: without it the arm stayed up to 6 mrad from a goal, beyond the arrival
// tolerance (wire bending's "the arm stopped 0.005 rad from its goal").
TEST(Simulation, ASteadyLoadOnTheToolLeavesNoSteadyErrorOnceTheSetpointRests) {
  const auto sim = Simulation::create(sceneOf(R"({"parts": []})"));
  const ArmJoints goal = toolDownAt({0.55, -0.15, 0.15});
  moveArm(*sim, goal, 1.0);
  arm::Wrench push;
  push.force = Eigen::Vector3d(0.0, 20.0, -10.0);
  sim->setHandWrench(push);
  double first = 0.0;
  for (int i = 0; i < 30; ++i) {
    waitSeconds(*sim, 0.01);
    first = std::max(first, arm::maxAbsDifference(sim->armPositions(), goal));
  }
  EXPECT_GT(first, 1e-3) << first;  // the load deflects the arm at first
  waitSeconds(*sim, 1.0);
  EXPECT_LT(arm::maxAbsDifference(sim->armPositions(), goal), 1e-4);
  // Let go: the arm comes back to its goal and the integral's part goes again.
  sim->setHandWrench({});
  waitSeconds(*sim, 1.5);
  EXPECT_LT(arm::maxAbsDifference(sim->armPositions(), goal), 1e-4);
}

TEST(Simulation, ASetpointForAnotherArmIsRefusedAndTheArmHolds) {
  const auto sim = Simulation::create(sceneOf(R"({"parts": []})"));
  EXPECT_EQ(sim->armJointNames().size(), 6u);  // from robots/ur5/ur5.json
  EXPECT_EQ(sim->armJointNames().front(), "shoulder_pan_joint");
  const ArmJoints before = sim->armPositions();
  // Seven joints for a six-joint arm: the controller keeps the last good setpoint.
  sim->setArmSetpointSource([](TimePoint) {
    return ArmSetpoint{ArmJoints(7, 0.5), ArmJoints::zero(7), ArmJoints::zero(7)};
  });
  waitSeconds(*sim, 0.5);
  EXPECT_LT(arm::maxAbsDifference(sim->armPositions(), before), 1e-3);
  sim->setArmSetpointSource(nullptr);
}

TEST(Simulation, AGraspIsPhysicalTheFingersHoldThePartByFrictionOnly) {
  const auto sim =
      Simulation::create(sceneOf(R"({"parts": [{"class": "node", "color": "red", "at": [0.5, -0.1, 0]}]})"));
  const Eigen::Vector3d node = sim->parts()[0].pose.translation();
  ASSERT_LT(moveArm(*sim, toolDownAt(node + Eigen::Vector3d(0, 0, 0.12)), 2.0), 0.003);
  ASSERT_LT(moveArm(*sim, toolDownAt(node + Eigen::Vector3d(0, 0, 0.005)), 1.0), 0.003);
  sim->commandFingers(0.0, 0.1, 40.0);
  waitSeconds(*sim, 1.0);
  const FingerState closed = sim->fingers();
  EXPECT_TRUE(closed.pads_in_contact);
  EXPECT_NEAR(closed.opening, 0.05, 0.002);  // stopped on the 5 cm node
  EXPECT_NEAR(closed.force, 40.0, 4.0);
  EXPECT_LT(std::abs(closed.opening_speed), 1e-3);

  // Lift: the node comes along, held only by the fingers.
  moveArm(*sim, toolDownAt(node + Eigen::Vector3d(0.05, 0.1, 0.2)), 2.0);
  const PartState lifted = sim->parts()[0];
  EXPECT_NEAR(lifted.pose.translation().z(), node.z() + 0.195, 0.005);
  EXPECT_NEAR(lifted.pose.translation().x(), node.x() + 0.05, 0.005);
  EXPECT_NEAR(lifted.pose.translation().y(), node.y() + 0.1, 0.005);
  const auto contacts = sim->contacts();
  EXPECT_NE(
      std::find(contacts.begin(), contacts.end(), std::make_pair(std::string("left_finger"), std::string("node_0"))),
      contacts.end());

  // Open: it falls back onto the table.
  sim->commandFingers(sim->maxOpening(), 0.1, 40.0);
  waitSeconds(*sim, 1.5);
  EXPECT_NEAR(sim->parts()[0].pose.translation().z(), 0.025, 0.01);
  EXPECT_FALSE(sim->fingers().pads_in_contact);
}

TEST(Simulation, ClosingOnNothingClosesFully) {
  const auto sim = Simulation::create(sceneOf(R"({"parts": []})"));
  sim->commandFingers(0.0, 0.1, 40.0);
  waitSeconds(*sim, 1.2);
  EXPECT_LT(sim->fingers().opening, 0.001);
  EXPECT_FALSE(sim->fingers().pads_in_contact);
}

// A full close presses a part as thin as a wire with the set force, as an electric gripper's
// motor current does: the position servo's setpoint at closed pressed a 2.5 mm wire with
// kp x 1.25 mm = 3.75 N of a 20 N close, and a wire being bent turned and slid in the pads
// (wire bending on iiwa-sim, seeds 1226, 1259, 1284: bends 6-12 degrees off).
TEST(Simulation, AFullCloseSqueezesAThinWireWithTheSetForce) {
  // The jig turned so that the wire runs along world y, across the fingers (they close along x).
  const auto sim = Simulation::create(sceneOf(R"({"parts": [],
    "jig": {"at": [0.5, -0.1, 90], "height": 0.03, "pins": []},
    "wire": {"material": "steel_annealed", "diameter": 0.0025, "length": 0.2, "segments": 16}})"));
  const Eigen::Vector3d grip(0.5, 0.05, 0.03);
  ASSERT_LT(moveArm(*sim, toolDownAt(grip + Eigen::Vector3d(0, 0, 0.1)), 2.0), 0.003);
  ASSERT_LT(moveArm(*sim, toolDownAt(grip), 1.5), 0.003);
  sim->commandFingers(0.0, 0.1, 20.0);
  waitSeconds(*sim, 1.0);
  const FingerState closed = sim->fingers();
  EXPECT_TRUE(closed.pads_in_contact);
  EXPECT_NEAR(closed.opening, 0.0025, 0.0005);  // stopped on the wire
  EXPECT_NEAR(closed.force, 20.0, 1.0);
  ASSERT_TRUE(sim->jig());
  EXPECT_EQ(sim->jig()->grip.holds, 1);
  // Let go: the servo's setpoint comes back within the stroke and the fingers open as told.
  sim->commandFingers(0.04, 0.1, 20.0);
  waitSeconds(*sim, 1.0);
  EXPECT_NEAR(sim->fingers().opening, 0.04, 0.001);
}

// A parallel gripper is its description (robots/grippers/NAME.json): the Franka Hand's stroke
// is read back from its generated model, and it opens, closes and squeezes as described.
TEST(Simulation, AParallelGripperHasTheStrokeItsDescriptionGives) {
  const auto two = Simulation::create(sceneOf(R"({"parts": []})"));
  EXPECT_DOUBLE_EQ(two->maxOpening(), 0.085);
  SimulationOptions options;
  options.gripper_model = std::filesystem::path(COSTAR_GRIPPER_MODEL_DIR) / "franka-hand_mount.xml";
  const auto hand = Simulation::create(sceneOf(R"({"parts": []})"), options);
  EXPECT_DOUBLE_EQ(hand->maxOpening(), 0.08);
  EXPECT_NEAR(hand->fingers().opening, 0.08, 0.001);  // fully open at the start
  hand->commandFingers(0.03, 0.1, 40.0);
  waitSeconds(*hand, 1.0);
  EXPECT_NEAR(hand->fingers().opening, 0.03, 0.001);
  hand->commandFingers(0.5, 0.1, 40.0);  // beyond the stroke: fully open
  waitSeconds(*hand, 1.0);
  EXPECT_NEAR(hand->fingers().opening, 0.08, 0.001);
  hand->commandFingers(0.0, 0.1, 40.0);
  waitSeconds(*hand, 1.2);
  EXPECT_LT(hand->fingers().opening, 0.001);
  EXPECT_FALSE(hand->fingers().pads_in_contact);
}

TEST(Simulation, TheRgbdCameraSeesTheTableAndTheParts) {
  const auto sim =
      Simulation::create(sceneOf(R"({"parts": [{"class": "node", "color": "green", "at": [0.5, 0.0, 0]}]})"));
  const camera::RgbdFrame frame = sim->captureRgbd(1);
  ASSERT_EQ(frame.points.size(), 640u * 480u);
  EXPECT_EQ(frame.rgb.width, 640);
  EXPECT_GT(frame.validCount(), 640u * 480u * 8 / 10);
  EXPECT_TRUE(frame.camera_pose.translation().isApprox(Eigen::Vector3d(1.25, 0, 0.85), 1e-6));
  // The optical axis points at the workspace, downward.
  EXPECT_LT((frame.camera_pose.linear() * Eigen::Vector3d::UnitZ()).z(), -0.6);
  // Points that land near the node's top face are where the node really is.
  int on_node = 0;
  int on_table = 0;
  for (const auto& p : frame.points) {
    if (!std::isfinite(p.z())) {
      continue;
    }
    const Eigen::Vector3d world_point = frame.camera_pose * p.cast<double>();
    if ((world_point.head<2>() - Eigen::Vector2d(0.5, 0.0)).norm() < 0.02 && world_point.z() > 0.04) {
      ++on_node;
      EXPECT_NEAR(world_point.z(), 0.05, 0.015);
    }
    if ((world_point.head<2>() - Eigen::Vector2d(0.4, 0.3)).norm() < 0.05) {
      ++on_table;
      EXPECT_NEAR(world_point.z(), 0.0, 0.01);
    }
  }
  EXPECT_GT(on_node, 20);
  EXPECT_GT(on_table, 100);
  // The node is green in the image where it is.
  const RgbImage overview = sim->renderImage("overview", 320, 240);
  EXPECT_EQ(overview.width, 320);
}

TEST(Simulation, AFrameWithoutColourHasTheSamePointsAsAFullOne) {
  // DetectObjects takes colour from its last frame only; the others are rendered flat, without
  // shadows or colour read-back. Their depth, and so their points, must be the same.
  const auto sim = Simulation::create(sceneOf(R"({"parts": [
      {"class": "node", "color": "green", "at": [0.5, 0.0, 0]},
      {"class": "link", "color": "grey", "at": [0.45, 0.2, 30]}]})"));
  for (const std::uint64_t seed : {3u, 4u}) {
    const camera::RgbdFrame full = sim->captureRgbd(seed);
    const camera::RgbdFrame depth_only = sim->captureRgbd(seed, false);
    EXPECT_EQ(full.rgb.width, 640);
    EXPECT_TRUE(depth_only.rgb.pixels.empty());
    ASSERT_EQ(full.points.size(), depth_only.points.size());
    std::size_t differ = 0;
    for (std::size_t i = 0; i < full.points.size(); ++i) {
      const bool both_invalid = !std::isfinite(full.points[i].z()) && !std::isfinite(depth_only.points[i].z());
      differ += both_invalid || full.points[i] == depth_only.points[i] ? 0 : 1;
    }
    EXPECT_EQ(differ, 0u) << "seed " << seed;
    EXPECT_GT(full.validCount(), 640u * 480u * 8 / 10);
    sim->stepTo(sim->time() + std::chrono::milliseconds(100));
  }
}

}  // namespace
}  // namespace costar::sim
