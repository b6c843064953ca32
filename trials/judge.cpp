#include "trials/judge.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <stdexcept>

#include "trials/wire_judge.h"

namespace costar::trials {

namespace {

constexpr double kNodeHalf = 0.025;
constexpr double kLinkHalfHeight = 0.0125;
// The simulated cells' table (workcells/*.json "table": centre x 0.4, 1.4 by 1.2 m): the
// simulator's table top is an endless plane, so a part resting beyond these edges fell off it.
constexpr double kTableNear = -0.3;
constexpr double kTableFar = 1.1;
constexpr double kTableHalfWidth = 0.6;
constexpr double kCarriedAway = 0.6;  // m beyond the table's edge

std::string millimetres(double metres) {
  char text[32];
  std::snprintf(text, sizeof text, "%.0f mm", metres * 1000);
  return text;
}

bool atRest(const sim::PartState& part) { return part.linear_velocity.norm() < 0.01; }

/// Whether `part` lies flat (its z axis, or for a link its x axis, horizontal as placed):
/// the part's frame z is vertical for a node (any face down is fine, the cube is symmetric).
double heightAbove(const sim::PartState& part, double support_top, double half_height) {
  return part.pose.translation().z() - support_top - half_height;
}

Verdict lift(sim::Simulation& simulation, const std::vector<sim::PartState>&) {
  const auto contacts = simulation.contacts();
  for (const auto& part : simulation.parts()) {
    if (part.object_class != "node") {
      continue;
    }
    const bool held = std::count_if(contacts.begin(), contacts.end(), [&part](const auto& pair) {
                        return (pair.first == part.name && pair.second.find("finger") != std::string::npos) ||
                               (pair.second == part.name && pair.first.find("finger") != std::string::npos);
                      }) >= 2;
    if (held && part.pose.translation().z() > kNodeHalf + 0.05) {
      return {true, part.name + " held " + millimetres(part.pose.translation().z() - kNodeHalf) + " above the table"};
    }
  }
  return {false, "no node is held 5 cm above the table"};
}

Verdict rightToLeft(sim::Simulation& simulation, const std::vector<sim::PartState>& initial) {
  int moved = 0;
  for (const auto& part : simulation.parts()) {
    if (part.object_class != "node") {
      continue;
    }
    const auto start = std::find_if(initial.begin(), initial.end(), [&](const auto& p) { return p.name == part.name; });
    const bool started_right = start != initial.end() && start->pose.translation().y() < 0.0;
    const bool rests_left =
        part.pose.translation().y() > 0.02 && std::abs(part.pose.translation().z() - kNodeHalf) < 0.005 && atRest(part);
    moved += started_right && rests_left ? 1 : 0;
  }
  if (moved >= 2) {
    return {true, std::to_string(moved) + " nodes moved from the right to the left"};
  }
  return {false, std::to_string(moved) + " of 2 nodes were moved from the right to the left"};
}

Verdict assembly(sim::Simulation& simulation, const std::vector<sim::PartState>&) {
  const auto parts = simulation.parts();
  std::string closest = "no node rests on the table left of table_center";
  for (const auto& base : parts) {
    if (base.object_class != "node" || base.pose.translation().y() <= 0.02 ||
        std::abs(heightAbove(base, 0.0, kNodeHalf)) > 0.005 || !atRest(base)) {
      continue;
    }
    closest = "no link rests on the base node " + base.name;
    for (const auto& link : parts) {
      if (link.object_class != "link" || !atRest(link) ||
          (link.pose.translation() - base.pose.translation()).head<2>().norm() > 0.02 ||
          std::abs(heightAbove(link, 2 * kNodeHalf, kLinkHalfHeight)) > 0.006) {
        continue;
      }
      closest = "no node rests on " + link.name + " (on " + base.name + ")";
      for (const auto& top : parts) {
        if (top.object_class != "node" || top.name == base.name || !atRest(top) ||
            (top.pose.translation() - link.pose.translation()).head<2>().norm() > 0.02 ||
            std::abs(heightAbove(top, 2 * kNodeHalf + 2 * kLinkHalfHeight, kNodeHalf)) > 0.006) {
          continue;
        }
        return {true, "structure: " + base.name + " / " + link.name + " / " + top.name};
      }
    }
  }
  return {false, closest};
}

Verdict blindPlace(sim::Simulation& simulation, const std::vector<sim::PartState>&) {
  for (const auto& part : simulation.parts()) {
    if (part.name == "node_0") {
      const double error = (part.pose.translation() - Eigen::Vector3d(0.45, 0.25, kNodeHalf)).norm();
      if (error < 0.01 && atRest(part)) {
        return {true, "node_0 placed within " + millimetres(error)};
      }
      return {false, "node_0 is " + millimetres(error) + " from the place spot"};
    }
  }
  return {false, "there is no node_0"};
}

bool isHandLabel(const std::string& label) {
  return label == "person_hand" || label == "person_fingers" || label == "person_thumb";
}

Verdict collaborativeAssembly(sim::Simulation& simulation, const std::vector<sim::PartState>& initial) {
  const auto contacts = simulation.contacts();
  int handed = 0;
  int placed = 0;
  int nodes = 0;
  for (const auto& part : simulation.parts()) {
    const auto start = std::find_if(initial.begin(), initial.end(), [&](const auto& p) { return p.name == part.name; });
    if (part.object_class != "node" || start == initial.end() || start->pose.translation().y() >= 0.0) {
      continue;
    }
    ++nodes;
    const Eigen::Vector3d at = part.pose.translation();
    const bool in_hand =
        at.z() > kNodeHalf + 0.03 && std::any_of(contacts.begin(), contacts.end(), [&part](const auto& pair) {
          return (pair.first == part.name && isHandLabel(pair.second)) ||
                 (pair.second == part.name && isHandLabel(pair.first));
        });
    const bool in_assembly_area = at.y() > 0.02 && at.y() < kTableHalfWidth && at.x() > kTableNear &&
                                  at.x() < kTableFar && std::abs(heightAbove(part, 0.0, kNodeHalf)) < 0.005 &&
                                  atRest(part);
    // Beyond the table on the person's side, where only a person walking away with it takes it
    // (sim/person.h "leave": 1.5 m; "open" there puts it down).
    const bool carried_away = at.y() > kTableHalfWidth + kCarriedAway;
    if (in_hand || carried_away) {
      ++handed;
    } else if (in_assembly_area) {
      ++placed;
    } else {
      char where[96];
      std::snprintf(where, sizeof where, " (%.3f, %.3f, %.3f)", at.x(), at.y(), at.z());
      const bool untouched = (at - start->pose.translation()).norm() < 0.005;
      return {false, part.name + (untouched ? " was never moved from the input area" + std::string(where)
                                            : " is neither in the person's hand nor resting in the assembly area: at" +
                                                  std::string(where))};
    }
  }
  if (nodes == 0) {
    return {false, "no node started right of table_center"};
  }
  return {true, std::to_string(handed) + " handed over, " + std::to_string(placed) + " put in the assembly area"};
}

constexpr double kPolishForce = kPolishingForce;
constexpr double kPolishBand = kPolishingBand;
constexpr double kTouching = 0.5;          // N: the pad touches the workpiece
constexpr double kResumeTolerance = 0.02;  // m: polishing resumes this near where it stopped

std::string percent(double fraction) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f %%", 100.0 * fraction);
  return text;
}

Verdict polishing(sim::Simulation& simulation, const std::vector<sim::PartState>&) {
  const sim::SimPowerTool* tool = simulation.powerTool();
  if (tool == nullptr || !tool->coverage() || !tool->hasTool()) {
    return {false, "the scene has no power tool on its stand or no workpiece (sim/scenes/polishing.json)"};
  }
  const std::vector<sim::PowerToolSample>& log = tool->log();
  const double coverage = tool->coverage()->fraction();
  // The pad's force while it touches the workpiece.
  int touching = 0;
  int in_band = 0;
  for (const sim::PowerToolSample& sample : log) {
    if (sample.pad_force > kTouching) {
      ++touching;
      in_band += std::abs(sample.pad_force - kPolishForce) <= kPolishBand ? 1 : 0;
    }
  }
  const double band = touching > 0 ? static_cast<double>(in_band) / touching : 0.0;
  const ToolLosses losses = toolLosses(log);
  if (!losses.problem.empty()) {
    return {false, losses.problem};
  }
  char summary[320];
  std::snprintf(summary, sizeof summary,
                "coverage %s, force within %.0f +/- %.0f N %s of %.1f s touching, %d loss(es) of the tool: off and "
                "still after %.2f s at most, resumed %.0f mm from where it stopped at most, arm on the workpiece %llu "
                "steps",
                percent(coverage).c_str(), kPolishForce, kPolishBand, percent(band).c_str(), touching * 0.01,
                losses.count, losses.slowest_stop, losses.farthest_resume * 1000.0,
                static_cast<unsigned long long>(tool->armWorkpieceSteps()));
  std::string problem;
  if (coverage < 0.95) {
    problem = "coverage " + percent(coverage) + " is below 95 %";
  } else if (band < 0.90) {
    problem = "the pad's force was within " + std::to_string(static_cast<int>(kPolishForce)) + " +/- " +
              std::to_string(static_cast<int>(kPolishBand)) + " N only " + percent(band) + " of the time it touched";
  } else if (tool->armWorkpieceSteps() > 0) {
    problem = "the arm touched the workpiece";
  } else if (!log.empty() && log.back().powered) {
    problem = "the tool was still on at the end";
  }
  if (!problem.empty()) {
    return {false, problem + " (" + summary + ")"};
  }
  return {true, summary};
}

}  // namespace

