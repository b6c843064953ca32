#include "smartmove/selection.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>

namespace costar::smartmove {

namespace {

double jointDistance(const arm::JointVector& a, const arm::JointVector& b) {
  double sum = 0.0;
  for (int j = 0; j < a.size(); ++j) {
    sum += std::abs(a[j] - b[j]);
  }
  return sum;
}

/// Reasons whose detail names what was false: the summary says which (the part and the
/// predicate), at most kNamedDetails of them.
constexpr const char* kPredicateFalse = "predicate false";
constexpr std::size_t kNamedDetails = 3;

std::string summarize(const std::vector<Candidate>& candidates) {
  struct Reason {
    int count = 0;
    std::vector<std::string> details;  // distinct, in the candidates' order
  };
  std::map<std::string, Reason> reasons;
  for (const Candidate& candidate : candidates) {
    if (candidate.rejected.empty()) {
      continue;
    }
    const std::size_t colon = candidate.rejected.find(':');
    Reason& reason = reasons[candidate.rejected.substr(0, colon)];
    ++reason.count;
    if (colon != std::string::npos && candidate.rejected.compare(0, colon, kPredicateFalse) == 0) {
      const std::size_t from = candidate.rejected.find_first_not_of(' ', colon + 1);
      const std::string detail = from == std::string::npos ? std::string() : candidate.rejected.substr(from);
      if (!detail.empty() && std::find(reason.details.begin(), reason.details.end(), detail) == reason.details.end()) {
        reason.details.push_back(detail);
      }
    }
  }
  std::string text = std::to_string(candidates.size()) + " candidate" + (candidates.size() == 1 ? "" : "s");
  if (candidates.empty()) {
    return "no candidates";
  }
  std::string details;
  for (const auto& [name, reason] : reasons) {
    details += (details.empty() ? "" : ", ") + std::to_string(reason.count) + " " + name;
    for (std::size_t d = 0; d < reason.details.size() && d < kNamedDetails; ++d) {
      details += (d == 0 ? ": " : "; ") + reason.details[d];
    }
    if (reason.details.size() > kNamedDetails) {
      details += "; " + std::to_string(reason.details.size() - kNamedDetails) + " more";
    }
  }
  return text + ", none feasible (" + details + ")";
}

}  // namespace

Selection selectAmong(std::vector<Candidate> candidates, const ArmModel& arm, const CostWeights& weights,
                      const FeasibilityCheck& feasible) {
  const auto start = std::chrono::steady_clock::now();
  Selection selection;
  std::vector<std::size_t> order;
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    Candidate& candidate = candidates[i];
    candidate.solutions = arm.solutions(candidate.goal);
    if (candidate.solutions.empty()) {
      candidate.rejected = "no IK solution: out of reach or beyond the joint limits";
      continue;
    }
    const Eigen::Vector3d tool_z = candidate.goal.linear().col(2);
    const double tilt = std::acos(std::clamp(-tool_z.z(), -1.0, 1.0));
    candidate.cost = weights.joint * jointDistance(candidate.solutions.front(), arm.joints) + weights.tilt * tilt +
                     weights.travel * (candidate.goal.translation() - arm.tool.translation()).norm();
    order.push_back(i);
  }
  std::stable_sort(order.begin(), order.end(),
                   [&candidates](std::size_t a, std::size_t b) { return candidates[a].cost < candidates[b].cost; });
  for (const std::size_t i : order) {
    Candidate& candidate = candidates[i];
    if (selection.chosen) {
      candidate.rejected = "not checked: a cheaper candidate works";
      continue;
    }
    candidate.rejected = feasible(candidate);
    if (candidate.rejected.empty()) {
      candidate.chosen = true;
      selection.chosen = i;
    }
  }
  selection.candidates = std::move(candidates);
  selection.summarizeFailure();
  selection.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return selection;
}

Selection selectGoal(const std::vector<std::pair<std::string, world::Pose>>& objects,
                     const world::ObjectClass& object_class, const world::Pose& relative, const ArmModel& arm,
                     const CostWeights& weights, const FeasibilityCheck& feasible) {
  std::vector<Candidate> candidates;
  candidates.reserve(objects.size() * object_class.symmetries.size());
  for (const auto& [name, pose] : objects) {
    for (std::size_t s = 0; s < object_class.symmetries.size(); ++s) {
      world::Pose symmetry = world::Pose::Identity();
      symmetry.linear() = object_class.symmetries[s];
      Candidate candidate;
      candidate.object = name;
      candidate.symmetry = static_cast<int>(s);
      candidate.goal = pose * symmetry * relative;
      candidates.push_back(std::move(candidate));
    }
  }
  return selectAmong(std::move(candidates), arm, weights, feasible);
}

void Selection::summarizeFailure() {
  if (!chosen) {
    failure = summarize(candidates);
  }
}

nlohmann::json Selection::toJson() const {
  nlohmann::json list = nlohmann::json::array();
  for (const Candidate& candidate : candidates) {
    const Eigen::Vector3d& p = candidate.goal.translation();
    nlohmann::json item = {{"object", candidate.object},
                           {"symmetry", candidate.symmetry},
                           {"goal", {p.x(), p.y(), p.z()}},
                           {"chosen", candidate.chosen}};
    if (std::isfinite(candidate.cost)) {
      item["cost"] = candidate.cost;
    }
    if (!candidate.rejected.empty()) {
      item["rejected"] = candidate.rejected;
    }
    if (candidate.finger_position > 0.0) {
      item["finger_position"] = candidate.finger_position;
    }
    list.push_back(std::move(item));
  }
  nlohmann::json json = {{"candidates", std::move(list)}, {"seconds", seconds}};
  if (chosen) {
    json["chosen"] = candidates[*chosen].object;
  } else {
    json["failure"] = failure;
  }
  return json;
}

}  // namespace costar::smartmove
