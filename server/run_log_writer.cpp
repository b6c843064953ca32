#include "server/run_log_writer.h"

#include <chrono>

#include "server/guard.h"

namespace costar::server {

RunLogWriter::~RunLogWriter() { stop(); }

void RunLogWriter::start() {
  // An exception that escapes the loop is logged and the loop goes on (guard.h).
  thread_ = std::thread([this] {
    prepareServerThread("runlog");
    while (!guarded("run log writer", [this] { loop(); })) {
    }
  });
}

void RunLogWriter::stop() {
  {
    const std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  cv_.notify_all();
  if (thread_.joinable()) {
    thread_.join();
  }
}

void RunLogWriter::begin(RunRecord record, std::vector<RunNode> nodes) {
  Command command;
  command.kind = Command::Kind::kBegin;
  command.record = std::move(record);
  command.nodes = std::move(nodes);
  push(std::move(command));
}

void RunLogWriter::addTransition(std::int64_t run, TransitionRecord transition) {
  const std::lock_guard lock(mutex_);
  pending_run_ = run;
  pending_.push_back(std::move(transition));
}

void RunLogWriter::addState(std::int64_t run, StateRecord state) {
  const std::lock_guard lock(mutex_);
  pending_run_ = run;
  pending_states_.push_back(std::move(state));
}

void RunLogWriter::end(RunRecord record) {
  Command command;
  command.kind = Command::Kind::kEnd;
  command.record = std::move(record);
  push(std::move(command));
}

void RunLogWriter::queuePending() {
  if (pending_.empty() && pending_states_.empty()) {
    return;
  }
  Command pending;
  pending.kind = Command::Kind::kTransitions;
  pending.record.id = pending_run_;
  pending.transitions.swap(pending_);
  pending.states.swap(pending_states_);
  queue_.push_back(std::move(pending));
}

void RunLogWriter::push(Command command) {
  {
    const std::lock_guard lock(mutex_);
    if (command.kind == Command::Kind::kEnd) {
      queuePending();
    }
    queue_.push_back(std::move(command));
  }
  cv_.notify_all();
}

void RunLogWriter::loop() {
  while (true) {
    std::deque<Command> commands;
    bool stopping = false;
    {
      std::unique_lock lock(mutex_);
      cv_.wait_for(lock, std::chrono::milliseconds(200), [this] { return stopping_ || !queue_.empty(); });
      queuePending();
      commands.swap(queue_);
      stopping = stopping_;
    }
    for (Command& command : commands) {
      try {
        switch (command.kind) {
          case Command::Kind::kBegin:
            store_.beginRun(command.record, command.nodes);
            break;
          case Command::Kind::kTransitions:
            store_.appendTransitions(command.record.id, command.transitions);
            store_.appendStates(command.record.id, command.states);
            break;
          case Command::Kind::kEnd:
            store_.endRun(command.record);
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
