// SmartMove's choice (the paper's Algorithm 2 over parts, symmetries and, when no centred grasp
// works, grasps shifted across the fingers): every query of a candidate carries its scene,
// the fingers standing as the grasp will have them.

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include "smartmove/script.h"
#include "smartmove/smartmove.h"

namespace costar::smartmove {

SmartMoveComponent::Matches SmartMoveComponent::matching(const std::string& object_class,
                                                         const std::vector<predicator::Pattern>& patterns,
                                                         const std::string& exclude) const {
  Matches matches;
  const std::vector<std::string> is_a{"?", object_class};
  for (const std::string& object : world_.match("is_a", is_a)) {
    const auto pose = world_.worldPose(object);
    if (object == exclude || !pose) {
      continue;
    }
    std::string failing;
    for (const auto& pattern : patterns) {
      std::vector<std::string> args = pattern.args;
      std::replace(args.begin(), args.end(), std::string("?"), object);
      if (!world_.holds(pattern.predicate, args)) {
        failing = world::predicateKey(pattern.predicate, args) + " is false";
        break;
      }
    }
    if (failing.empty()) {
      matches.objects.emplace_back(object, *pose);
    } else {
      matches.rejected.emplace_back(object, failing);
    }
  }
  return matches;
}

std::optional<double> SmartMoveComponent::graspOpening(const world::Pose& tcp, const world::Pose& object,
                                                       const world::ObjectClass& object_class) const {
  return fingers_.graspOpening(partHalfWidth(tcp, object, object_class), config_.grasp_margin);
}

double SmartMoveComponent::partHalfWidth(const world::Pose& tcp, const world::Pose& object,
                                         const world::ObjectClass& object_class) const {
  // The part's boxes in the tool's frame: their extent along y, either side of the TCP. A box
  // wholly beyond the finger pads' reach along the approach is not between the fingers (the
  // sander's 10 cm pad under the 36 mm knob they hold).
  const world::Pose part_in_tool = tcp.inverse() * object;
  double half = 0.0;
  for (const world::Box& box : object_class.boxes) {
    const Eigen::AlignedBox3d bounds(box.center - box.half_size, box.center + box.half_size);
    double nearest = std::numeric_limits<double>::infinity();
    double box_half = 0.0;
    for (int corner = 0; corner < 8; ++corner) {
      const Eigen::Vector3d p = part_in_tool * bounds.corner(static_cast<Eigen::AlignedBox3d::CornerType>(corner));
      nearest = std::min(nearest, p.z());
      box_half = std::max(box_half, std::abs(p.y()));
    }
    if (nearest <= config_.finger_reach + 1e-9) {
      half = std::max(half, box_half);
    }
  }
  return half;
}

void SmartMoveComponent::addRejected(Selection& selection, const Matches& matches) {
  for (const auto& [object, reason] : matches.rejected) {
    Candidate candidate;
    candidate.object = object;
    candidate.symmetry = -1;
    candidate.rejected = "predicate false: " + reason;
    selection.candidates.push_back(std::move(candidate));
  }
  selection.summarizeFailure();
  if (!selection.ok() && selection.candidates.empty()) {
    selection.failure = "no part of the class is known (detect the parts first)";
  }
}

Selection SmartMoveComponent::selectGrasp(const std::string& object_class,
                                          const std::vector<predicator::Pattern>& patterns, const world::Pose& grasp,
                                          double approach, double speed, const std::string& mode) {
  const bool with_approach = approach > 0.0;
  const world::ObjectClass* object = objectClass(object_class);
  if (object == nullptr) {
    Selection none;
    none.failure = "unknown object class '" + object_class + "'";
    return none;
  }
  syncObstacles();
  const Matches matches = matching(object_class, patterns);
  const arm::JointVector now = motion_.joints();
  // SmartGrasp plans with the fingers as the grasp will have them: opened as far as the part
  // needs (it opens them so first), in the grasp's mode (it turns the gripper to it while they
  // are open), closed to `position` in that mode. SmartMove leaves them as they are.
  const bool in_mode = with_approach && fingers_.plansMode(mode);
  const auto stance = [&](const std::optional<double>& opening, double position) {
    return gripper::FingerStance{with_approach ? opening : std::nullopt, in_mode ? mode : std::string(), position};
  };
  const auto check = [&](Candidate& candidate, double position) -> std::string {
    const auto object_pose = world_.worldPose(candidate.object);
    const auto opening = graspOpening(candidate.goal, *object_pose, *object);
    if (!opening) {
      return "too wide for the fingers";
    }
    // The fingers may touch the part they are to grasp, in these queries only.
    const arm::QueryScene grasping = scene({candidate.object}, stance(opening, position));
    std::string reason;
    const auto goal = motion_.firstFree(candidate.solutions, grasping, reason);
    if (!goal) {
      return "collision at the goal: " + reason;
    }
    if (!with_approach) {
      const arm::MotionPlan path = motion_.planToJoints(now, *goal, speed, grasping);
      return path.ok() ? std::string() : "no path: " + path.failure;
    }
    const world::Pose pregrasp = candidate.goal * world::Pose(Eigen::Translation3d(0, 0, -approach));
    arm::JointVector pre{};
    arm::MotionPlan line;
    if (std::string problem =
            straightOnto(pregrasp, candidate.goal, *goal, grasping, reason,
                         {"no reachable, collision-free pre-grasp", "no straight approach"}, pre, line);
        !problem.empty()) {
      return problem;
    }
    const arm::MotionPlan retreat =
        motion_.planLine(line.goal, up(config_.retreat) * candidate.goal, config_.approach_speed, grasping);
    if (!retreat.ok()) {
      return "no straight retreat: " + retreat.failure;
    }
    const arm::MotionPlan path = motion_.planToJoints(now, pre, speed, grasping);
    return path.ok() ? std::string() : "no path to the pre-grasp: " + path.failure;
  };
  // In a mode whose fingers can close part way: a candidate the open fingers do not fit is
  // checked again with them closed as far as the part allows (beside a neighbour that the
  // open fingers, leaning out, would reach).
  // The fingers closing from `from` onto the part, at the goal (found with them open): they
  // sweep the space between, which must be free of neighbours (a part lying against it would
  // be caught too).
  const auto closingClear = [&](const Candidate& candidate, double from) -> std::string {
    const world::Pose object_pose = *world_.worldPose(candidate.object);
    const double contact = fingers_.fingertipPosition(mode, partHalfWidth(candidate.goal, object_pose, *object));
    const auto opening = graspOpening(candidate.goal, object_pose, *object);
    std::string reason;
    const auto goal = motion_.firstFree(candidate.solutions, scene({candidate.object}, stance(opening, 0.0)), reason);
    std::string blocked;
    for (double position = from + 0.05; blocked.empty() && position < contact + 0.025; position += 0.05) {
      const arm::QueryScene closing = scene({candidate.object}, stance(opening, std::min(position, contact)));
      if (const auto touch = goal ? motion_.collision(*goal, closing) : std::nullopt) {
        blocked = "the closing fingers would touch " + touch->str();
      }
    }
    return blocked;
  };
  const FeasibilityCheck feasible = [&](Candidate& candidate) -> std::string {
    candidate.finger_position = 0.0;
    const std::string open = check(candidate, 0.0);
    if (!in_mode || open.starts_with("too wide")) {
      return open;
    }
    if (open.empty()) {
      return closingClear(candidate, 0.0);
    }
    const world::Pose object_pose = *world_.worldPose(candidate.object);
    const double half = partHalfWidth(candidate.goal, object_pose, *object) + 0.5 * config_.grasp_margin;
    const double position = fingers_.fingertipPosition(mode, half);
    if (position <= 0.0) {
      return open;
    }
    const std::string part_way = check(candidate, position);
    if (!part_way.empty()) {
      return open + "; with the fingers closed part way: " + part_way;
    }
    if (std::string blocked = closingClear(candidate, position); !blocked.empty()) {
      return blocked;
    }
    candidate.finger_position = position;
    return {};
  };
  Selection selection = selectGoal(matches.objects, *object, grasp, armModel(), config_.weights, feasible);
  if (!selection.ok() && with_approach) {
    if (const auto reach = fingers_.reachAcross(mode)) {
      selection = withShiftedGrasps(std::move(selection), *object, *reach, feasible);
    }
  }
  addRejected(selection, matches);
  return selection;
}

std::string SmartMoveComponent::straightOnto(const world::Pose& start, const world::Pose& goal,
                                             const arm::JointVector& goal_joints, const arm::QueryScene& scene,
                                             std::string& reason, const StraightNames& names, arm::JointVector& from,
                                             arm::MotionPlan& line) const {
  const auto free = motion_.firstFree(motion_.solutions(start, goal_joints), scene, reason);
  if (!free) {
    return std::string(names.start) + ": " + (reason.empty() ? "no IK solution" : reason);
  }
  from = *free;
  line = motion_.planLine(from, goal, config_.approach_speed, scene);
  return line.ok() ? std::string() : std::string(names.line) + ": " + line.failure;
}

std::vector<double> SmartMoveComponent::graspShifts(const world::Pose& tcp, const world::Pose& object,
                                                    const world::ObjectClass& object_class, double reach) const {
  // The part's extent along the tool's x (across the fingers); the fingers reach `reach` either side.
  const Eigen::AlignedBox3d bounds = object_class.bounds();
  const world::Pose part_in_tool = tcp.inverse() * object;
  double low = 0.0;
  double high = 0.0;
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3d p = part_in_tool * bounds.corner(static_cast<Eigen::AlignedBox3d::CornerType>(corner));
    low = std::min(low, p.x());
    high = std::max(high, p.x());
  }
  const double keep = config_.grasp_shift_keep;
  std::vector<double> shifts;
  for (int k = 1; k * config_.grasp_shift_step <= config_.grasp_shift_max + 1e-9; ++k) {
    const double shift = k * config_.grasp_shift_step;
    for (const double d : {shift, -shift}) {
      const double limited = d > 0 ? std::min(d, high - reach - keep) : std::max(d, low + reach + keep);
      if (limited * d > 1e-6 &&
          std::none_of(shifts.begin(), shifts.end(), [&](double s) { return std::abs(s - limited) < 1e-6; })) {
        shifts.push_back(limited);
      }
    }
  }
  return shifts;
}

