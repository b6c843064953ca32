#pragma once
// The behavior-tree engine's node model. Knows nothing of robots: leaves that call robot
// operations live in component/, built on LeafNode.
//
// Tick protocol: a parent calls child.tick(); the child returns RUNNING (the paper's BUSY),
// SUCCESS or FAILURE. A parent that stops ticking a RUNNING child (preemption, Reset, Timeout,
// user stop) calls child.halt(), which halts the subtree and cancels running operations.
// Completed children are set back to IDLE by their parent when the parent completes.

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/clock.h"

namespace costar::bt {

/// kSkipped is BehaviorTree.CPP's SKIPPED: a node that did not run at all this time (RunOnce
/// after its run). It is only ever *returned* to the parent: the node's recorded status stays
/// IDLE, so observers never see it. Parents pass over a skipped child; a node whose children
/// were all skipped is skipped itself (docs/BEHAVIOR_TREES.md).
enum class Status : std::uint8_t { kIdle, kRunning, kSuccess, kFailure, kSkipped };

/// "IDLE", "RUNNING", "SUCCESS", "FAILURE", "SKIPPED".
const char* toString(Status status);
inline bool isCompleted(Status status) { return status == Status::kSuccess || status == Status::kFailure; }

class TreeNode;

/// Receives every status transition of every node of a tree, in the order they happen.
/// Called on the ticking thread; implementations must not tick or halt the tree.
class TreeObserver {
 public:
  virtual ~TreeObserver() = default;
  /// `node` went from `from` to `to` at `time`. When `to` is FAILURE, node.failureReason()
  /// and node.failureOrigin() say why and where.
  virtual void onTransition(TimePoint time, const TreeNode& node, Status from, Status to) = 0;
};

/// State shared by the nodes of one tree: the clock, the observers, and a flag a node sets
/// to ask the executor for another tick at once (a loop that finished a run synchronously).
class TreeContext {
 public:
  explicit TreeContext(const Clock& clock) : clock_(&clock) {}
  TreeContext(const TreeContext&) = delete;
  TreeContext& operator=(const TreeContext&) = delete;

  const Clock& clock() const { return *clock_; }
  TimePoint now() const { return clock_->now(); }

  void requestImmediateTick() { immediate_tick_ = true; }
  /// Returns and clears the request.
  bool takeImmediateTickRequest() {
    const bool requested = immediate_tick_;
    immediate_tick_ = false;
    return requested;
  }

  /// Node ticks since the tree was built (every TreeNode::tick() of every node).
  std::uint64_t nodeTicks() const { return node_ticks_; }
  void countNodeTick() { ++node_ticks_; }

  void addObserver(TreeObserver* observer);
  void removeObserver(TreeObserver* observer);
  bool observed() const { return !observers_.empty(); }
  void notify(const TreeNode& node, Status from, Status to);

 private:
  const Clock* clock_;
  std::vector<TreeObserver*> observers_;
  std::uint64_t node_ticks_ = 0;
  bool immediate_tick_ = false;
};

/// Base of every node. Not copyable or movable: nodes are owned by their Tree and refer to
/// each other by pointer.
class TreeNode {
 public:
  /// `id` is the registered node type (e.g. "Sequence"); `name` the optional instance name.
  TreeNode(std::string id, std::string name);
  TreeNode(const TreeNode&) = delete;
  TreeNode& operator=(const TreeNode&) = delete;
  virtual ~TreeNode() = default;

  /// Ticks this node once and records (and reports) the status it returns.
  Status tick();
  /// If RUNNING, stops the node's work (halting running descendants and cancelling
  /// operations). Afterwards the node is IDLE. Memory that a node keeps across runs on
  /// purpose (SequenceWithMemory's index, Reset's budget) survives a halt; see reset().
  void halt();
  /// Halts, then clears every memory the subtree keeps across runs (indices, counters,
  /// budgets): the subtree behaves as freshly built.
  void reset();

  Status status() const { return status_; }
  const std::string& id() const { return id_; }
  const std::string& name() const { return name_; }
  /// Full path from the main tree, e.g. `main/assemble/Sequence[2]/SmartMove "grasp link"`.
  const std::string& path() const { return path_; }
  /// Index of the node in a pre-order walk of its tree (root = 0).
  std::uint32_t uid() const { return uid_; }
  const TreeNode* parent() const { return parent_; }
  virtual std::span<TreeNode* const> children() const { return {}; }

  /// For a node whose last completion was FAILURE: the node where the failure arose (this
  /// node or a descendant) and its reason.
  const TreeNode& failureOrigin() const { return *failure_origin_; }
  std::string_view failureReason() const { return failure_origin_->reason_view_; }

  /// Path segment of this node below its parent: `ID "name"` when named, else `ID[k]` with
  /// k the 1-based position among its siblings. SubTree nodes use their subtree's ID.
  virtual std::string pathSegment(std::size_t index_in_parent) const;

 protected:
  virtual Status onTick() = 0;
  /// Called by halt() only while RUNNING: stop children and cancel work.
  virtual void onHalt() {}
  /// Called by reset() after halting: clear memory kept across runs. Children are reset by
  /// the base class.
  virtual void onReset() {}

  /// Records a FAILURE that arises here, with its reason (copied); returns kFailure.
  Status fail(std::string_view reason);
  /// As fail(), for a reason that lives as long as the program (a string literal): no copy.
  Status failStatic(const char* reason) {
    reason_view_ = reason;
    failure_origin_ = this;
    return Status::kFailure;
  }
  /// Records a FAILURE passed on from `child` (origin and reason stay the child's).
  Status failFrom(const TreeNode& child);

  TreeContext& context() const { return *context_; }

 private:
  friend class Tree;
  void setStatus(Status status);

  std::string id_;
  std::string name_;
  std::string path_;
  std::string reason_;
  std::string_view reason_view_;  // reason_, or a static string
  const TreeNode* failure_origin_ = this;
  const TreeNode* parent_ = nullptr;
  TreeContext* context_ = nullptr;
  std::uint32_t uid_ = 0;
  Status status_ = Status::kIdle;
};

/// A node with any number of children, ticked by its own rule.
class ControlNode : public TreeNode {
 public:
  using TreeNode::TreeNode;
  void addChild(TreeNode* child) { children_.push_back(child); }
  std::span<TreeNode* const> children() const override { return children_; }

 protected:
  /// Halts every child (running ones are stopped, completed ones return to IDLE).
  void haltChildren(std::size_t first = 0);
  void onHalt() override { haltChildren(); }

  std::vector<TreeNode*> children_;
};

/// A node with exactly one child.
class DecoratorNode : public TreeNode {
 public:
  using TreeNode::TreeNode;
  void setChild(TreeNode* child) { child_ = child; }
  TreeNode& child() const { return *child_; }
  std::span<TreeNode* const> children() const override { return {&child_, 1}; }

 protected:
  void onHalt() override { child_->halt(); }

  TreeNode* child_ = nullptr;
};

/// A node without children: an action or a condition.
class LeafNode : public TreeNode {
 public:
  using TreeNode::TreeNode;
};

}  // namespace costar::bt