ToolLosses toolLosses(const std::vector<sim::PowerToolSample>& log) {
  ToolLosses losses;
  for (std::size_t i = 1; i < log.size(); ++i) {
    if (!(log[i - 1].held && !log[i].held && log[i].away)) {
      continue;
    }
    ++losses.count;
    const double lost_at = log[i].time;
    std::optional<double> stopped;
    for (std::size_t k = i; k < log.size() && log[k].time <= lost_at + 1.0 + 1e-9; ++k) {
      if (!log[k].powered && log[k].arm_speed < 0.02) {
        stopped = log[k].time - lost_at;
        break;
      }
    }
    if (!stopped) {
      losses.problem = "the tool was taken out of the gripper at " + std::to_string(lost_at).substr(0, 6) +
                       " s, and 1 s later it was still on or the arm still moving";
      return losses;
    }
    losses.slowest_stop = std::max(losses.slowest_stop, *stopped);
    if (!log[i - 1].powered) {
      continue;  // off when it was taken: the plan had stopped polishing (its passes done, ToolOff)
    }
    std::optional<Eigen::Vector2d> last_worked;
    for (std::size_t k = i; k-- > 0 && log[k].time >= lost_at - 0.5;) {
      if (log[k].working) {
        last_worked = log[k].pad;
        break;
      }
    }
    if (!last_worked) {
      continue;  // it was not polishing when it was taken
    }
    const auto resumed = std::find_if(log.begin() + static_cast<std::ptrdiff_t>(i), log.end(),
                                      [](const sim::PowerToolSample& sample) { return sample.working; });
    if (resumed == log.end()) {
      losses.problem = "polishing stopped when the tool was taken at " + std::to_string(lost_at).substr(0, 6) +
                       " s and never resumed";
      return losses;
    }
    const double distance = (resumed->pad - *last_worked).norm();
    // Away from where it stopped: right when the pass it was on was done and the next one starts
    // on ground not polished before the loss; wrong when it goes back over that ground.
    const bool over_polished =
        std::any_of(log.begin(), log.begin() + static_cast<std::ptrdiff_t>(i), [&](const sim::PowerToolSample& sample) {
          return sample.working && (sample.pad - resumed->pad).norm() <= kResumeTolerance;
        });
    losses.farthest_resume = std::max(losses.farthest_resume, distance);
    if (distance > kResumeTolerance && over_polished) {
      losses.problem = "polishing resumed " + millimetres(distance) +
                       " from where it stopped (more than 20 mm), over ground it had polished";
      return losses;
    }
  }
  return losses;
}

