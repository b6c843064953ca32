#include "bt/decorator_nodes.h"

#include <chrono>

namespace costar::bt {

Status Inverter::onTick() {
  switch (child_->tick()) {
    case Status::kSuccess:
      child_->halt();
      return failStatic("Inverter: child succeeded, inverted to FAILURE");
    case Status::kFailure:
      child_->halt();
      return Status::kSuccess;
    case Status::kSkipped:
      return Status::kSkipped;
    default:
      return Status::kRunning;
  }
}

Status ForceSuccess::onTick() {
  const Status status = child_->tick();
  if (status == Status::kRunning || status == Status::kSkipped) {
    return status;
  }
  child_->halt();
  return Status::kSuccess;
}

Status ForceFailure::onTick() {
  const Status status = child_->tick();
  if (status == Status::kRunning || status == Status::kSkipped) {
    return status;
  }
  child_->halt();
  return status == Status::kFailure ? failFrom(*child_)
                                    : failStatic("ForceFailure: child succeeded, forced to FAILURE");
}

// --- Repeat ----------------------------------------------------------------------------

Repeat::Repeat(std::string id, std::string name, int num_cycles)
    : DecoratorNode(std::move(id), std::move(name)), num_cycles_(num_cycles) {}

Status Repeat::onTick() {
  const Status status = child_->tick();
  if (status == Status::kRunning) {
    return status;
  }
  if (status == Status::kSkipped) {
    count_ = 0;
    return status;
  }
  child_->halt();
  if (status == Status::kFailure) {
    count_ = 0;
    return failFrom(*child_);
  }
  ++count_;
  if (num_cycles_ >= 0 && count_ >= num_cycles_) {
    count_ = 0;
    return Status::kSuccess;
  }
  context().requestImmediateTick();
  return Status::kRunning;
}

void Repeat::onHalt() {
  child_->halt();
  count_ = 0;
}

// --- RepeatRuns ------------------------------------------------------------------------

RepeatRuns::RepeatRuns(std::string id, std::string name, int num_runs)
    : DecoratorNode(std::move(id), std::move(name)), num_runs_(num_runs) {}

Status RepeatRuns::onTick() {
  const Status status = child_->tick();
  if (status == Status::kRunning) {
    return status;
  }
  if (status == Status::kSkipped) {
    count_ = 0;
    return status;
  }
  child_->halt();
  ++count_;
  if (num_runs_ >= 0 && count_ >= num_runs_) {
    count_ = 0;
    return Status::kSuccess;
  }
  context().requestImmediateTick();
  return Status::kRunning;
}

void RepeatRuns::onHalt() {
  child_->halt();
  count_ = 0;
}

// --- Reset -----------------------------------------------------------------------------

Reset::Reset(std::string id, std::string name, int num_resets)
    : DecoratorNode(std::move(id), std::move(name)), num_resets_(num_resets) {}

Status Reset::onTick() {
  if (exhausted_) {
    return failFrom(*child_);  // budget spent: pass the last FAILURE on, child untouched
  }
  const Status status = child_->tick();
  if (status == Status::kRunning || status == Status::kSkipped) {
    return status;
  }
  if (status == Status::kSuccess) {
    child_->halt();
    return Status::kSuccess;
  }
  if (num_resets_ < 0 || resets_done_ < num_resets_) {
    ++resets_done_;
    child_->reset();
  } else {
    exhausted_ = true;
  }
  return failFrom(*child_);
}

void Reset::onReset() {
  resets_done_ = 0;
  exhausted_ = false;
}

// --- Timeout ---------------------------------------------------------------------------

Timeout::Timeout(std::string id, std::string name, Duration limit)
    : DecoratorNode(std::move(id), std::move(name)),
      limit_(limit),
      reason_("Timeout: child did not complete within " +
              std::to_string(std::chrono::duration_cast<std::chrono::milliseconds>(limit).count()) + " ms") {}

Status Timeout::onTick() {
  const TimePoint now = context().now();
  if (!started_) {
    started_ = true;
    deadline_ = now + limit_;
  } else if (now >= deadline_) {
    child_->halt();
    started_ = false;
    return fail(reason_);
  }
  const Status status = child_->tick();
  if (status == Status::kRunning) {
    return status;
  }
  started_ = false;
  child_->halt();
  return status == Status::kFailure ? failFrom(*child_) : status;
}

void Timeout::onHalt() {
  child_->halt();
  started_ = false;
}

// --- RetryUntilSuccessful --------------------------------------------------------------

RetryUntilSuccessful::RetryUntilSuccessful(std::string id, std::string name, int num_attempts)
    : DecoratorNode(std::move(id), std::move(name)), num_attempts_(num_attempts) {}

Status RetryUntilSuccessful::onTick() {
  const Status status = child_->tick();
  if (status == Status::kRunning) {
    return status;
  }
  if (status == Status::kSkipped) {
    attempts_ = 0;
    return status;
  }
  child_->halt();
  if (status == Status::kSuccess) {
    attempts_ = 0;
    return status;
  }
  ++attempts_;
  if (num_attempts_ >= 0 && attempts_ >= num_attempts_) {
    attempts_ = 0;
    return failFrom(*child_);
  }
  context().requestImmediateTick();
  return Status::kRunning;
}

void RetryUntilSuccessful::onHalt() {
  child_->halt();
  attempts_ = 0;
}

// --- SubTree ---------------------------------------------------------------------------

SubTreeNode::SubTreeNode(std::string id, std::string name, std::string subtree_id)
    : DecoratorNode(std::move(id), std::move(name)), subtree_id_(std::move(subtree_id)) {}

std::string SubTreeNode::pathSegment(std::size_t /*index_in_parent*/) const {
  return name().empty() ? subtree_id_ : subtree_id_ + " \"" + name() + "\"";
}

Status SubTreeNode::onTick() {
  const Status status = child_->tick();
  if (status == Status::kRunning) {
    return status;
  }
  child_->halt();
  return status == Status::kFailure ? failFrom(*child_) : status;
}

// --- KeepRunningUntilFailure ------------------------------------------------------------

Status KeepRunningUntilFailure::onTick() {
  const Status status = child_->tick();
  switch (status) {
    case Status::kFailure:
      child_->halt();
      return failFrom(*child_);
    case Status::kSuccess:
      child_->halt();
      return Status::kRunning;  // run it again on the next tick
    default:
      return status;
  }
}

// --- Delay -------------------------------------------------------------------------------

Delay::Delay(std::string id, std::string name, Duration delay)
    : DecoratorNode(std::move(id), std::move(name)), delay_(delay) {}

Status Delay::onTick() {
  const TimePoint now = context().now();
  if (!started_) {
    started_ = true;
    ticking_child_ = false;
    deadline_ = now + delay_;
  }
  if (!ticking_child_) {
    if (now < deadline_) {
      return Status::kRunning;
    }
    ticking_child_ = true;
  }
  const Status status = child_->tick();
  if (status == Status::kRunning) {
    return status;
  }
  started_ = false;
  child_->halt();
  return status == Status::kFailure ? failFrom(*child_) : status;
}

void Delay::onHalt() {
  child_->halt();
  started_ = false;
}

// --- RunOnce -------------------------------------------------------------------------------

RunOnce::RunOnce(std::string id, std::string name, bool then_skip)
    : DecoratorNode(std::move(id), std::move(name)), then_skip_(then_skip) {}

Status RunOnce::onTick() {
  if (done_) {
    if (then_skip_) {
      return Status::kSkipped;
    }
    return result_ == Status::kFailure ? failFrom(*child_) : result_;
  }
  const Status status = child_->tick();
  if (status == Status::kRunning || status == Status::kSkipped) {
    return status;
  }
  done_ = true;
  result_ = status;
  child_->halt();
  return status == Status::kFailure ? failFrom(*child_) : status;
}

void RunOnce::onReset() {
  done_ = false;
  result_ = Status::kIdle;
}

}  // namespace costar::bt
