// The wire-bending judge (trials/wire_judge.h) on the simulator's true state: a scene without a
// wire, a wire nobody touched, and one trial of examples/iiwa/wire_bending.xml on the 3-finger
// iiwa cell, whose bends it measures within the drawing's tolerance.

#include "trials/wire_judge.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/paths.h"
#include "sim/scene.h"
#include "trials/trials.h"

namespace costar::trials {
namespace {

TEST(WireJudge, ASceneWithoutAWireIsNoWireBending) {
  const auto simulation = sim::Simulation::create(sim::loadScene(dataRoot() / "sim/scenes/one_node.json"));
  const Verdict verdict = judge("wire_bending")(*simulation, simulation->parts());
  EXPECT_FALSE(verdict.success);
  EXPECT_NE(verdict.reason.find("the scene has no wire in a jig"), std::string::npos) << verdict.reason;
}

TEST(WireJudge, AWireNobodyTouchedIsNotBent) {
  sim::SimulationOptions options;
  options.settle_seconds = 0.5;
  const auto simulation = sim::Simulation::create(sim::loadScene(dataRoot() / "sim/scenes/wire_bending.json"), options);
  const Verdict verdict = wireBending(*simulation, simulation->parts());
  EXPECT_FALSE(verdict.success);
  EXPECT_EQ(verdict.reason, "the gripper never held the wire");
}

TEST(WireJudge, TheWireBendingPlanBendsTheWireToTheDrawing) {
  TrialOptions options;
  options.workcell = "iiwa-3f-sim";
  options.plan = dataRoot() / "examples/iiwa/wire_bending.xml";
  options.scene = dataRoot() / "sim/scenes/wire_bending.json";
  options.waypoints = dataRoot() / "examples/iiwa/wire_waypoints.json";
  options.judge = "wire_bending";
  options.count = 1;
  options.seed = 1;
  options.jobs = 1;
  const Summary summary = runTrials(options);
  ASSERT_EQ(summary.trials.size(), 1u);
  const TrialResult& trial = summary.trials[0];
  EXPECT_TRUE(trial.success) << trial.failure_path << ": " << trial.reason;
  // "bends A, B degrees; ...": both within the judge's 5 degrees of +90 and -90.
  double first = 0.0;
  double second = 0.0;
  ASSERT_EQ(std::sscanf(trial.reason.c_str(), "bends %lf, %lf degrees", &first, &second), 2) << trial.reason;
  EXPECT_LE(std::abs(first - 90.0), kWireBendToleranceDeg);
  EXPECT_LE(std::abs(second + 90.0), kWireBendToleranceDeg);
}

}  // namespace
}  // namespace costar::trials
