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

/// What a plan may expand to once every SubTree is instantiated. Validation measures the
/// expanded tree without expanding it (each tree once, with an explicit stack, never deeper
/// than max_depth), so a plan far beyond these, a chain of 10,000 SubTrees or one that doubles
/// at each level, is refused quickly and in little memory.
struct BuildLimits {
  /// Nodes after expanding every SubTree instance.
  std::size_t max_nodes = 1'000'000;
  /// Nesting depth after expanding SubTrees. Building and ticking a tree recurse once per
  /// level (a few hundred bytes of stack each): keep it within a thread's stack.
  std::size_t max_depth = 1'000;
  /// Bytes of every node's path (`main/Sequence[1]/Move "home"`, which each node keeps for
  /// failure reasons and traces) added up: a long name above many nodes is repeated in each.
  std::size_t max_path_bytes = 64u << 20;
};

/// Every problem of the plan, in file order; empty when the plan is valid. Only the main
/// tree and the trees it uses are checked for depth and size; every tree for the rest.
std::vector<Diagnostic> validatePlan(const Plan& plan, const NodeRegistry& registry, const BuildLimits& limits = {});

/// Validates and instantiates the main tree (or `tree_id` if given).
/// @throws PlanError with every problem when the plan is invalid.
Tree buildTree(const Plan& plan, const NodeRegistry& registry, const Clock& clock, const std::string& tree_id = {},
               const BuildLimits& limits = {});

}  // namespace costar::bt