std::vector<JudgeInfo> judges() {
  return {{"lift", "task 1: a node is held 5 cm above the table"},
          {"right_to_left", "task 2: two nodes moved from the right to the left of table_center"},
          {"assembly", "task 3: node on the table (left), link on it, node on the link"},
          {"blind_place", "node_0 within 1 cm of (0.45, 0.25), the blind pick-and-place example"},
          {"wire_bending",
           "every bend of the jig's drawing within 5 degrees after release, the wire never pulled "
           "out of the gripper, no pin moved (examples/iiwa/wire_bending.xml)"},
          {"polishing",
           "the sanding/polishing task (examples/iiwa/polishing.xml): marked area worked >= 95 %, pad force 10 +/- 4 N "
           ">= 90 % of the time it touches, off and still within 1 s of losing the tool, resumed within 20 mm, the arm "
           "never on the workpiece"},
          {"collaborative_assembly",
           "every node from the right of table_center handed to the person (held off the table in their hand) or "
           "resting on the table left of it, none elsewhere (examples/iiwa/collaborative_assembly.xml)"}};
}

Judge judge(const std::string& name) {
  if (name == "lift") {
    return lift;
  }
  if (name == "right_to_left") {
    return rightToLeft;
  }
  if (name == "assembly") {
    return assembly;
  }
  if (name == "blind_place") {
    return blindPlace;
  }
  if (name == "wire_bending") {
    return wireBending;
  }
  if (name == "polishing") {
    return polishing;
  }
  if (name == "collaborative_assembly") {
    return collaborativeAssembly;
  }
  std::string known;
  for (const auto& info : judges()) {
    known += (known.empty() ? "" : ", ") + info.name;
  }
  throw std::invalid_argument("unknown judge '" + name + "' (known: " + known + ")");
}

}  // namespace costar::trials
