#pragma once
// Calibration judged against the simulator's truth: N seeded set-ups of the simulated cell,
// the camera moved from its drawn mounting by a given distance and angle in a random
// direction; in each, the marker calibration (per hand-eye method, optional) and Calibrate,
// and the camera's error after each against its true pose. docs/CALIBRATION.md.

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace costar::trials {

struct CalibrationEvalOptions {
  /// The simulated workcell (workcells/NAME.json).
  std::string workcell = "ur5-sim";
  std::filesystem::path scene;  // default: sim/scenes/assembly.json
  int setups = 20;
  std::uint64_t seed = 100;  // set-up i: seed + i
  double camera_move_m = 0.05;
  double camera_turn_deg = 5.0;
  /// Hand-eye methods whose marker calibration is run in each set-up, each followed by a
  /// Calibrate with its result (empty: only Calibrate, with the cell's marker calibration).
  std::vector<std::string> methods;
  /// Refine the methods' solutions on the corners' reprojection.
  bool refine = true;
  /// Also run DetectObjects before and after Calibrate and score the parts' poses against the
  /// simulator's (within 5 mm and 5 degrees, symmetry-aware).
  bool perception = false;
  /// Views taken by the marker calibration and by Calibrate (0: the component's defaults).
  int marker_views = 0;
  int camera_views = 0;
};

/// One calibration in one set-up (a cell without a simulator: a failed sample saying so).
struct CalibrationSample {
  int setup = 0;
  std::string method;  // "" for Calibrate with the cell's marker calibration
  bool marker_ok = true;
  bool camera_ok = false;
  std::string reason;
  double camera_before_mm = 0, camera_before_deg = 0;  // the drawn pose against the truth
  double marker_mm = 0, marker_deg = 0;                // X against the truth
  double stage_a_camera_mm = 0, stage_a_camera_deg = 0;
  double camera_mm = 0, camera_deg = 0;  // after Calibrate
  double marker_simulated_s = 0, camera_simulated_s = 0;
  double reprojection_rms_px = 0;
  /// The farthest any part moved while Calibrate ran (mm, the simulator's true poses).
  double parts_moved_mm = 0;
  /// With `perception`: parts in the scene, and those DetectObjects put within 5 mm and 5
  /// degrees of their true pose, with the drawn camera pose and after Calibrate.
  int parts = 0;
  int parts_accurate_before = 0;
  int parts_accurate_after = 0;
};

struct CalibrationEvalSummary {
  std::vector<CalibrationSample> samples;
  nlohmann::json toJson() const;
  /// Per method: successes, median and worst of each error, median simulated time.
  std::string text() const;
};

CalibrationEvalSummary evaluateCalibration(const CalibrationEvalOptions& options,
                                           const std::function<void(const CalibrationSample&)>& progress = {});

}  // namespace costar::trials
