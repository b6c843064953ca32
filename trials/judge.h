#pragma once
// Judges of the paper's evaluation tasks: each decides success from the simulator's TRUE final
// state (part poses, contacts), never from what the plan believes.

#include <functional>
#include <string>
#include <vector>

#include "sim/power_tool.h"
#include "sim/simulation.h"

namespace costar::trials {

struct Verdict {
  bool success = false;
  std::string reason;  // why not (or what was achieved)
};

/// Judges the end of a trial, given the parts as they were at its start.
using Judge = std::function<Verdict(sim::Simulation& simulation, const std::vector<sim::PartState>& initial)>;

struct JudgeInfo {
  std::string name;
  std::string description;
};

/// "lift" (task 1): some node is held at least 5 cm above the table by the fingers.
/// "right_to_left" (task 2): at least two nodes that started right of table_center (y < 0)
///   rest on the table left of it (y > 0.02).
/// "assembly" (task 3): a node rests on the table left of table_center, a link rests on it
///   (centred within 2 cm), a node rests on the link (centred within 2 cm), all at rest.
/// "blind_place": node_0 rests within 1 cm of (0.45, 0.25) (examples/ur5/blind_pick_place.xml).
/// "wire_bending": the scene's wire bent to its jig's drawing (trials/wire_judge.h).
/// "polishing" (the paper's Fig. 7, examples/iiwa/polishing.xml): from the power tool's record
///   (sim/power_tool.h): >= 95 % of the marked area worked; the pad's force within 10 +/- 4 N for
///   >= 90 % of the time it touches the workpiece; each time the tool is taken out of the gripper,
///   the tool off and the arm still (joints < 0.02 rad/s) within 1 s, and polishing, if it was
///   under way, resumed within 20 mm of where it stopped (or, its pass done, on ground it had not
///   polished yet: the next pass's start); the arm never on the workpiece; the tool off at the end.
/// "collaborative_assembly" (the paper's third iiwa task, examples/iiwa/collaborative_assembly.xml):
///   every node that started right of table_center (y < 0) is either the person's (held by their
///   hand: touching the palm, fingers or thumb, its centre 3 cm or more above its resting height;
///   or carried off: more than 0.6 m beyond the table's edge, where only the person walking away
///   takes it) or rests on the table left of table_center (y > 0.02, on the table); any other
///   node fails the trial, named.
std::vector<JudgeInfo> judges();

/// What the polishing judge finds of the tool's losses in the power tool's 100 Hz log: each time
/// the tool left the gripper without being put on its stand.
struct ToolLosses {
  int count = 0;
  double slowest_stop = 0.0;     // s from a loss until the tool was off and the arm still
  double farthest_resume = 0.0;  // m from where polishing stopped to where it resumed (the next
                                 // pass's start when the pass it was on was done)
  std::string problem;           // empty when every loss was handled
};
ToolLosses toolLosses(const std::vector<sim::PowerToolSample>& log);
/// The polishing judge's force and band (N): the plan presses with 10 N.
inline constexpr double kPolishingForce = 10.0;
inline constexpr double kPolishingBand = 4.0;
/// @throws std::invalid_argument naming the known judges.
Judge judge(const std::string& name);

}  // namespace costar::trials
