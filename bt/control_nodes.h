#pragma once
// Control nodes: several children, ticked by each node's rule. Semantics table:
// docs/BEHAVIOR_TREES.md. Names follow BehaviorTree.CPP v4 where the semantics match.

#include "bt/node.h"

namespace costar::bt {

/// `->` in the paper. Ticks children in order while they succeed. Keeps memory of the
/// RUNNING child: the next tick resumes there (earlier children are not re-ticked).
/// FAILURE of a child: halts all, FAILURE, and the next run starts from the first child.
class Sequence final : public ControlNode {
 public:
  using ControlNode::ControlNode;

 private:
  Status onTick() override;
  void onHalt() override;
  void onReset() override { index_ = 0; }
  std::size_t index_ = 0;
};

/// As Sequence, but a FAILURE or a halt keeps the index: the next tick retries the child
/// that failed or was interrupted. Only reset() (e.g. by a Reset ancestor) or completing
/// every child starts it over.
class SequenceWithMemory final : public ControlNode {
 public:
  using ControlNode::ControlNode;

 private:
  Status onTick() override;
  void onReset() override { index_ = 0; }
  std::size_t index_ = 0;
};

/// Re-ticks every child from the first on every tick (conditions are re-checked while a
/// later action runs). A child returning RUNNING halts the children after it.
/// Children before the last must never return RUNNING (checked when a plan is validated).
class ReactiveSequence final : public ControlNode {
 public:
  using ControlNode::ControlNode;

 private:
  Status onTick() override;
};

/// `?` in the paper (Selector). Ticks children in order until one succeeds; memory of the
/// RUNNING child like Sequence. All children failed: FAILURE, passing on the last child's
/// failure.
class Fallback final : public ControlNode {
 public:
  using ControlNode::ControlNode;

 private:
  Status onTick() override;
  void onHalt() override;
  void onReset() override { index_ = 0; }
  std::size_t index_ = 0;
};

/// Fallback that re-ticks from the first child on every tick: a higher-priority child that
/// now succeeds or runs preempts (halts) a lower-priority RUNNING one.
class ReactiveFallback final : public ControlNode {
 public:
  using ControlNode::ControlNode;

 private:
  Status onTick() override;
};

/// Ticks every not-yet-completed child on each tick. SUCCESS once `success_count` children
/// succeeded; FAILURE once `failure_count` failed or success became impossible. Either way
/// the children still running are halted. Negative counts are relative to the number of
/// children: -1 means all of them.
class Parallel final : public ControlNode {
 public:
  Parallel(std::string id, std::string name, int success_count, int failure_count);

 private:
  Status onTick() override;
  void onHalt() override;
  void onReset() override;
  int threshold(int count) const;
  int success_count_;
  int failure_count_;
  int successes_ = 0;
  int failures_ = 0;
};

/// CoSTAR's Iterator: ticks children in order, one run each, ignoring their failures
/// (each child's FAILURE is still reported to observers with its reason). SUCCESS after the
/// last child completed. Memory of the RUNNING child like Sequence.
class Iterator final : public ControlNode {
 public:
  using ControlNode::ControlNode;

 private:
  Status onTick() override;
  void onHalt() override;
  void onReset() override { index_ = 0; }
  std::size_t index_ = 0;
};

}  // namespace costar::bt
