#pragma once
// The fault campaign: runs the paper's UR5 plans in the simulated cell with one injected fault
// each (every kind, every target, at random moments drawn from the seed) and judges every run
// from outside: it must end as FAILURE with the failing node's path and a reason within a
// deadline (1 s of simulated time) of the fault taking effect, the arm must come to rest
// (the simulator's true joint velocities), and the waypoint file the cell keeps must be
// unchanged and loadable. A fault that takes no effect (the plan was over, or the broken
// device was not used again) may end in SUCCESS; those are counted apart, not hidden.

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace costar::trials {

struct CampaignTask {
  std::string name;
  std::filesystem::path plan;
  /// DetectObjects runs in the plan (camera faults pick a frame among them).
  int detections = 1;
  /// Timed faults of this task come in [0, min(window_s, this)): task 1 is over in ~6 s.
  double window_s = 1e9;
};

/// The paper's three UR5 tasks (examples/ur5/).
std::vector<CampaignTask> paperTasks();

struct CampaignOptions {
  /// "ur5-sim", or "test" (components only, no robot: the arm checks are skipped).
  std::string workcell = "ur5-sim";
  std::vector<CampaignTask> tasks = paperTasks();
  /// Fault specs to cycle through, "KIND:TARGET" (the moment is drawn) or "KIND:TARGET@WHEN"
  /// (as given); default: every kind on every target of the UR5 cell.
  std::vector<std::string> faults;
  int count = 30;
  std::uint64_t seed = 1;           // trial i: seed + i (placement, noise, the moment)
  double window_s = 8.0;            // timed faults: a moment in [0, window) of simulated time
  int frames_per_detection = 15;    // camera faults: frame drawn in [1, frames x detections]
  double deadline_s = 1.0;          // FAILURE within this of the fault taking effect
  double rest_speed = 0.01;         // rad/s: the arm is at rest below this, on every joint
  double settle_s = 1.0;            // simulated after the run, then the arm must be at rest
  double time_limit_s = 60.0;       // simulated per run: beyond it the run counts as a hang
  std::filesystem::path scene;      // default sim/scenes/assembly.json
  std::filesystem::path waypoints;  // the cell's waypoint file: must stay unchanged
  int jobs = 1;
};

/// Every fault of the UR5 cell: each driver's and component's kinds.
std::vector<std::string> allFaults();
/// Every fault of the test cell (its components' kinds).
std::vector<std::string> testCellFaults();

struct FaultTrial {
  int index = 0;
  std::uint64_t seed = 0;
  std::string task;
  std::string fault;  // the spec, with its moment
  /// stopped: FAILURE in time, at rest, nothing lost (the target met);
  /// late / not-at-rest / lost-data / no-reason: FAILURE, but a criterion missed;
  /// not-due: the plan ended before the fault's moment; no-effect: due, but the broken
  /// device was not used again and the plan succeeded; missed: the fault took effect and
  /// the plan still succeeded; recovered: an operation threw and the plan recovered from
  /// its FAILURE (a Fallback) and succeeded; hang: the time limit ended the run; error: an exception
  /// escaped; other-failure: the run failed before the fault took effect.
  std::string outcome;
  std::string failure_path;
  std::string reason;
  double due_s = -1;         // simulated, when the fault became active
  double effect_s = -1;      // when a call was first answered faultily
  double end_s = -1;         // when the run ended
  double latency_s = -1;     // end - effect
  double rest_after_s = -1;  // after the end, until every joint is below rest_speed
  double final_speed = -1;   // rad/s, largest joint speed after settle_s
  bool waypoints_intact = true;
  double wall_s = 0;
  bool met() const { return outcome == "stopped"; }
  /// One run as a JSON object (a line of --jsonl, an entry of --json's "trials").
  nlohmann::json toJson() const;
  /// Reads what toJson wrote. @throws std::runtime_error "missing field 'F'" or "field 'F' must
  /// be ..., not V".
  static FaultTrial fromJson(const nlohmann::json& json);
};

struct CampaignSummary {
  CampaignOptions options;
  std::vector<FaultTrial> trials;
  nlohmann::json toJson() const;
  /// Per kind and per target: counts of outcomes, max and p99 time to FAILURE.
  std::string text() const;
};

/// The runs of a --jsonl file (one FaultTrial::toJson() a line; empty lines are skipped). A last
/// line cut short (the campaign was killed while writing it) is left out with a note in `notes`.
/// @throws std::runtime_error "FILE:LINE: PROBLEM" for a line that is not a run, naming the field.
CampaignSummary readJsonLines(const std::filesystem::path& file, std::vector<std::string>& notes);

/// Checks the numbers: count and jobs at least 1; window, deadline, settle time and time limit
/// numbers of seconds (core/clock.h checkedDuration), the window and time limit above 0; rest
/// speed and frames per detection positive.
/// @throws std::invalid_argument naming the option and the problem.
void checkOptions(const CampaignOptions& options);

/// @throws std::invalid_argument for an option out of range (checkOptions), std::runtime_error
/// before the first run for a missing plan or file.
CampaignSummary runCampaign(const CampaignOptions& options,
                            const std::function<void(const FaultTrial&, int done)>& progress = {});

}  // namespace costar::trials
