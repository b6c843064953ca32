#pragma once
// The engine benchmark's reference trees, built as plan data (no XML parsing in the timed
// part).

#include <string>

#include "bt/plan.h"

namespace costar::bench {

inline bt::PlanNode node(std::string id, std::vector<bt::PlanNode> children = {},
                         std::vector<std::pair<std::string, std::string>> attributes = {}) {
  bt::PlanNode n;
  n.id = std::move(id);
  n.children = std::move(children);
  n.attributes = std::move(attributes);
  return n;
}

inline bt::Plan planOf(bt::PlanNode root) {
  bt::Plan plan;
  plan.file.path = "<bench>";
  plan.file.main_tree = "main";
  plan.file.trees.push_back({"main", std::move(root), {}});
  return plan;
}

/// 1,000 leaves in 200 groups of 5, cycling Sequence(5 x AlwaysSuccess),
/// Fallback(4 x AlwaysFailure, AlwaysSuccess) and Repeat(2, Sequence(5 x AlwaysSuccess)).
inline bt::Plan mixedTree1000() {
  std::vector<bt::PlanNode> groups;
  for (int g = 0; g < 200; ++g) {
    std::vector<bt::PlanNode> leaves;
    if (g % 3 == 1) {
      for (int i = 0; i < 4; ++i) {
        leaves.push_back(node("AlwaysFailure"));
      }
      leaves.push_back(node("AlwaysSuccess"));
      groups.push_back(node("Fallback", std::move(leaves)));
      continue;
    }
    for (int i = 0; i < 5; ++i) {
      leaves.push_back(node("AlwaysSuccess"));
    }
    bt::PlanNode sequence = node("Sequence", std::move(leaves));
    groups.push_back(g % 3 == 0 ? std::move(sequence) : node("Repeat", {std::move(sequence)}, {{"num_cycles", "2"}}));
  }
  return planOf(node("Sequence", std::move(groups)));
}

/// A chain 100 levels deep: Sequence > Sequence > ... > AlwaysSuccess.
inline bt::Plan deepTree100() {
  bt::PlanNode current = node("AlwaysSuccess");
  for (int level = 0; level < 99; ++level) {
    current = node("Sequence", {std::move(current)});
  }
  return planOf(std::move(current));
}

/// A Parallel with 1,000 children (AlwaysSuccess, or Sleep to stay RUNNING a while).
inline bt::Plan wideParallel1000(bool running_children) {
  std::vector<bt::PlanNode> children;
  for (int i = 0; i < 1000; ++i) {
    children.push_back(running_children ? node("Sleep", {}, {{"msec", "50"}}) : node("AlwaysSuccess"));
  }
  return planOf(node("Parallel", std::move(children)));
}

}  // namespace costar::bench
