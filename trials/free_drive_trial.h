#pragma once
// A person guiding the arm by hand for a long while, judged from the simulator's true state
// (docs/TEACHING.md): a scripted random drag. The person's hand pulls the tool toward targets
// drawn from the seed over and beyond the table (a quarter of them under its top or into a part,
// which the arm must refuse), turns it toward drawn orientations, switches guiding modes and lets
// go of the dead-man now and then. Every 10 ms tick the judge reads the true joints, contacts and
// tool speed. `costar teach` runs it ('drag random MINUTES SEED'); a short one is a unit test.

#include <cstddef>
#include <cstdint>
#include <map>
#include <string>

namespace costar::workcell {
class Workcell;
}

namespace costar::trials {

struct FreeDriveTrialOptions {
  double seconds = 600.0;  // simulated
  std::uint64_t seed = 1;
  /// Switch guiding modes (free, translation, rotation, z locked) between holds; else free only.
  bool modes = true;
};

struct FreeDriveTrialResult {
  double seconds = 0.0;                      // simulated
  int holds = 0;                             // times the dead-man was held (FreeDrive operations)
  double travelled = 0.0;                    // m of the tool centre point
  std::uint64_t joint_limit_violations = 0;  // ticks with a joint beyond its limit
  double closest_to_limit = 0.0;             // rad: the least distance of a joint to its limit
  double max_departure = 0.0;                // rad: the joints' largest departure from those checked
  double least_dexterity = 0.0;              // m/rad: the arm's nearest a singularity (arm::dexterity), free-driving
  std::string least_dexterity_joints;        // the joints that lose the tool's motion there ("4, 6")
  std::uint64_t table_contact_steps = 0;     // physics steps with the arm or gripper on the table
  std::uint64_t part_contact_ticks = 0;      // ticks with the arm or gripper touching a part
  std::string first_part_contact;            // the first: which bodies, when
  double max_tool_speed = 0.0;               // m/s of the tool centre point (10 ms differences)
  double max_tracking = 0.0;                 // m: the tool's farthest from its reference (the protective stop's)
  double max_speed_at = 0.0;                 // s into the drag when it was reached
  bool max_speed_held = false;               // while the dead-man was held (else: after letting go)
  double lowest_tool = 0.0;                  // m: the tool centre point's lowest height above the table
  double max_stop_time = 0.0;                // s from letting go to the arm at rest (joints < 0.02 rad/s)
  std::map<std::string, int> blocked;        // why steps were refused, and how many ticks
  std::string failure;                       // an operation that failed (empty: none)
};

/// A stroke recorded by hand and replayed (FollowTrajectory), compared on the true tool poses.
struct ReplayTrialResult {
  double recorded_seconds = 0.0;
  double replay_seconds = 0.0;  // of the path, after the motion to its start
  double length = 0.0;          // m of the recorded stroke
  std::size_t samples = 0;      // recorded (every 10 ms)
  std::size_t kept = 0;         // after simplification
  double rms_position = 0.0;    // m: the replayed tool's distance to the recorded path (RMS)
  double max_position = 0.0;    // m
  double max_angle = 0.0;       // rad: its orientation against the recorded one's there
  std::string failure;
};

/// Guides the tool along a curved stroke of about 20 cm drawn from `seed` (a hand pulling it
/// along an arc, turning it a little), recorded as `name`, then replays it at `speed`.
ReplayTrialResult runReplayTrial(workcell::Workcell& cell, std::uint64_t seed, double speed = 1.0,
                                 const std::string& name = "stroke");

/// Runs the drag on `cell` (a simulated cell with free-drive). @throws std::invalid_argument for
/// a cell without a simulation or without FreeDrive.
FreeDriveTrialResult runFreeDriveTrial(workcell::Workcell& cell, const FreeDriveTrialOptions& options);

}  // namespace costar::trials
