#pragma once
// SmartMove's choice of a goal (the paper's Algorithm 2): for every object that matches, every
// symmetry s of its class and the relative transform T, the goal o * s * T; the cheapest
// feasible one wins. Every candidate keeps its cost or the reason it was rejected, so a person
// can see why the robot chose what it did.
//
// Cost (documented in docs/SMARTMOVE.md):
//   cost = joint_weight * sum |q_goal - q_now|        (how far the arm must turn, rad)
//        + tilt_weight * angle(tool z, world -z)      (prefer approaching from above, rad)
//        + travel_weight * |p_goal - p_tool|          (how far the tool travels, m)
// Feasibility is checked in order of cost, cheapest first, and stops at the first feasible
// candidate: the others are listed as "not checked".

#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "arm/joints.h"
#include "world/object_class.h"
#include "world/pose.h"

namespace costar::smartmove {

struct CostWeights {
  double joint = 1.0;
  double tilt = 1.0;
  double travel = 0.5;
};

struct Candidate {
  std::string object;
  int symmetry = 0;                            // index in the class's symmetries
  world::Pose goal = world::Pose::Identity();  // TCP in the world
  std::vector<arm::JointVector> solutions;     // IK, nearest first
  double cost = std::numeric_limits<double>::infinity();
  std::string rejected;  // why not; empty for the chosen one
  bool chosen = false;
  /// How far the fingers close before the approach (0 open .. 1, the gripper's units): above 0
  /// for a fingertip grasp that clears its neighbours only with the fingers closed part way.
  double finger_position = 0.0;
};

struct Selection {
  std::vector<Candidate> candidates;
  std::optional<std::size_t> chosen;
  /// Why no candidate works: the reasons counted, e.g. "48 candidates: 30 no IK solution, ...".
  std::string failure;
  double seconds = 0.0;
  bool ok() const { return chosen.has_value(); }
  /// Sets `failure` from the candidates' reasons (after candidates were added).
  void summarizeFailure();
  const Candidate& best() const { return candidates.at(*chosen); }
  nlohmann::json toJson() const;
};

/// What SmartMove needs of the arm: IK solutions for a TCP pose (nearest first), the tool's
/// pose now, and the joints now.
struct ArmModel {
  std::function<std::vector<arm::JointVector>(const world::Pose&)> solutions;
  world::Pose tool;
  arm::JointVector joints{};
};

/// Checks a candidate fully (collisions, path); returns the reason it fails, empty if it works.
using FeasibilityCheck = std::function<std::string(Candidate&)>;

/// Goals for each (object, pose) × symmetry of `object_class` × `relative` (T), then IK and
/// cost for all, then `feasible` in order of cost.
Selection selectGoal(const std::vector<std::pair<std::string, world::Pose>>& objects,
                     const world::ObjectClass& object_class, const world::Pose& relative, const ArmModel& arm,
                     const CostWeights& weights, const FeasibilityCheck& feasible);

/// As selectGoal, with candidate goals given directly (SmartRelease builds them itself).
Selection selectAmong(std::vector<Candidate> candidates, const ArmModel& arm, const CostWeights& weights,
                      const FeasibilityCheck& feasible);

}  // namespace costar::smartmove
