#pragma once
// Disturbances during a trial, as a technician who moves parts around causes them (issue 12):
// the simulated world is changed under the running plan, never the robot's belief; each is
// drawn from the trial's seed. A disturbance reads
//   KIND[@grasp=N]
//   nudge       the part about to be grasped is pushed 1-3 cm in a random direction and turned
//               by up to 15 degrees, as the gripper starts down toward it (a free spot: it does
//               not land on a neighbour)
//   take-away   the part about to be grasped is taken off the table at that moment
//   drop-frame  one camera frame of one DetectObjects comes empty (the fault injector's
//               drop-frame:camera@op=N, N drawn from the seed among the plan's first frames)
//   add         a part is put on the table at a free place, as the gripper starts down toward
//               another (its class drawn from the seed among the cell's spare parts, parked
//               off the table from the start: the simulator's bodies are fixed once loaded)
//   take-tool   the power tool is taken (out of the gripper, or off its stand: wherever it is)
//               at a moment drawn from the seed within the polishing plan's span (1 to 19 s
//               into the trial: undisturbed, examples/iiwa/polishing.xml picks the tool up from
//               its stand until 5 s, runs it from 6 to 19.5 s and ends at 22 s, so every trial
//               is disturbed while the plan works; "@within=A-B": A to B seconds; "@at=S": S
//               seconds) and given back onto its stand 2 to 8 s later (sim/power_tool.h)
// "@grasp=N" picks the N-th approach to a part (default: 1 to 3, drawn from the seed).
// An approach is the tool going down over a part resting on the table with the fingers open
// and empty, within 3 cm of its centre, 4 to 9 cm above it (just past the pre-grasp pose).

#include <cstdint>
#include <optional>
#include <random>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace costar::sim {
class Simulation;
}

namespace costar::trials {

enum class DisturbanceKind { kNudge, kTakeAway, kDropFrame, kAdd, kTakeTool };

/// take-tool's default window (s into the trial): within the polishing plan's span (above).
inline constexpr std::pair<double, double> kTakeToolWindow{1.0, 19.0};

struct DisturbanceSpec {
  DisturbanceKind kind = DisturbanceKind::kNudge;
  /// The approach disturbed (1-based); 0: drawn from the seed in 1..3.
  int grasp = 0;
  /// take-tool: when (simulated seconds); absent: drawn from the seed within `within`.
  std::optional<double> at_seconds;
  /// take-tool: the window its moment is drawn in (simulated seconds).
  std::pair<double, double> within = kTakeToolWindow;
  std::string text;  // as written
};

/// Parses "nudge", "take-away@grasp=2", "drop-frame", "take-tool@at=20", "take-tool@within=2-10". @throws
/// std::invalid_argument naming the spec and the problem.
DisturbanceSpec parseDisturbance(std::string_view text);
/// The grammar in a few lines, for --help.
std::string disturbanceGrammar();

/// Applies disturbances to one trial's simulation. Call watch() before every tick.
class Disturber {
 public:
  Disturber(std::vector<DisturbanceSpec> specs, std::uint64_t seed);

  /// Fault specs (faults/fault.h grammar) the trial's cell must inject for the camera's
  /// disturbances (drop-frame), drawn from the seed.
  std::vector<std::string> faultSpecs() const { return faults_; }
  /// How many `add` disturbances there are: the trial's cell needs that many spare parts of
  /// every class (sim::SimulationOptions::spare_classes).
  int additions() const;
  /// Looks at the simulation's true state and disturbs it when a disturbance is due.
  void watch(sim::Simulation& simulation);
  /// What was done, one line each ("nudge node_1: 23 mm, -7 deg at 12.3 s"), for the trial's
  /// record; a disturbance never due is listed as "not applied".
  std::vector<std::string> events() const;

  /// Frames the drawn drop-frame fault lands among: three DetectObjects of 15 frames.
  static constexpr int kFramesDrawn = 45;

 private:
  struct Pending {
    DisturbanceSpec spec;
    int approach = 1;
    bool done = false;
    std::string event;
    // take-tool: when it is taken, how long it stays away, and whether it is away now.
    double take_at = 0.0;
    double away_for = 0.0;
    bool taken = false;
  };
  void takeTool(sim::Simulation& simulation, Pending& pending);
  void nudge(sim::Simulation& simulation, Pending& pending, const std::string& part);
  void takeAway(sim::Simulation& simulation, Pending& pending, const std::string& part);
  void add(sim::Simulation& simulation, Pending& pending);

  std::vector<Pending> pending_;
  std::vector<std::string> faults_;
  std::mt19937_64 random_;
  int approaches_ = 0;
  std::string approaching_;  // the part approached at the last watch, if any
  double last_tcp_z_ = 1e9;
  int taken_ = 0;
};

}  // namespace costar::trials
