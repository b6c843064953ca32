#pragma once
// Reruns a task plan as N randomized trials in the simulated cell (parts placed at random in
// the scene's regions with any yaw, fresh sensor noise, a different seed per trial), judges
// each from the simulator's true state, and summarizes: success rate, failures by node and
// reason, cycle times. The paper's evaluation, repeatable with one command.

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace costar::trials {

struct ToolTrace;  // trials/tool_plot.h

struct TrialOptions {
  std::filesystem::path plan;
  /// The simulated workcell the trials run in (workcells/NAME.json).
  std::string workcell = "ur5-sim";
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
  /// This run's slice of the trials, for spreading them over machines: trials i with
  /// i % shard_count == shard_index (trial i keeps seed + i whichever shard runs it).
  int shard_index = 0;
  int shard_count = 1;
  /// Faults to inject in every trial (faults/fault.h grammar); random moments are drawn from
  /// the trial's seed.
  std::vector<std::string> inject;
  /// Disturbances of the simulated world in every trial (trials/disturbance.h grammar: nudge,
  /// take-away, drop-frame), drawn from the trial's seed.
  std::vector<std::string> disturb;
  /// When set, every trial's status transitions are written to trace_dir/trial_SEED.jsonl
  /// (bt/trace.h JSON lines: each node's failure reason, also of failures a retry recovered).
  std::filesystem::path trace_dir;
  /// A JSON file naming the cell's components served by hosts (`costar host`) in lockstep with
  /// each trial's simulation (workcell::WorkcellOptions::remote); empty: as the cell says.
  /// A host serves one run at a time: with it, trials run one at a time (jobs 1).
  std::filesystem::path remote;
};

/// A trial's speed and separation record, in a scene with a person (sim::SeparationRecord).
struct SeparationFigures {
  double min_separation_fast_m = 0.0;  // the smallest separation while the arm moved faster than 0.25 m/s
  double min_margin_fast_m = 0.0;      // the smallest separation less S_p then
  std::uint64_t violation_steps = 0;   // physics steps below S_p while faster
  std::uint64_t contact_steps = 0;     // physics steps touching the person, the arm moving
  double max_contact_n = 0.0;
  std::uint64_t stopped_contact_steps = 0;  // the person running into the stopped arm
  int stops = 0;                            // protective stops
  double stopped_s = 0.0;
  /// In collaborative mode (a hand-over): its time, and the steps touching the person's hand
  /// while the arm moved in it with the largest force (contact outside the hand: contact_steps).
  double collaborative_s = 0.0;
  std::uint64_t hand_contact_steps = 0;
  double max_hand_contact_n = 0.0;
};

struct TrialResult {
  int index = 0;
  std::uint64_t seed = 0;
  bool success = false;
  /// On failure: the failing node's path (or "judge") and the reason; on success, what the
  /// judge found ("bends 91.2, -89.4 degrees; ..."; the JSON's "judged").
  std::string failure_path;
  std::string reason;
  double cycle_time_s = 0.0;  // simulated
  double wall_s = 0.0;
  /// What the disturbances did (trials/disturbance.h), one line each.
  std::vector<std::string> disturbances;
  /// The process's resident memory (kB) when the trial ended (0: unknown), for soak runs.
  long rss_kb = 0;
  /// With --calibrate: the farthest any part moved while Calibrate ran (m; the arm knows no
  /// part before the camera is calibrated, so this is how much it disturbed the table).
  std::optional<double> calibrate_moved_part_m;
  /// Stopped midway by a stop request (runTrials' `stop`): not a result, left out of the summary.
  bool interrupted = false;
  /// Not started: the stop came first.
  bool started = true;
  /// The trial's --trace could not be written: "cannot write 'FILE': ERROR" (the trial ran).
  std::string trace_error;
  /// With a person in the scene: the separation record. A trial with a violation of the
  /// protective distance or contact while the arm moved fails ("safety").
  std::optional<SeparationFigures> separation;
  /// The power tool's record (sim/power_tool.h) of the batch's first trial in a scene with a
  /// workpiece, for writePlot's force and coverage pictures; not in the JSON.
  std::shared_ptr<const ToolTrace> tool;
};

struct Summary {
  TrialOptions options;
  /// The trials this summary holds, by index (a shard holds every shard_count-th).
  std::vector<TrialResult> trials;
  /// A stop request (SIGINT, SIGTERM) ended the batch early: `trials` holds the trials that
  /// finished, of `planned`; `cancelled` the indices of those stopped midway (not results; their
  /// traces end where they stopped). An interrupted summary is not merged.
  bool interrupted = false;
  int planned = 0;
  std::vector<int> cancelled;
  /// Fingerprints (core/files.h) of what the trials read, by name: "plan" (with its included
  /// files), "scene", "waypoints"; shards of one batch must agree on them.
  std::map<std::string, std::string> fingerprints;
  int successes() const;
  /// Failures grouped by node path and reason, numbers masked ("# candidates"), most first.
  std::vector<std::pair<std::string, int>> failureHistogram() const;
  /// Cycle times of the successful trials: min, median, p95, max, mean.
  std::map<std::string, double> cycleTimes() const;
  /// Resident memory (kB) after every 100th trial (index 99, 199, ...) and after the last one,
  /// by trial count; growth from trial 100 to the last, in per cent (0 with fewer than 101).
  std::vector<std::pair<int, long>> residentMemory() const;
  double residentGrowthPercent() const;
  nlohmann::json toJson() const;
  std::string text() const;
  /// Reads what toJson wrote. @throws std::runtime_error naming the field and the problem.
  static Summary fromJson(const nlohmann::json& json);
};

/// Checks the numbers: count and jobs at least 1, time limit a finite number of seconds above 0
/// (at most kMaxTimeLimitSeconds), settle time finite and not negative, camera move finite, from
/// 0 to 0.5 m and 45 degrees. @throws std::invalid_argument naming the option and the problem.
void checkOptions(const TrialOptions& options);
inline constexpr double kMaxTimeLimitSeconds = 1e6;

/// Combines shard summaries of one batch into the summary a single run would give. Shards of
/// one batch agree on every option that affects outcomes (plan, workcell, scene, judge, first
/// seed, count, time limit, settle time, waypoints, faults, disturbances, camera move,
/// calibrate) and on the fingerprints of the files read. @throws std::runtime_error naming the
/// option and both values when they do not, for an interrupted shard, when a trial appears
/// twice, or when trials are missing (listing the first missing ones).
Summary mergeShards(const std::vector<Summary>& shards);

/// Runs the trials; `progress` is called as each one ends (from the trial's thread, one at a
/// time). Once `*stop` is set (a signal handler's flag) no trial starts, the running ones are
/// stopped at their next tick (their operations cancelled, the arm stopped), and the summary of
/// the trials that finished is returned, marked interrupted.
/// @throws std::invalid_argument or std::runtime_error before the first trial when an
/// option is out of range (checkOptions), the plan is invalid or a file is missing.
Summary runTrials(const TrialOptions& options, const std::function<void(const TrialResult&, int done)>& progress = {},
                  const std::atomic<bool>* stop = nullptr);

/// The scene the trials read: options.scene, or the workcell's default scene (an absolute path
/// under the data root, wherever the command runs). @throws std::runtime_error for an unknown
/// workcell.
std::filesystem::path effectiveScene(const TrialOptions& options);

/// Writes Summary::toJson() to `file` (core/files.h writeOutputFile): atomically for a regular
/// file (a crash leaves the old file or the new one), straight through for a device such as
/// /dev/stdout; every write checked. @throws std::runtime_error naming the file and the system
/// error.
void writeJson(const Summary& summary, const std::filesystem::path& file);

/// A PNG a person can read: success rate, failures by reason, cycle-time histogram. When a trial
/// kept the power tool's record (a polishing scene), also PLOT_force.png and PLOT_coverage.png
/// beside it (trials/tool_plot.h); returns the files written.
/// @throws std::runtime_error naming the file when it cannot be written.
std::vector<std::filesystem::path> writePlot(const Summary& summary, const std::filesystem::path& png);

}  // namespace costar::trials
