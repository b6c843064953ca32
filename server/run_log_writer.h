#pragma once
// The run log's writer: a thread of its own that writes each plan run to the store (its nodes
// when it starts, its transitions and snapshots of the cell in batches every 200 ms, its end),
// so that the engine thread's ticks never wait for the disk. Best effort: a store that fails
// (a full disk) loses log entries, never stops the robot.

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <mutex>
#include <thread>
#include <vector>

#include "server/store.h"

namespace costar::server {

class RunLogWriter {
 public:
  /// `store` must outlive the writer.
  explicit RunLogWriter(Store& store) : store_(store) {}
  /// stop().
  ~RunLogWriter();
  RunLogWriter(const RunLogWriter&) = delete;
  RunLogWriter& operator=(const RunLogWriter&) = delete;

  /// Starts the thread. Once.
  void start();
  /// Writes what is queued and ends the thread. Idempotent.
  void stop();

  /// A plan run began: its record (id, plan, version, XML, start time, cell) and its nodes.
  void begin(RunRecord record, std::vector<RunNode> nodes);
  /// A transition of run `run` (written with the next batch).
  void addTransition(std::int64_t run, TransitionRecord transition);
  /// A snapshot of the cell during run `run` (written with the next batch).
  void addState(std::int64_t run, StateRecord state);
  /// A plan run ended: what is pending is written first, then its end (result, times, counts).
  void end(RunRecord record);

 private:
  struct Command {
    enum class Kind { kBegin, kTransitions, kEnd } kind = Kind::kBegin;
    RunRecord record;
    std::vector<RunNode> nodes;
    std::vector<TransitionRecord> transitions;
    std::vector<StateRecord> states;
  };

  void loop();
  void push(Command command);
  /// Moves the pending transitions and snapshots to the queue as one command (mutex_ held).
  void queuePending();

  Store& store_;
  std::thread thread_;
  std::mutex mutex_;
  std::condition_variable cv_;
  std::deque<Command> queue_;
  std::vector<TransitionRecord> pending_;
  std::vector<StateRecord> pending_states_;
  std::int64_t pending_run_ = 0;
  bool stopping_ = false;
};

}  // namespace costar::server
