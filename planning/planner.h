#pragma once
// Joint-space motion planning around obstacles with OMPL (RRT-Connect, then shortcutting),
// for when the straight joint-space motion would collide.

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "planning/collision_world.h"

namespace costar::planning {

struct PlannerOptions {
  double time_limit_s = 2.0;
  /// OMPL's random generator is seeded with this, so plans are reproducible.
  std::uint64_t seed = 1;
  /// Planning stays within +-range of the start on every joint (and within the limits).
  double joint_range = M_PI;
};

struct PlanResult {
  /// Joint configurations from start to goal, each segment collision-free; empty on failure.
  std::vector<Eigen::VectorXd> path;
  /// Why no path was found, in words a user can act on.
  std::string failure;
  double planning_seconds = 0.0;
  bool ok() const { return !path.empty(); }
};

/// A collision-free path from `start` to `goal`: the straight segment when it is free, else a
/// planned one. Fails with a reason when the start or the goal is in collision (naming the
/// contact) or no path is found in time. `scene`: what this plan sees besides the world
/// (contacts it may make, shapes, obstacles: CollisionWorld::query).
PlanResult planPath(const CollisionWorld& world, const Eigen::VectorXd& start, const Eigen::VectorXd& goal,
                    const PlannerOptions& options = {}, const QueryScene& scene = {});

}  // namespace costar::planning
