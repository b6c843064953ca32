// Calibrate (calibration/calibration_component.h) in the simulated cell, judged from the
// simulator's true state: the arm shows the gripper's marker to a camera moved 5 cm / 5 deg
// from its drawn mounting without touching the parts on the table (it knows none of them yet:
// the camera is not calibrated), and the camera is found within the 2 mm / 0.2 deg.
// The seeds are set-ups where Calibrate's arm used to sweep through the parts (seed 500: a
// part pushed 81 mm; iiwa seed 31: docs/BENCHMARKS_HISTORY.md, "Calibration").

#include <gtest/gtest.h>

#include <cmath>

#include "core/paths.h"
#include "sim/simulation.h"
#include "workcell/workcell.h"

namespace costar::workcell {
namespace {

/// Runs Calibrate in a fresh cell; returns the farthest any part moved (m), and checks the
/// camera against the simulator's true pose.
double calibrateAndMeasure(const std::string& cell_name, std::uint64_t seed) {
  const auto cell = makeWorkcell({.name = cell_name,
                                  .scene = dataRoot() / "sim/scenes/assembly.json",
                                  .seed = seed,
                                  .memory_only = true,
                                  .camera_move = WorkcellOptions::CameraMove{0.05, 5.0, {}}});
  sim::Simulation& simulation = *cell->simulation();
  const std::vector<sim::PartState> before = simulation.parts();
  EXPECT_EQ(before.size(), 5u);
  const component::OperationResult result = runOperation(*cell, "Calibrate", {}, std::chrono::seconds(120));
  EXPECT_EQ(result.state, component::OperationState::kSuccess) << result.reason;
  const std::vector<sim::PartState> after = simulation.parts();
  double moved = 0.0;
  for (std::size_t i = 0; i < before.size() && i < after.size(); ++i) {
    EXPECT_EQ(before[i].name, after[i].name);
    const double d = (after[i].pose.translation() - before[i].pose.translation()).norm();
    EXPECT_LT(d, 0.001) << cell_name << " seed " << seed << ": Calibrate moved " << after[i].name << " by " << d * 1000
                        << " mm";
    moved = std::max(moved, d);
  }
  if (result.state == component::OperationState::kSuccess) {
    const auto& t = result.data.at("camera").at("xyz");
    const auto& r = result.data.at("camera").at("rpy_deg");
    const world::Pose found = world::poseFromXyzRpy(t[0], t[1], t[2], r[0].get<double>() * M_PI / 180,
                                                    r[1].get<double>() * M_PI / 180, r[2].get<double>() * M_PI / 180);
    const world::Pose truth = simulation.rgbdPose();
    EXPECT_LT((found.translation() - truth.translation()).norm(), 0.002);
    EXPECT_LT(world::rotationAngle(found, truth), 0.2 * M_PI / 180);
    EXPECT_LE(result.data.at("simulated_s").get<double>(), 50.0);
  }
  return moved;
}

TEST(CalibrateSim, TheUr5ShowsTheMarkerWithoutPushingAPart) { EXPECT_LT(calibrateAndMeasure("ur5-sim", 500), 0.001); }

TEST(CalibrateSim, TheIiwaShowsTheMarkerWithoutPushingAPart) { EXPECT_LT(calibrateAndMeasure("iiwa-sim", 31), 0.001); }

// Calibrate asked with the gripper down among the parts' places: refused with the reason (it
// could not move without the risk of pushing a part), the drawn camera pose kept; the keep-out
// is gone afterwards (the arm can go there again).
TEST(CalibrateSim, RefusedWhileTheGripperIsInThePartArea) {
  const auto cell = makeWorkcell({.name = "ur5-sim",
                                  .scene = dataRoot() / "sim/scenes/assembly.json",  // parts at y < 0
                                  .seed = 3,
                                  .memory_only = true});
  const auto down = [&cell](double z) {
    return runOperation(*cell, "MoveToPose",
                        {{"pose", component::Value(world::poseFromXyzRpy(0.5, 0.3, z, M_PI, 0, 0))},
                         {"frame", component::Value("world")},
                         {"speed", component::Value(1.0)}},
                        std::chrono::seconds(30));
  };
  ASSERT_EQ(down(0.05).state, component::OperationState::kSuccess);
  const component::OperationResult result = runOperation(*cell, "Calibrate", {}, std::chrono::seconds(30));
  EXPECT_EQ(result.state, component::OperationState::kFailure);
  EXPECT_NE(result.reason.find("the arm is in the table's part area"), std::string::npos) << result.reason;
  EXPECT_NE(result.reason.find("calibration_keep_out"), std::string::npos) << result.reason;
  EXPECT_NE(result.reason.find("the previous calibration is kept"), std::string::npos) << result.reason;
  cell->components().refreshWorld();
  EXPECT_FALSE(cell->components().world().holds("camera_calibrated", {}));
  EXPECT_EQ(down(0.04).state, component::OperationState::kSuccess);
}

}  // namespace
}  // namespace costar::workcell
