#pragma once
// Built-in leaves that need no robot: AlwaysSuccess, AlwaysFailure, Sleep.

#include "bt/node.h"

namespace costar::bt {

class AlwaysSuccess final : public LeafNode {
 public:
  using LeafNode::LeafNode;

 private:
  Status onTick() override { return Status::kSuccess; }
};

class AlwaysFailure final : public LeafNode {
 public:
  using LeafNode::LeafNode;

 private:
  Status onTick() override { return failStatic("AlwaysFailure"); }
};

/// RUNNING until `msec` of clock time have passed since its first tick, then SUCCESS.
/// With the simulated clock the wait costs no wall time.
class Sleep final : public LeafNode {
 public:
  Sleep(std::string id, std::string name, Duration duration);

 private:
  Status onTick() override;
  void onHalt() override { started_ = false; }
  void onReset() override { started_ = false; }
  Duration duration_;
  TimePoint deadline_{};
  bool started_ = false;
};

}  // namespace costar::bt
