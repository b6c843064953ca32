// The run-log writer: a thread that writes each plan run's nodes and transitions to the store
// and snapshots of the cell in batches (every 200 ms), so ticks never wait for the disk.

#include "server/engine_parts.h"

namespace costar::server {

void Engine::queuePending() {
  if (log_pending_.empty() && log_pending_states_.empty()) {
    return;
  }
  LogCommand pending;
  pending.kind = LogCommand::Kind::kTransitions;
  pending.record.id = log_pending_run_;
  pending.transitions.swap(log_pending_);
  pending.states.swap(log_pending_states_);
  log_queue_.push_back(std::move(pending));
}

void Engine::pushLog(LogCommand command) {
  {
    const std::lock_guard lock(log_mutex_);
    if (command.kind == LogCommand::Kind::kEnd) {
      queuePending();
    }
    log_queue_.push_back(std::move(command));
  }
  log_cv_.notify_all();
}

void Engine::logWriterLoop() {
  while (true) {
    std::deque<LogCommand> commands;
    bool stopping = false;
    {
      std::unique_lock lock(log_mutex_);
      log_cv_.wait_for(lock, std::chrono::milliseconds(200), [this] { return log_stopping_ || !log_queue_.empty(); });
      queuePending();
      commands.swap(log_queue_);
      stopping = log_stopping_;
    }
    for (LogCommand& command : commands) {
      if (store_ == nullptr) {
        continue;
      }
      try {
        switch (command.kind) {
          case LogCommand::Kind::kBegin:
            store_->beginRun(command.record, command.nodes);
            break;
          case LogCommand::Kind::kTransitions:
            store_->appendTransitions(command.record.id, command.transitions);
            store_->appendStates(command.record.id, command.states);
            break;
          case LogCommand::Kind::kEnd:
            store_->endRun(command.record);
            break;
        }
      } catch (const std::exception&) {
        // The run log is best effort: a full disk must not stop the robot.
      }
    }
    if (stopping && commands.empty()) {
      return;
    }
  }
}

}  // namespace costar::server
