#include "bt/control_nodes.h"

namespace costar::bt {

// --- Sequence ---------------------------------------------------------------------------

Status Sequence::onTick() {
  while (index_ < children_.size()) {
    TreeNode& child = *children_[index_];
    switch (child.tick()) {
      case Status::kRunning:
        return Status::kRunning;
      case Status::kFailure:
        haltChildren();
        index_ = 0;
        return failFrom(child);
      default:
        ++index_;
    }
  }
  haltChildren();
  index_ = 0;
  return Status::kSuccess;
}

void Sequence::onHalt() {
  haltChildren();
  index_ = 0;
}

// --- SequenceWithMemory -------------------------------------------------------------------

Status SequenceWithMemory::onTick() {
  while (index_ < children_.size()) {
    TreeNode& child = *children_[index_];
    switch (child.tick()) {
      case Status::kRunning:
        return Status::kRunning;
      case Status::kFailure:
        // Keep index_: the next tick retries this child.
        haltChildren(index_ + 1);
        return failFrom(child);
      default:
        ++index_;
    }
  }
  haltChildren();
  index_ = 0;
  return Status::kSuccess;
}

// --- ReactiveSequence ----------------------------------------------------------------------

Status ReactiveSequence::onTick() {
  for (std::size_t i = 0; i < children_.size(); ++i) {
    TreeNode& child = *children_[i];
    switch (child.tick()) {
      case Status::kRunning:
        haltChildren(i + 1);
        return Status::kRunning;
      case Status::kFailure:
        haltChildren();
        return failFrom(child);
      default:
        break;
    }
  }
  haltChildren();
  return Status::kSuccess;
}

// --- Fallback --------------------------------------------------------------------------------

Status Fallback::onTick() {
  while (index_ < children_.size()) {
    TreeNode& child = *children_[index_];
    switch (child.tick()) {
      case Status::kRunning:
        return Status::kRunning;
      case Status::kSuccess:
        haltChildren();
        index_ = 0;
        return Status::kSuccess;
      default:
        ++index_;
    }
  }
  const TreeNode& last = *children_.back();
  haltChildren();
  index_ = 0;
  return failFrom(last);
}

void Fallback::onHalt() {
  haltChildren();
  index_ = 0;
}

// --- ReactiveFallback ------------------------------------------------------------------------

Status ReactiveFallback::onTick() {
  for (std::size_t i = 0; i < children_.size(); ++i) {
    TreeNode& child = *children_[i];
    switch (child.tick()) {
      case Status::kRunning:
        haltChildren(i + 1);
        return Status::kRunning;
      case Status::kSuccess:
        haltChildren();
        return Status::kSuccess;
      default:
        break;
    }
  }
  const TreeNode& last = *children_.back();
  haltChildren();
  return failFrom(last);
}

// --- Parallel ----------------------------------------------------------------------------------

Parallel::Parallel(std::string id, std::string name, int success_count, int failure_count)
    : ControlNode(std::move(id), std::move(name)), success_count_(success_count), failure_count_(failure_count) {}

int Parallel::threshold(int count) const {
  const int n = static_cast<int>(children_.size());
  return count < 0 ? n + count + 1 : count;
}

Status Parallel::onTick() {
  const int n = static_cast<int>(children_.size());
  const int needed_successes = threshold(success_count_);
  const int allowed_failures = threshold(failure_count_);
  const TreeNode* last_failed = nullptr;
  for (TreeNode* child : children_) {
    if (isCompleted(child->status())) {
      continue;  // completed earlier in this run
    }
    const Status status = child->tick();
    if (status == Status::kSuccess) {
      ++successes_;
    } else if (status == Status::kFailure) {
      ++failures_;
      last_failed = child;
    }
    if (successes_ >= needed_successes) {
      onReset();
      haltChildren();
      return Status::kSuccess;
    }
    if (failures_ >= allowed_failures || n - failures_ < needed_successes) {
      onReset();
      haltChildren();
      return last_failed != nullptr ? failFrom(*last_failed)
                                    : failStatic("Parallel: success threshold can no longer be reached");
    }
  }
  return Status::kRunning;
}

void Parallel::onHalt() {
  haltChildren();
  onReset();
}

void Parallel::onReset() {
  successes_ = 0;
  failures_ = 0;
}

// --- Iterator ------------------------------------------------------------------------------------

Status Iterator::onTick() {
  while (index_ < children_.size()) {
    if (children_[index_]->tick() == Status::kRunning) {
      return Status::kRunning;
    }
    ++index_;  // success or failure: go on
  }
  haltChildren();
  index_ = 0;
  return Status::kSuccess;
}

void Iterator::onHalt() {
  haltChildren();
  index_ = 0;
}

}  // namespace costar::bt
