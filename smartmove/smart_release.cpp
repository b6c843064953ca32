// SmartRelease: the held part put on top of a matching part (every symmetric way), at a frame,
// or at a free spot on the table that satisfies the predicates; lowered in a straight line,
// released, lifted. The part put down is remembered, for misplaced(o).

#include <algorithm>
#include <cstdio>

#include "smartmove/script.h"
#include "smartmove/smartmove.h"

namespace costar::smartmove {

using component::OperationResult;
using component::RunningOperation;

std::string SmartMoveComponent::spotFailsPattern(const Eigen::Vector3d& spot,
                                                 const predicator::Pattern& pattern) const {
  const auto relation = predicator::relationFromName(pattern.predicate);
  const bool usable = relation && *relation != predicator::Relation::kOn && *relation != predicator::Relation::kAbove &&
                      *relation != predicator::Relation::kBelow;
  if (!usable || pattern.args.size() != 2 || pattern.args[0] != "?") {
    return "only left_of, right_of, in_front_of, behind, near(?, frame) can choose a spot on the table: " +
           pattern.predicate;
  }
  const auto reference = world_.worldPose(pattern.args[1]);
  if (!reference) {
    return "unknown frame '" + pattern.args[1] + "'";
  }
  const auto viewpoint = world_.worldPose("table_center");
  const Eigen::Matrix3d axes = viewpoint ? Eigen::Matrix3d(viewpoint->linear()) : Eigen::Matrix3d::Identity();
  const bool holds = predicator::relationHolds(*relation, {spot, {}}, {reference->translation(), {}}, axes, {});
  return holds ? std::string() : pattern.predicate + " is false there";
}

std::unique_ptr<RunningOperation> SmartMoveComponent::beginRelease(const component::ParamMap& params) {
  const auto text = [&params](const char* name) { return params.at(name).asString(); };
  std::vector<predicator::Pattern> patterns;
  if (const auto problem = parsePredicates(params, patterns)) {
    return failed(*problem);
  }
  const double speed = params.at("speed").asDouble();
  const double drop = params.at("drop").asDouble();
  if (!held_) {
    return failed("nothing to release: no part was grasped with SmartGrasp");
  }
  const world::ObjectClass* held_object = objectClass(held_class_);
  const std::string target_class = text("target_class");
  const std::string target = text("target");
  if (target_class.empty() == target.empty()) {
    return failed("give either target_class (put the part on such a part) or target (put it at a frame)");
  }
  syncObstacles();
  // Candidate poses of the held part: on top of each matching part, every symmetric way.
  std::vector<Candidate> candidates;
  Matches matches;
  const auto addPlacements = [&](const std::string& name, const world::Pose& support, double lift) {
    for (std::size_t h = 0; h < held_object->symmetries.size(); ++h) {
      world::Pose held_symmetry = world::Pose::Identity();
      held_symmetry.linear() = held_object->symmetries[h];
      Candidate candidate;
      candidate.object = name;
      candidate.symmetry = static_cast<int>(h);
      candidate.goal = support * up(lift + drop) * held_symmetry * held_grasp_;
      candidates.push_back(std::move(candidate));
    }
  };
  if (target == "table") {
    // Free spots on the table that satisfy the predicates, clear of every known part.
    const std::vector<std::pair<std::string, world::Pose>> others = [&] {
      std::vector<std::pair<std::string, world::Pose>> parts;
      for (const auto& object : classes_) {
        for (const auto& entry : matching(object.name, {}, *held_).objects) {
          parts.push_back(entry);
        }
      }
      return parts;
    }();
    for (const auto& pattern : patterns) {
      const std::string problem = spotFailsPattern(Eigen::Vector3d::Zero(), pattern);
      if (problem.rfind("only ", 0) == 0 || problem.rfind("unknown frame", 0) == 0) {
        return failed(problem);
      }
    }
    const double held_radius = 0.5 * held_object->bounds().sizes().head<2>().norm();
    const double step = config_.table_spot_step;
    for (double x = config_.table_min.x(); x <= config_.table_max.x() + 1e-9; x += step) {
      for (double y = config_.table_min.y(); y <= config_.table_max.y() + 1e-9; y += step) {
        const Eigen::Vector3d spot(x, y, 0.0);
        const bool clear =
            std::all_of(others.begin(), others.end(), [&](const std::pair<std::string, world::Pose>& other) {
              const world::ObjectClass* c = nullptr;
              for (const auto& object : classes_) {
                if (world_.holds("is_a", std::vector<std::string>{other.first, object.name})) {
                  c = &object;
                }
              }
              const double radius = c != nullptr ? 0.5 * c->bounds().sizes().head<2>().norm() : 0.05;
              return (other.second.translation().head<2>() - spot.head<2>()).norm() > held_radius + radius + 0.02;
            });
        std::string failing;
        const double m = config_.table_spot_margin;
        for (const auto& pattern : patterns) {
          for (const Eigen::Vector3d& shift :
               {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(m, 0, 0), Eigen::Vector3d(-m, 0, 0), Eigen::Vector3d(0, m, 0),
                Eigen::Vector3d(0, -m, 0)}) {
            failing = spotFailsPattern(spot + shift, pattern);
            if (!failing.empty()) {
              break;
            }
          }
          if (!failing.empty()) {
            break;
          }
        }
        if (!clear || !failing.empty()) {
          continue;
        }
        char name[48];
        std::snprintf(name, sizeof name, "table(%.2f,%.2f)", x, y);
        world::Pose frame = world::Pose::Identity();
        frame.translation() = spot;
        addPlacements(name, frame, held_object->rest_height + config_.place_clearance);
      }
    }
    // Keep the held part's placements that rest it as it rests canonically (its z up).
    std::erase_if(candidates, [this](const Candidate& candidate) {
      const world::Pose part = candidate.goal * held_grasp_.inverse();
      return part.linear().col(2).z() < 0.98;
    });
    if (candidates.empty()) {
      return failed("no free spot on the table satisfies " + text("predicates"));
    }
  } else if (!target.empty()) {
    const auto frame = world_.worldPose(target);
    if (!frame) {
      return failed("unknown frame '" + target + "'");
    }
    addPlacements(target, *frame, held_object->rest_height + config_.place_clearance);
  } else {
    const world::ObjectClass* support = objectClass(target_class);
    matches = matching(target_class, patterns, *held_);
    for (const auto& [name, pose] : matches.objects) {
      for (const Eigen::Matrix3d& symmetry : support->symmetries) {
        world::Pose frame = pose;
        frame.linear() = pose.linear() * symmetry;
        if (frame.linear().col(2).z() < 0.98) {
          continue;  // only the part's top side faces up
        }
        addPlacements(name, frame,
                      support->bounds().max().z() - held_object->bounds().min().z() + config_.place_clearance);
      }
    }
  }
  // Checked with the fingers as they release: at the opening they release to, wider than they
  // hold, or in the mode the part was grasped in, as far open as they release to.
  const gripper::FingerStance releasing{
      .opening = held_opening_ > 0.0 ? held_opening_ : fingers_.stroke().value_or(0.0),
      .mode = held_mode_,
      .position = held_finger_position_};
  const FeasibilityCheck feasible = [&](Candidate& candidate) -> std::string {
    // The part held may touch its support, in these queries only.
    const arm::QueryScene allowed = scene({candidate.object}, releasing);
    std::string reason;
    const auto goal = motion_.firstFree(candidate.solutions, allowed, reason);
    if (!goal) {
      return "collision at the goal: " + reason;
    }
    const world::Pose above = up(params.at("approach").asDouble()) * candidate.goal;
    arm::JointVector pre{};
    arm::MotionPlan line;
    if (std::string problem =
            straightOnto(above, candidate.goal, *goal, allowed, reason,
                         {"no reachable, collision-free point above", "no straight way down"}, pre, line);
        !problem.empty()) {
      return problem;
    }
    const arm::MotionPlan path = motion_.planToJoints(motion_.joints(), pre, speed, allowed);
    return path.ok() ? std::string() : "no path: " + path.failure;
  };
  Selection selection = selectAmong(std::move(candidates), armModel(), config_.weights, feasible);
  addRejected(selection, matches);
  nlohmann::json data = selection.toJson();
  if (!selection.ok()) {
    return failed("no feasible place for " + *held_ + ": " + selection.failure, data);
  }
  const Candidate chosen = selection.best();
  const double approach = params.at("approach").asDouble();
  const std::string released = *held_;
  const std::string support_object = chosen.object;
  std::vector<Script::Step> steps;
  steps.push_back({"move above " + support_object,
                   [this, chosen, approach, speed] {
                     return moveToFreeConfiguration(up(approach) * chosen.goal, chosen.solutions.front(), speed,
                                                    "above the place", "no collision-free point above");
                   },
                   nullptr});
  steps.push_back(
      {"lower onto " + support_object,
       [this, chosen, support_object] {
         return follow(motion_.planLine(motion_.joints(), chosen.goal, config_.approach_speed, scene({support_object})),
                       "lower");
       },
       nullptr});
  steps.push_back({"release " + released,
                   [this, opening = held_opening_, position = held_finger_position_] {
                     // As far as the part needs: its grasp's opening, or a fingertip mode's position.
                     return openGripper({.opening = opening, .position = position});
                   },
                   [this, part = chosen.goal * held_grasp_.inverse()](const OperationResult&) -> std::string {
                     put_ = PutDown{held_class_, part, {}};
                     for (const auto& [object, pose] : matching(held_class_, {}).objects) {
                       put_->known.push_back(pose.translation());
                     }
                     held_.reset();
                     return {};
                   }});
  steps.push_back({"lift away",
                   [this, approach, support_object, mode = held_mode_, position = held_finger_position_] {
                     const arm::JointVector now = motion_.joints();
                     return follow(motion_.planLine(now, up(approach) * motion_.toolAt(now), config_.approach_speed,
                                                    scene({support_object}, {.mode = mode, .position = position})),
                                   "retreat");
                   },
                   nullptr});
  return std::make_unique<Script>(std::move(steps), data);
}

}  // namespace costar::smartmove
