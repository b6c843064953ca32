#include "server/run_observer.h"

#include "component/nodes.h"

namespace costar::server {

using nlohmann::json;

void RunObserver::onTransition(TimePoint time, const bt::TreeNode& node, bt::Status from, bt::Status to) {
  if (node.uid() >= run_.statuses.size()) {
    return;
  }
  // An operation's result data (SmartMove's candidates, ...) when it completes.
  json data;
  if (bt::isCompleted(to)) {
    if (const auto* operation = dynamic_cast<const component::OperationNode*>(&node)) {
      const json& result_data = operation->lastResult().data;
      if (!result_data.is_null() && !result_data.empty()) {
        data = result_data;
      }
    }
  }
  TransitionRecord record;
  record.t = toSeconds(time - run_.start_time);
  record.uid = node.uid();
  record.from = bt::toString(from);
  record.to = bt::toString(to);
  if (to == bt::Status::kFailure) {
    record.reason = std::string(node.failureReason());
    record.origin = node.failureOrigin().path();
  }
  // The node's status as the browser sees it, marked for the stream's next read.
  bool keep = false;
  {
    const std::lock_guard lock(mutex_);
    RunState::Node& state = run_.statuses[node.uid()];
    state.current = to;
    if (to == bt::Status::kIdle) {
      if (from == bt::Status::kRunning) {
        state.last = "HALTED";
      }
    } else {
      state.last = bt::toString(to);
    }
    if (to == bt::Status::kRunning) {
      state.reason.clear();
      state.origin.clear();
    } else if (to == bt::Status::kFailure) {
      state.reason = record.reason;
      state.origin = record.origin;
    }
    if (!data.is_null()) {
      state.data = data;
    }
    if (!state.dirty) {
      state.dirty = true;
      run_.dirty.push_back(node.uid());
    }
    record.seq = ++run_.transitions;
    keep = !run_.operation && log_ != nullptr && record.seq <= max_logged_transitions_;
    if (!run_.operation && record.seq > max_logged_transitions_) {
      run_.truncated = true;
    }
  }
  // A plan run's transition to the run log, up to the limit.
  if (keep) {
    if (!data.is_null()) {
      record.data = jsonText(data);
    }
    log_->addTransition(run_.id, std::move(record));
  }
}

}  // namespace costar::server
