// The simulated wrist force/torque sensor (bias, noise, tare, seeded) and the controller's
// Cartesian impedance mode (holding, following a line, pressing with a force, the force limit's
// stop), on the default UR5 cell with its 2-finger gripper and no parts.

#include <gtest/gtest.h>

#include <cmath>

#include "arm/cartesian_controller.h"
#include "sim/simulation.h"

namespace costar::sim {
namespace {

using std::chrono::milliseconds;

std::unique_ptr<Simulation> emptyCell(std::uint64_t seed = 3) {
  SimulationOptions options;
  options.placement_seed = seed;
  return Simulation::create(parseScene(R"({"parts": []})", "empty"), options);
}

void run(Simulation& simulation, Duration duration) { simulation.stepTo(simulation.time() + duration); }

/// The mean and standard deviation of the reading's force (sensor frame) over `count` steps.
std::pair<Eigen::Vector3d, double> sampleForce(Simulation& simulation, int count) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector3d> samples;
  for (int i = 0; i < count; ++i) {
    run(simulation, simulation.timestep());
    samples.push_back(simulation.forceTorqueSensor().read().wrench.force);
    sum += samples.back();
  }
  const Eigen::Vector3d mean = sum / count;
  double variance = 0.0;
  for (const auto& sample : samples) {
    variance += (sample - mean).squaredNorm() / (3.0 * count);
  }
  return {mean, std::sqrt(variance)};
}

TEST(ForceTorqueSensor, ReadsTheGrippersWeightAndABiasUntilTaredThenNoiseAroundZero) {
  const auto simulation = emptyCell();
  arm::ForceTorqueSensor& sensor = simulation->forceTorqueSensor();
  // The flange holds the gripper up: the true force points up in the world, its weight.
  const Eigen::Matrix3d flange = simulation->tcpPose().linear();
  const Eigen::Vector3d held = flange * simulation->trueFlangeWrench().force;
  EXPECT_GT(held.z(), 5.0);
  EXPECT_LT(held.head<2>().norm(), 0.05 * held.z());
  const auto [before, sigma_before] = sampleForce(*simulation, 200);
  // Untared: the true force plus the bias drawn from the seed (up to 3 N an axis).
  const arm::Wrench& bias = dynamic_cast<const SimForceTorqueSensor&>(sensor).bias();
  EXPECT_GT(bias.force.norm(), 0.1);
  EXPECT_LT((before - simulation->trueFlangeWrench().force - bias.force).norm(), 0.05);
  sensor.tare();
  const auto [after, sigma] = sampleForce(*simulation, 500);
  EXPECT_LT(after.norm(), 0.1);  // the tare's mean of 50 samples: 0.02 N an axis
  EXPECT_NEAR(sigma, 0.15, 0.02);
  EXPECT_NEAR(sigma_before, 0.15, 0.03);
}

TEST(ForceTorqueSensor, TheSameSeedReadsTheSameAndAnotherSeedHasAnotherBias) {
  const auto a = emptyCell(5);
  const auto b = emptyCell(5);
  const auto c = emptyCell(6);
  run(*a, milliseconds(100));
  run(*b, milliseconds(100));
  run(*c, milliseconds(100));
  EXPECT_EQ(a->forceTorqueSensor().read().wrench.force, b->forceTorqueSensor().read().wrench.force);
  EXPECT_EQ(a->forceTorqueSensor().read().wrench.torque, b->forceTorqueSensor().read().wrench.torque);
  const auto& bias_a = dynamic_cast<const SimForceTorqueSensor&>(a->forceTorqueSensor()).bias();
  const auto& bias_c = dynamic_cast<const SimForceTorqueSensor&>(c->forceTorqueSensor()).bias();
  EXPECT_GT((bias_a.force - bias_c.force).norm(), 0.1);
}

arm::CartesianMotion holding(const world::Pose& pose) {
  arm::CartesianMotion motion;
  motion.path = std::make_shared<arm::CartesianPath>(arm::CartesianPath::through({pose}, {}));
  return motion;
}

TEST(CartesianImpedance, HoldsThePoseItIsGivenAndHandsBackToJointControl) {
  const auto simulation = emptyCell();
  const world::Pose start = simulation->tcpPose();
  simulation->cartesianController().follow(holding(start), simulation->time());
  run(*simulation, std::chrono::seconds(2));
  EXPECT_TRUE(simulation->cartesianController().state().following);
  EXPECT_LT((simulation->tcpPose().translation() - start.translation()).norm(), 0.001);
  EXPECT_LT(world::rotationAngle(simulation->tcpPose(), start), 0.01);
  const ArmJoints q = simulation->armPositions();
  simulation->setArmSetpointSource([q](TimePoint) { return ArmSetpoint{q, ArmJoints::zero(6), ArmJoints::zero(6)}; });
  EXPECT_FALSE(simulation->cartesianController().state().following);
  run(*simulation, std::chrono::seconds(1));
  EXPECT_LT((simulation->tcpPose().translation() - start.translation()).norm(), 0.001);
}

TEST(CartesianImpedance, FollowsALineInFreeSpaceWithinAFewMillimetres) {
  const auto simulation = emptyCell();
  const world::Pose start = simulation->tcpPose();
  world::Pose end = start;
  end.translation() += Eigen::Vector3d(0.1, 0.05, -0.05);
  arm::CartesianMotion motion;
  motion.path = std::make_shared<arm::CartesianPath>(
      arm::CartesianPath::through({start, end}, {.speed = 0.05, .acceleration = 0.5}));
  simulation->cartesianController().follow(motion, simulation->time());
  const TimePoint began = simulation->time();
  double worst = 0.0;
  while (simulation->time() - began < motion.path->duration()) {
    run(*simulation, milliseconds(10));
    const Eigen::Vector3d reference = motion.path->sample(simulation->time() - began).pose.translation();
    worst = std::max(worst, (simulation->tcpPose().translation() - reference).norm());
  }
  run(*simulation, milliseconds(500));
  EXPECT_LT(worst, 0.004);
  EXPECT_LT((simulation->tcpPose().translation() - end.translation()).norm(), 0.001);
  EXPECT_TRUE(simulation->cartesianController().state().path_done);
}

TEST(CartesianImpedance, PressesOnTheTableWithTheTargetForceAlongTheAxis) {
  const auto simulation = emptyCell();
  simulation->forceTorqueSensor().tare();
  // Down until the fingers press on the table with 10 N.
  arm::CartesianMotion motion = holding(simulation->tcpPose());
  motion.force = arm::ForceAxis{-Eigen::Vector3d::UnitZ(), 10.0, 0.05};
  motion.force_limit = 40.0;
  simulation->cartesianController().follow(motion, simulation->time());
  run(*simulation, std::chrono::seconds(8));
  const arm::CartesianState state = simulation->cartesianController().state();
  EXPECT_FALSE(state.force_limit_stop);
  double force = 0.0;
  for (int i = 0; i < 100; ++i) {
    run(*simulation, milliseconds(10));
    force += simulation->cartesianController().state().axis_force / 100.0;
  }
  EXPECT_NEAR(force, 10.0, 0.3);
  EXPECT_GT(state.offset, 0.05);  // it went down to the table
  const auto contacts = simulation->contacts();
  EXPECT_TRUE(std::any_of(contacts.begin(), contacts.end(),
                          [](const auto& pair) { return pair.first == "table" || pair.second == "table"; }));
}

TEST(CartesianImpedance, AForceAboveTheLimitStopsTheMotionWhereItIs) {
  const auto simulation = emptyCell();
  simulation->forceTorqueSensor().tare();
  arm::CartesianMotion motion = holding(simulation->tcpPose());
  motion.force = arm::ForceAxis{-Eigen::Vector3d::UnitZ(), 20.0, 0.05};
  motion.force_limit = 8.0;
  simulation->cartesianController().follow(motion, simulation->time());
  run(*simulation, std::chrono::seconds(8));
  const arm::CartesianState state = simulation->cartesianController().state();
  EXPECT_TRUE(state.force_limit_stop);
  EXPECT_GT(state.stop_force, 8.0);
  // It presses no more (the impact's peak is over; the target's 20 N is never pressed with) and
  // stays where it stopped.
  EXPECT_LT(std::abs(state.axis_force), 2.0);
  const world::Pose stopped = simulation->tcpPose();
  run(*simulation, std::chrono::seconds(1));
  EXPECT_LT((simulation->tcpPose().translation() - stopped.translation()).norm(), 0.001);
  EXPECT_LT(std::abs(simulation->cartesianController().state().axis_force), 2.0);
}

}  // namespace
}  // namespace costar::sim