Selection SmartMoveComponent::withShiftedGrasps(Selection centred, const world::ObjectClass& object_class, double reach,
                                                const FeasibilityCheck& feasible) {
  // Grasps shifted across the fingers, nearest the centre first, of the centred candidates
  // that failed for something in the way (not reach, not width).
  std::map<double, std::vector<Candidate>> by_shift;
  for (const Candidate& candidate : centred.candidates) {
    if (candidate.symmetry < 0 || candidate.rejected.starts_with("no IK solution") ||
        candidate.rejected.starts_with("too wide")) {
      continue;
    }
    const auto pose = world_.worldPose(candidate.object);
    for (const double shift : graspShifts(candidate.goal, *pose, object_class, reach)) {
      Candidate shifted;
      shifted.object = candidate.object;
      shifted.symmetry = candidate.symmetry;
      shifted.goal = candidate.goal * Eigen::Translation3d(shift, 0, 0);
      by_shift[std::abs(shift)].push_back(std::move(shifted));
    }
  }
  Selection merged = std::move(centred);
  for (auto& [shift, candidates] : by_shift) {
    Selection selection = selectAmong(std::move(candidates), armModel(), config_.weights, feasible);
    const std::size_t offset = merged.candidates.size();
    for (Candidate& candidate : selection.candidates) {
      merged.candidates.push_back(std::move(candidate));
    }
    merged.seconds += selection.seconds;
    if (selection.chosen) {
      merged.chosen = offset + *selection.chosen;
      break;
    }
  }
  if (merged.chosen) {
    merged.failure.clear();
  } else {
    merged.summarizeFailure();
  }
  return merged;
}

}  // namespace costar::smartmove
