#include "trials/judge.h"

#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "trials/wire_judge.h"

namespace costar::trials {

namespace {

constexpr double kNodeHalf = 0.025;
constexpr double kLinkHalfHeight = 0.0125;

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

}  // namespace

std::vector<JudgeInfo> judges() {
  return {{"lift", "task 1: a node is held 5 cm above the table"},
          {"right_to_left", "task 2: two nodes moved from the right to the left of table_center"},
          {"assembly", "task 3: node on the table (left), link on it, node on the link"},
          {"blind_place", "node_0 within 1 cm of (0.45, 0.25), the blind pick-and-place example"},
          {"wire_bending",
           "every bend of the jig's drawing within 5 degrees after release, the wire never pulled "
           "out of the gripper, no pin moved (examples/iiwa/wire_bending.xml)"}};
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
  std::string known;
  for (const auto& info : judges()) {
    known += (known.empty() ? "" : ", ") + info.name;
  }
  throw std::invalid_argument("unknown judge '" + name + "' (known: " + known + ")");
}

}  // namespace costar::trials
