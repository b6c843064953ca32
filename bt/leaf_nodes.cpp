#include "bt/leaf_nodes.h"

namespace costar::bt {

Sleep::Sleep(std::string id, std::string name, Duration duration)
    : LeafNode(std::move(id), std::move(name)), duration_(duration) {}

Status Sleep::onTick() {
  const TimePoint now = context().now();
  if (!started_) {
    started_ = true;
    deadline_ = now + duration_;
  }
  if (now >= deadline_) {
    started_ = false;
    return Status::kSuccess;
  }
  return Status::kRunning;
}

}  // namespace costar::bt
