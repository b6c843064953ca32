#include "planning/planner.h"

#include <ompl/base/spaces/RealVectorStateSpace.h>
#include <ompl/geometric/PathSimplifier.h>
#include <ompl/geometric/SimpleSetup.h>
#include <ompl/geometric/planners/rrt/RRTConnect.h>
#include <ompl/util/Console.h>
#include <ompl/util/RandomNumbers.h>

#include <chrono>
#include <cstdio>
#include <mutex>

namespace costar::planning {

namespace ob = ompl::base;
namespace og = ompl::geometric;

namespace {

std::mutex g_ompl_mutex;  // OMPL keeps global state (its log level, its seed generator)

/// Uniform samples from an RNG seeded for this plan, so a plan does not depend on what was
/// planned before in the process (OMPL's global seed works only before its first use).
class SeededSampler final : public ob::RealVectorStateSampler {
 public:
  SeededSampler(const ob::StateSpace* space, std::uint64_t seed) : ob::RealVectorStateSampler(space) {
    rng_.setLocalSeed(static_cast<std::uint_fast32_t>(seed));
  }
};

class SeededSimplifier final : public og::PathSimplifier {
 public:
  SeededSimplifier(const ob::SpaceInformationPtr& si, std::uint64_t seed) : og::PathSimplifier(si) {
    rng_.setLocalSeed(static_cast<std::uint_fast32_t>(seed));
  }
};

}  // namespace

PlanResult planPath(const CollisionWorld& world, const Eigen::VectorXd& start, const Eigen::VectorXd& goal,
                    const PlannerOptions& options, const QueryScene& scene) {
  CollisionWorld::Query query = world.query(scene);
  const auto wall_start = std::chrono::steady_clock::now();
  PlanResult result;
  const auto elapsed = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  };
  // A goal beyond a joint's limits (or not a number) is refused with the joint named, before any
  // collision check (OMPL would only log "invalid bounds" to the console and find nothing).
  const RobotModel& robot = world.robot();
  for (Eigen::Index j = 0; j < goal.size() && j < robot.lowerLimits().size(); ++j) {
    if (!(goal[j] >= robot.lowerLimits()[j] && goal[j] <= robot.upperLimits()[j])) {
      char bounds[160];
      std::snprintf(bounds, sizeof bounds, " (%.4f rad; its limits %.4f .. %.4f)", goal[j], robot.lowerLimits()[j],
                    robot.upperLimits()[j]);
      result.failure =
          "the goal is outside joint " + robot.jointNames()[static_cast<std::size_t>(j)] + "'s limits" + bounds;
      return result;
    }
  }
  if (const auto contact = query.check(start)) {
    result.failure = "the arm is in collision where it starts: " + contact->str();
    return result;
  }
  if (const auto contact = query.check(goal)) {
    result.failure = "the goal is in collision: " + contact->str();
    return result;
  }
  if (!query.checkSegment(start, goal)) {
    result.path = {start, goal};
    result.planning_seconds = elapsed();
    return result;
  }

  std::lock_guard lock(g_ompl_mutex);
  ompl::msg::setLogLevel(ompl::msg::LOG_WARN);
  const auto dof = static_cast<unsigned>(start.size());
  auto space = std::make_shared<ob::RealVectorStateSpace>(dof);
  const std::uint64_t seed = options.seed == 0 ? 1 : options.seed;
  space->setStateSamplerAllocator(
      [seed](const ob::StateSpace* state_space) { return std::make_shared<SeededSampler>(state_space, seed); });
  ob::RealVectorBounds bounds(dof);
  for (unsigned j = 0; j < dof; ++j) {
    // The arm is where it is: a start a hair beyond a limit (a reading at the stop) stays inside.
    bounds.setLow(
        j, std::min(start[j], std::max(robot.lowerLimits()[j], std::min(start[j], goal[j]) - options.joint_range)));
    bounds.setHigh(
        j, std::max(start[j], std::min(robot.upperLimits()[j], std::max(start[j], goal[j]) + options.joint_range)));
  }
  space->setBounds(bounds);
  og::SimpleSetup setup(space);
  Eigen::VectorXd q(dof);
  setup.setStateValidityChecker([&query, &q, dof](const ob::State* state) {
    const auto* values = state->as<ob::RealVectorStateSpace::StateType>()->values;
    for (unsigned j = 0; j < dof; ++j) {
      q[j] = values[j];
    }
    return !query.check(q).has_value();
  });
  // Check motions at the collision world's joint resolution.
  setup.getSpaceInformation()->setStateValidityCheckingResolution(world.options().resolution /
                                                                  space->getMaximumExtent());
  ob::ScopedState<> from(space);
  ob::ScopedState<> to(space);
  for (unsigned j = 0; j < dof; ++j) {
    from[j] = start[j];
    to[j] = goal[j];
  }
  setup.setStartAndGoalStates(from, to);
  setup.setPlanner(std::make_shared<og::RRTConnect>(setup.getSpaceInformation()));
  const ob::PlannerStatus status = setup.solve(options.time_limit_s);
  if (status != ob::PlannerStatus::EXACT_SOLUTION) {
    result.failure = "no collision-free path found within " + std::to_string(options.time_limit_s) +
                     " s (the straight motion would hit: " + query.checkSegment(start, goal)->str() + ")";
    result.planning_seconds = elapsed();
    return result;
  }
  og::PathGeometric& path = setup.getSolutionPath();
  SeededSimplifier simplifier(setup.getSpaceInformation(), seed + 1);
  simplifier.shortcutPath(path);
  simplifier.reduceVertices(path);
  for (std::size_t i = 0; i < path.getStateCount(); ++i) {
    const auto* values = path.getState(i)->as<ob::RealVectorStateSpace::StateType>()->values;
    Eigen::VectorXd waypoint(dof);
    for (unsigned j = 0; j < dof; ++j) {
      waypoint[j] = values[j];
    }
    result.path.push_back(waypoint);
  }
  // OMPL checks motions discretely; confirm every segment at our resolution.
  for (std::size_t i = 1; i < result.path.size(); ++i) {
    if (const auto contact = query.checkSegment(result.path[i - 1], result.path[i])) {
      result.path.clear();
      result.failure = "the planned path failed its final check: " + contact->str();
      break;
    }
  }
  result.planning_seconds = elapsed();
  return result;
}

}  // namespace costar::planning
