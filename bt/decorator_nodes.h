#pragma once
// Decorator nodes: exactly one child. Semantics table: docs/BEHAVIOR_TREES.md.

#include <string>

#include "bt/node.h"

namespace costar::bt {

/// SUCCESS <-> FAILURE; RUNNING passes through.
class Inverter final : public DecoratorNode {
 public:
  using DecoratorNode::DecoratorNode;

 private:
  Status onTick() override;
};

/// Child completed (either way): SUCCESS.
class ForceSuccess final : public DecoratorNode {
 public:
  using DecoratorNode::DecoratorNode;

 private:
  Status onTick() override;
};

/// Child completed (either way): FAILURE.
class ForceFailure final : public DecoratorNode {
 public:
  using DecoratorNode::DecoratorNode;

 private:
  Status onTick() override;
};

/// BehaviorTree.CPP's Repeat: re-runs its child while it succeeds, until `num_cycles`
/// successful runs (then SUCCESS); a FAILURE ends the loop with FAILURE. -1 repeats forever.
/// Counts runs, not ticks. After each run the node returns RUNNING and asks for an
/// immediate tick, so an endless loop never blocks a tick and can always be halted.
class Repeat final : public DecoratorNode {
 public:
  Repeat(std::string id, std::string name, int num_cycles);

 private:
  Status onTick() override;
  void onHalt() override;
  void onReset() override { count_ = 0; }
  int num_cycles_;
  int count_ = 0;
};

/// The paper's REPEAT N taken literally: runs its child `num_runs` times whatever each run
/// returns ("until N successes or failures have been reported"), then SUCCESS. Each run's
/// FAILURE is still reported to observers with its reason. -1 runs forever.
class RepeatRuns final : public DecoratorNode {
 public:
  RepeatRuns(std::string id, std::string name, int num_runs);

 private:
  Status onTick() override;
  void onHalt() override;
  void onReset() override { count_ = 0; }
  int num_runs_;
  int count_ = 0;
};

/// CoSTAR's RESET N: returns its child's value. When the child fails, resets the child
/// (clearing every memory in its subtree, see TreeNode::reset) before returning FAILURE, so
/// the next tick starts the child over, up to `num_resets` times (-1: always). Once the
/// budget is spent it passes FAILURE on without resetting, and keeps returning that FAILURE
/// without ticking the child until an ancestor resets this node.
class Reset final : public DecoratorNode {
 public:
  Reset(std::string id, std::string name, int num_resets);

 private:
  Status onTick() override;
  void onReset() override;
  int num_resets_;
  int resets_done_ = 0;
  bool exhausted_ = false;
};

/// Fails the child if it has not completed `msec` after its first tick (clock time): the
/// child is halted and the Timeout returns FAILURE with the reason "timed out".
class Timeout final : public DecoratorNode {
 public:
  Timeout(std::string id, std::string name, Duration limit);

 private:
  Status onTick() override;
  void onHalt() override;
  void onReset() override { started_ = false; }
  Duration limit_;
  std::string reason_;  // composed once: failing must not allocate
  TimePoint deadline_{};
  bool started_ = false;
};

/// Re-runs a failing child up to `num_attempts` runs in all (-1: until it succeeds).
/// SUCCESS on the first successful run; FAILURE (the last run's) when attempts run out.
class RetryUntilSuccessful final : public DecoratorNode {
 public:
  RetryUntilSuccessful(std::string id, std::string name, int num_attempts);

 private:
  Status onTick() override;
  void onHalt() override;
  void onReset() override { attempts_ = 0; }
  int num_attempts_;
  int attempts_ = 0;
};

/// BehaviorTree.CPP's KeepRunningUntilFailure: re-runs its child while it succeeds, one run
/// per tick at most (returns RUNNING after each successful run); a FAILURE ends it with that
/// FAILURE. Never returns SUCCESS.
class KeepRunningUntilFailure final : public DecoratorNode {
 public:
  using DecoratorNode::DecoratorNode;

 private:
  Status onTick() override;
};

/// BehaviorTree.CPP's Delay: RUNNING until `delay_msec` of clock time have passed since its
/// first tick, then ticks its child (in the same tick) and returns the child's result. With
/// the simulated clock the wait costs no wall time. A halt cancels the wait.
class Delay final : public DecoratorNode {
 public:
  Delay(std::string id, std::string name, Duration delay);

 private:
  Status onTick() override;
  void onHalt() override;
  void onReset() override { started_ = false; }
  Duration delay_;
  TimePoint deadline_{};
  bool started_ = false;
  bool ticking_child_ = false;
};

/// BehaviorTree.CPP's RunOnce: runs its child once (to completion, however many ticks);
/// afterwards, without ticking the child again, it is skipped (`then_skip=true`, the default)
/// or returns the same result again (`then_skip=false`). Only reset() (a Reset ancestor, a new
/// run of the plan) lets it run again; a halt while the child is RUNNING does not count as a run.
class RunOnce final : public DecoratorNode {
 public:
  RunOnce(std::string id, std::string name, bool then_skip);

 private:
  Status onTick() override;
  void onReset() override;
  bool then_skip_;
  bool done_ = false;
  Status result_ = Status::kIdle;
};

/// An instance of another BehaviorTree of the plan; transparent: returns its child's value.
class SubTreeNode final : public DecoratorNode {
 public:
  SubTreeNode(std::string id, std::string name, std::string subtree_id);
  const std::string& subtreeId() const { return subtree_id_; }
  std::string pathSegment(std::size_t index_in_parent) const override;

 private:
  Status onTick() override;
  std::string subtree_id_;
};

}  // namespace costar::bt
