#pragma once
// From plan to tree: validatePlan() finds every problem before anything runs (unknown node,
// missing or ill-typed parameter, bad count, unknown or recursive subtree, ...), each with
// file and line; buildTree() instantiates a valid plan.

#include <string>
#include <vector>

#include "bt/plan.h"
#include "bt/registry.h"
#include "bt/tree.h"

namespace costar::bt {

struct BuildLimits {
  /// Nodes after expanding every SubTree instance.
  std::size_t max_nodes = 1'000'000;
  /// Nesting depth after expanding SubTrees.
  std::size_t max_depth = 1'000;
};

/// Every problem of the plan, in file order; empty when the plan is valid. Only the main
/// tree and the trees it uses are checked for depth and size; every tree for the rest.
std::vector<Diagnostic> validatePlan(const Plan& plan, const NodeRegistry& registry, const BuildLimits& limits = {});

/// Validates and instantiates the main tree (or `tree_id` if given).
/// @throws PlanError with every problem when the plan is invalid.
Tree buildTree(const Plan& plan, const NodeRegistry& registry, const Clock& clock, const std::string& tree_id = {},
               const BuildLimits& limits = {});

}  // namespace costar::bt
