#pragma once
// Observers that record a run: JSON lines for replay and tooling.

#include <ostream>

#include "bt/node.h"

namespace costar::bt {

/// Writes one JSON object per status transition and line:
///   {"t":1.25,"uid":4,"path":"main/Sequence[1]/Move \"home\"","node":"Move",
///    "from":"RUNNING","to":"FAILURE","reason":"...","origin":"<path where it arose>"}
/// `reason` and `origin` appear on transitions to FAILURE only. `t` is clock seconds.
class JsonLinesTrace final : public TreeObserver {
 public:
  explicit JsonLinesTrace(std::ostream& out) : out_(out) {}
  void onTransition(TimePoint time, const TreeNode& node, Status from, Status to) override;

 private:
  std::ostream& out_;
};

}  // namespace costar::bt
