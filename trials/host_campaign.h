#pragma once
// The liveness campaign of remote components (issue 34): a simulated cell's gripper and
// perception served by a host in another process (`costar host`, in lockstep with the run's
// simulation), the host killed with SIGKILL at a moment drawn from the seed — during a
// DetectObjects, during an arm motion (Home, Move, MoveRelative, SmartGrasp, SmartRelease,
// SmartPush) or at the boundary between two operations — and every run judged from outside: it
// must end as FAILURE with a reason naming the host's component within a deadline (wall time
// from the kill), the arm must come to rest (the simulator's true joint velocities), nothing may
// hang, and the plan and waypoint files must be unchanged. The moment is found in a run of the
// same seed in one process (lockstep makes the two the same up to the kill) and taken in
// simulated time.

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace costar::trials {

struct HostCampaignOptions {
  std::string workcell = "ur5-sim";
  std::filesystem::path plan;  // default examples/ur5/assemble_structure.xml
  /// "detect", "move", "between": runs are spread over them in turn.
  std::vector<std::string> phases = {"detect", "move", "between"};
  int count = 3;           // runs in all
  std::uint64_t seed = 1;  // run i: seed + i (placement, noise, the moment)
  /// The host's command line up to its components (the campaign adds the components, the
  /// cell, --domain and --partition), e.g. {"/path/costar-robot", "host"}.
  std::vector<std::string> host_command;
  std::vector<std::string> components = {"gripper", "perception"};
  std::uint32_t domain = 74;        // DDS domain of the campaign's runs (each run a partition of its own)
  double deadline_s = 1.0;          // wall time from the kill to the run's FAILURE
  double rest_speed = 0.01;         // rad/s: the arm is at rest below this, on every joint
  double settle_s = 1.0;            // simulated after the run, then the arm must be at rest
  double time_limit_s = 120.0;      // simulated per run
  std::filesystem::path waypoints;  // a waypoint file the plan reads: must stay unchanged
};

struct HostKillRun {
  int index = 0;
  std::uint64_t seed = 0;
  std::string phase;
  std::string node;       // the operation running at the kill (or that just ended: between)
  double kill_at_s = -1;  // simulated
  /// stopped: FAILURE naming the component within the deadline, at rest, files intact;
  /// late / no-reason / not-at-rest / lost-data: FAILURE, but a criterion missed; success: the
  /// plan succeeded without its host; hang: the time limit ended it; not-killed: the run ended
  /// before the moment; error: an exception escaped.
  std::string outcome;
  std::string failure_path;
  std::string reason;
  double noticed_s = -1;    // wall time from the kill to the run's end
  double final_speed = -1;  // rad/s, largest joint speed after settle_s
  bool files_intact = true;
  double wall_s = 0;
  bool met() const { return outcome == "stopped"; }
  nlohmann::json toJson() const;
};

struct HostCampaignSummary {
  HostCampaignOptions options;
  std::vector<HostKillRun> runs;
  nlohmann::json toJson() const;
  /// Per phase: outcomes, median / p99 / max time to FAILURE.
  std::string text() const;
};

/// @throws std::invalid_argument for an unknown phase, no host command, or a count below 1.
HostCampaignSummary runHostCampaign(const HostCampaignOptions& options,
                                    const std::function<void(const HostKillRun&, int done)>& progress = {});

}  // namespace costar::trials
