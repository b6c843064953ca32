#pragma once
// Reruns a task plan as N randomized trials in the simulated cell (parts placed at random in
// the scene's regions with any yaw, fresh sensor noise, a different seed per trial), judges
// each from the simulator's true state, and summarizes: success rate, failures by node and
// reason, cycle times. The paper's evaluation, repeatable with one command.

#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace costar::trials {

struct TrialOptions {
  std::filesystem::path plan;
  std::filesystem::path scene;
  std::string judge;
  int count = 10;
  std::uint64_t seed = 1;           // trial i uses seed + i
  std::filesystem::path waypoints;  // read, never written
  double time_limit_s = 600.0;      // simulated seconds per trial
  double settle_s = 2.0;            // simulated after the plan, before judging
  int jobs = 1;                     // trials run at once (threads)
  /// The camera moved from its drawn mounting in each trial by this distance (m) and angle
  /// (degrees) in a direction drawn from the trial's seed (0, 0: mounted as drawn).
  double camera_move_m = 0.0;
  double camera_turn_deg = 0.0;
  /// Calibrate the camera once in each trial's cell before the plan runs, as a technician does
  /// after setting the cell up (not counted in the cycle time; a failed calibration fails the
  /// trial).
  bool calibrate = false;
};

struct TrialResult {
  int index = 0;
  std::uint64_t seed = 0;
  bool success = false;
  /// On failure: the failing node's path (or "judge") and the reason.
  std::string failure_path;
  std::string reason;
  double cycle_time_s = 0.0;  // simulated
  double wall_s = 0.0;
};

struct Summary {
  TrialOptions options;
  std::vector<TrialResult> trials;
  int successes() const;
  /// Failures grouped by node path and reason, numbers masked ("# candidates"), most first.
  std::vector<std::pair<std::string, int>> failureHistogram() const;
  /// Cycle times of the successful trials: min, median, p95, max, mean.
  std::map<std::string, double> cycleTimes() const;
  nlohmann::json toJson() const;
  std::string text() const;
};

/// Runs the trials; `progress` is called as each one ends (from the trial's thread, one at a
/// time). @throws std::runtime_error before the first trial when the plan is invalid or a file
/// is missing.
Summary runTrials(const TrialOptions& options, const std::function<void(const TrialResult&, int done)>& progress = {});

/// A PNG a person can read: success rate, failures by reason, cycle-time histogram.
void writePlot(const Summary& summary, const std::filesystem::path& png);

}  // namespace costar::trials
