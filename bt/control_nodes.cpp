#include "bt/control_nodes.h"

#include <algorithm>

namespace costar::bt {

// --- Sequence ---------------------------------------------------------------------------

Status Sequence::onTick() {
  if (status() != Status::kRunning) {
    skipped_ = 0;
  }
  while (index_ < children_.size()) {
    TreeNode& child = *children_[index_];
    switch (child.tick()) {
      case Status::kRunning:
        return Status::kRunning;
      case Status::kFailure:
        haltChildren();
        index_ = 0;
        return failFrom(child);
      case Status::kSkipped:
        ++skipped_;
        ++index_;
        break;
      default:
        ++index_;
    }
  }
  haltChildren();
  index_ = 0;
  return skipped_ == children_.size() ? Status::kSkipped : Status::kSuccess;
}

void Sequence::onHalt() {
  haltChildren();
  index_ = 0;
}

// --- SequenceWithMemory -------------------------------------------------------------------

Status SequenceWithMemory::onTick() {
  if (status() != Status::kRunning) {
    skipped_ = 0;
  }
  while (index_ < children_.size()) {
    TreeNode& child = *children_[index_];
    switch (child.tick()) {
      case Status::kRunning:
        return Status::kRunning;
      case Status::kFailure:
        // Keep index_: the next tick retries this child.
        haltChildren(index_ + 1);
        return failFrom(child);
      case Status::kSkipped:
        ++skipped_;
        ++index_;
        break;
      default:
        ++index_;
    }
  }
  haltChildren();
  index_ = 0;
  return skipped_ == children_.size() ? Status::kSkipped : Status::kSuccess;
}

// --- ReactiveSequence ----------------------------------------------------------------------

Status ReactiveSequence::onTick() {
  std::size_t skipped = 0;
  for (std::size_t i = 0; i < children_.size(); ++i) {
    TreeNode& child = *children_[i];
    switch (child.tick()) {
      case Status::kRunning:
        haltChildren(i + 1);
        return Status::kRunning;
      case Status::kFailure:
        haltChildren();
        return failFrom(child);
      case Status::kSkipped:
        ++skipped;
        break;
      default:
        break;
    }
  }
  haltChildren();
  return skipped == children_.size() ? Status::kSkipped : Status::kSuccess;
}

// --- Fallback --------------------------------------------------------------------------------

Status Fallback::onTick() {
  if (status() != Status::kRunning) {
    skipped_ = 0;
    last_failed_ = nullptr;
  }
  while (index_ < children_.size()) {
    TreeNode& child = *children_[index_];
    switch (child.tick()) {
      case Status::kRunning:
        return Status::kRunning;
      case Status::kSuccess:
        haltChildren();
        index_ = 0;
        return Status::kSuccess;
      case Status::kSkipped:
        ++skipped_;
        ++index_;
        break;
      default:
        last_failed_ = &child;
        ++index_;
    }
  }
  haltChildren();
  index_ = 0;
  if (skipped_ == children_.size()) {
    return Status::kSkipped;
  }
  return failFrom(*last_failed_);
}

void Fallback::onHalt() {
  haltChildren();
  index_ = 0;
}

// --- ReactiveFallback ------------------------------------------------------------------------

Status ReactiveFallback::onTick() {
  const TreeNode* last_failed = nullptr;
  for (std::size_t i = 0; i < children_.size(); ++i) {
    TreeNode& child = *children_[i];
    switch (child.tick()) {
      case Status::kRunning:
        haltChildren(i + 1);
        return Status::kRunning;
      case Status::kSuccess:
        haltChildren();
        return Status::kSuccess;
      case Status::kSkipped:
        break;
      default:
        last_failed = &child;
        break;
    }
  }
  haltChildren();
  return last_failed == nullptr ? Status::kSkipped : failFrom(*last_failed);
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
  int skipped = 0;
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
    } else if (status == Status::kSkipped) {
      ++skipped;  // did not run: counts neither way, but cannot succeed either
    }
    if (successes_ >= needed_successes) {
      onReset();
      haltChildren();
      return Status::kSuccess;
    }
    if (skipped == n) {
      onReset();
      return Status::kSkipped;
    }
    if (failures_ >= allowed_failures || n - failures_ - skipped < needed_successes) {
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

namespace costar::bt {

// --- AsyncSequence / AsyncFallback ---------------------------------------------------------

Status AsyncSequence::onTick() {
  if (status() != Status::kRunning) {
    skipped_ = 0;
  }
  while (index_ < children_.size()) {
    TreeNode& child = *children_[index_];
    const Status before = child.status();
    switch (child.tick()) {
      case Status::kRunning:
        return Status::kRunning;
      case Status::kFailure:
        haltChildren();
        index_ = 0;
        return failFrom(child);
      case Status::kSkipped:
        ++skipped_;
        ++index_;
        break;
      default:
        ++index_;
        if (before == Status::kIdle && index_ < children_.size()) {
          // Completed within one tick: give the tick back (interruptible), resume at once.
          context().requestImmediateTick();
          return Status::kRunning;
        }
    }
  }
  haltChildren();
  index_ = 0;
  return skipped_ == children_.size() ? Status::kSkipped : Status::kSuccess;
}

void AsyncSequence::onHalt() {
  haltChildren();
  index_ = 0;
}

Status AsyncFallback::onTick() {
  if (status() != Status::kRunning) {
    skipped_ = 0;
    last_failed_ = nullptr;
  }
  while (index_ < children_.size()) {
    TreeNode& child = *children_[index_];
    const Status before = child.status();
    switch (child.tick()) {
      case Status::kRunning:
        return Status::kRunning;
      case Status::kSuccess:
        haltChildren();
        index_ = 0;
        return Status::kSuccess;
      case Status::kSkipped:
        ++skipped_;
        ++index_;
        break;
      default:
        last_failed_ = &child;
        ++index_;
        if (before == Status::kIdle && index_ < children_.size()) {
          context().requestImmediateTick();
          return Status::kRunning;
        }
    }
  }
  haltChildren();
  index_ = 0;
  if (skipped_ == children_.size()) {
    return Status::kSkipped;
  }
  return failFrom(*last_failed_);
}

void AsyncFallback::onHalt() {
  haltChildren();
  index_ = 0;
}

// --- ParallelAll ----------------------------------------------------------------------------

ParallelAll::ParallelAll(std::string id, std::string name, int max_failures)
    : ControlNode(std::move(id), std::move(name)), max_failures_(max_failures) {}

Status ParallelAll::onTick() {
  const int n = static_cast<int>(children_.size());
  const int threshold = max_failures_ < 0 ? std::max(n + max_failures_ + 1, 0) : max_failures_;
  int skipped = 0;
  int completed = 0;
  for (TreeNode* child : children_) {
    if (isCompleted(child->status())) {
      ++completed;  // completed earlier in this run
      continue;
    }
    switch (child->tick()) {
      case Status::kSuccess:
        ++completed;
        break;
      case Status::kFailure:
        ++completed;
        ++failures_;
        last_failed_ = child;
        break;
      case Status::kSkipped:
        ++skipped;
        break;
      default:
        break;
    }
  }
  if (skipped == n) {
    return Status::kSkipped;
  }
  if (skipped + completed < n) {
    return Status::kRunning;
  }
  const bool failed = failures_ >= threshold;
  const TreeNode* last_failed = last_failed_;
  haltChildren();
  onReset();
  if (!failed) {
    return Status::kSuccess;
  }
  return last_failed != nullptr ? failFrom(*last_failed)
                                : failStatic("ParallelAll: max_failures is 0, so it always fails");
}

void ParallelAll::onHalt() {
  haltChildren();
  onReset();
}

void ParallelAll::onReset() {
  failures_ = 0;
  last_failed_ = nullptr;
}

// --- IfThenElse -------------------------------------------------------------------------------

Status IfThenElse::onTick() {
  if (branch_ == 0) {
    TreeNode& condition = *children_[0];
    switch (condition.tick()) {
      case Status::kRunning:
        return Status::kRunning;
      case Status::kSkipped:
        return Status::kSkipped;
      case Status::kSuccess:
        branch_ = 1;
        break;
      default:
        if (children_.size() < 3) {
          haltChildren();
          return failFrom(condition);
        }
        branch_ = 2;
    }
  }
  TreeNode& branch = *children_[branch_];
  const Status status = branch.tick();
  if (status == Status::kRunning) {
    return status;
  }
  haltChildren();
  branch_ = 0;
  return status == Status::kFailure ? failFrom(branch) : status;
}

void IfThenElse::onHalt() {
  haltChildren();
  branch_ = 0;
}

// --- WhileDoElse ------------------------------------------------------------------------------

Status WhileDoElse::onTick() {
  TreeNode& condition = *children_[0];
  const Status holds = condition.tick();
  if (holds == Status::kRunning || holds == Status::kSkipped) {
    return holds;
  }
  Status status = Status::kFailure;
  const TreeNode* origin = &condition;
  if (holds == Status::kSuccess) {
    if (children_.size() == 3) {
      children_[2]->halt();
    }
    origin = children_[1];
    status = children_[1]->tick();
  } else if (children_.size() == 3) {
    children_[1]->halt();
    origin = children_[2];
    status = children_[2]->tick();
  }
  if (status == Status::kRunning) {
    return status;
  }
  haltChildren();
  return status == Status::kFailure ? failFrom(*origin) : status;
}

// --- TryCatch ---------------------------------------------------------------------------------

TryCatch::TryCatch(std::string id, std::string name, bool catch_on_halt)
    : ControlNode(std::move(id), std::move(name)), catch_on_halt_(catch_on_halt) {}

Status TryCatch::onTick() {
  const std::size_t try_count = children_.size() - 1;
  if (status() != Status::kRunning) {
    skipped_ = 0;
    failed_ = nullptr;
  }
  while (failed_ == nullptr && index_ < try_count) {
    TreeNode& child = *children_[index_];
    switch (child.tick()) {
      case Status::kRunning:
        return Status::kRunning;
      case Status::kFailure:
        haltChildren();
        index_ = 0;
        failed_ = &child;  // enter the catch block, in this same tick
        break;
      case Status::kSkipped:
        ++skipped_;
        ++index_;
        break;
      default:
        ++index_;
    }
  }
  if (failed_ == nullptr) {
    haltChildren();
    index_ = 0;
    return skipped_ == try_count ? Status::kSkipped : Status::kSuccess;
  }
  if (children_.back()->tick() == Status::kRunning) {
    return Status::kRunning;
  }
  // The catch block finished, either way: FAILURE, with the try block's reason.
  const TreeNode* failed = failed_;
  haltChildren();
  failed_ = nullptr;
  return failFrom(*failed);
}

void TryCatch::onHalt() {
  if (catch_on_halt_ && failed_ == nullptr) {
    // Halted during the try block: halt it, then run the catch block once, best effort (a
    // catch block that takes time is halted right after its first tick, as BehaviorTree.CPP).
    haltChildren(0);
    TreeNode& catch_block = *children_.back();
    if (catch_block.tick() == Status::kRunning) {
      catch_block.halt();
    }
  }
  haltChildren();
  index_ = 0;
  failed_ = nullptr;
}

}  // namespace costar::bt
