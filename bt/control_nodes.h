#pragma once
// Control nodes: several children, ticked by each node's rule. Semantics table:
// docs/BEHAVIOR_TREES.md. Names follow BehaviorTree.CPP v4 where the semantics match.

#include "bt/node.h"

namespace costar::bt {

/// `->` in the paper. Ticks children in order while they succeed. Keeps memory of the
/// RUNNING child: the next tick resumes there (earlier children are not re-ticked).
/// FAILURE of a child: halts all, FAILURE, and the next run starts from the first child.
/// A skipped child is passed over; every child skipped: skipped.
class Sequence final : public ControlNode {
 public:
  using ControlNode::ControlNode;

 private:
  Status onTick() override;
  void onHalt() override;
  void onReset() override { index_ = 0; }
  std::size_t index_ = 0;
  std::size_t skipped_ = 0;
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
  std::size_t skipped_ = 0;
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
/// failure. A skipped child is passed over; every child skipped: skipped.
class Fallback final : public ControlNode {
 public:
  using ControlNode::ControlNode;

 private:
  Status onTick() override;
  void onHalt() override;
  void onReset() override { index_ = 0; }
  std::size_t index_ = 0;
  std::size_t skipped_ = 0;
  const TreeNode* last_failed_ = nullptr;
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

/// BehaviorTree.CPP's AsyncSequence: a Sequence that, when a child completes with SUCCESS
/// within one tick and more children remain, returns RUNNING and asks for an immediate tick
/// instead of ticking the next child at once: a long chain of instant children never holds a
/// tick, and a halt can come between any two of them.
class AsyncSequence final : public ControlNode {
 public:
  using ControlNode::ControlNode;

 private:
  Status onTick() override;
  void onHalt() override;
  void onReset() override { index_ = 0; }
  std::size_t index_ = 0;
  std::size_t skipped_ = 0;
};

/// BehaviorTree.CPP's AsyncFallback: a Fallback that yields (RUNNING + immediate tick) after a
/// child fails within one tick, as AsyncSequence does after a success.
class AsyncFallback final : public ControlNode {
 public:
  using ControlNode::ControlNode;

 private:
  Status onTick() override;
  void onHalt() override;
  void onReset() override { index_ = 0; }
  std::size_t index_ = 0;
  std::size_t skipped_ = 0;
  const TreeNode* last_failed_ = nullptr;
};

/// BehaviorTree.CPP's ParallelAll: ticks every not-yet-completed child on each tick and
/// completes only when **all** have completed (none is halted early): FAILURE if at least
/// `max_failures` of them failed (negative: n + max_failures + 1), else SUCCESS.
class ParallelAll final : public ControlNode {
 public:
  ParallelAll(std::string id, std::string name, int max_failures);

 private:
  Status onTick() override;
  void onHalt() override;
  void onReset() override;
  int max_failures_;
  int failures_ = 0;
  const TreeNode* last_failed_ = nullptr;
};

/// BehaviorTree.CPP's IfThenElse (2 or 3 children): ticks the first child (the condition)
/// until it completes; SUCCESS: runs the second child, FAILURE: the third (or, with two
/// children, returns that FAILURE). Returns the branch's result. The condition is not
/// re-checked while the branch runs.
class IfThenElse final : public ControlNode {
 public:
  using ControlNode::ControlNode;

 private:
  Status onTick() override;
  void onHalt() override;
  void onReset() override { branch_ = 0; }
  std::size_t branch_ = 0;
};

/// BehaviorTree.CPP's WhileDoElse (2 or 3 children): re-ticks the condition on every tick;
/// while it succeeds ticks the second child (halting the third), when it fails ticks the third
/// (halting the second; with two children: FAILURE). Returns the ticked branch's result.
class WhileDoElse final : public ControlNode {
 public:
  using ControlNode::ControlNode;

 private:
  Status onTick() override;
};

/// BehaviorTree.CPP's TryCatch (4.9): children 1..n-1 are the try block, run as a Sequence;
/// all succeed: SUCCESS. One fails: the last child (the catch block) runs to completion and
/// the node returns FAILURE whatever it returned, with the try block's failure as its reason.
/// `catch_on_halt`: a halt during the try block ticks the catch block once (best effort).
class TryCatch final : public ControlNode {
 public:
  TryCatch(std::string id, std::string name, bool catch_on_halt);

 private:
  Status onTick() override;
  void onHalt() override;
  void onReset() override { index_ = 0; }
  bool catch_on_halt_;
  std::size_t index_ = 0;
  std::size_t skipped_ = 0;
  const TreeNode* failed_ = nullptr;  // set: in the catch block
};

}  // namespace costar::bt
