#pragma once
// The root that generates ticks: ticks a Tree at a fixed rate against a Clock until it
// completes, is stopped, or runs out of time.

#include <atomic>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>

#include "bt/tree.h"
#include "core/clock.h"

namespace costar::bt {

struct ExecutorOptions {
  /// Time between ticks (clock time). 10 ms = 100 Hz.
  Duration tick_period = std::chrono::milliseconds(10);
  /// Halt the tree and report FAILURE once this much clock time has passed; none if empty.
  std::optional<Duration> time_limit;
  /// Immediate re-ticks allowed between two periods (a loop whose child completes every tick
  /// asks for one each run); beyond it the executor waits for the next period.
  std::uint32_t max_immediate_ticks = 100000;
};

struct RunResult {
  /// SUCCESS or FAILURE; IDLE when stopped by requestStop().
  Status status = Status::kIdle;
  bool stopped = false;
  std::uint64_t ticks = 0;
  Duration elapsed{};
  /// On FAILURE: where (node path) and why.
  std::string failure_path;
  std::string failure_reason;
};

class Executor {
 public:
  /// The tree and clock must outlive the executor.
  Executor(Tree& tree, Clock& clock, ExecutorOptions options = {});

  /// Called before every tick (e.g. to refresh the world state, apply pause).
  void setBeforeTick(std::function<void()> hook) { before_tick_ = std::move(hook); }

  /// Ticks until the tree completes, stop is requested, or the time limit passes. A stop or
  /// the time limit halts the tree, which cancels running operations.
  RunResult run();

  /// Thread-safe: the run halts the tree at the next tick boundary and returns.
  void requestStop() { stop_requested_.store(true); }
  /// Thread-safe: stops ticking the tree (operations already running go on: a Move finishes
  /// its motion) until resume(); time goes on. step() while paused ticks exactly once.
  void pause() { paused_.store(true); }
  void resume() { paused_.store(false); }
  void step() { steps_requested_.fetch_add(1); }
  bool paused() const { return paused_.load(); }

 private:
  Tree& tree_;
  Clock& clock_;
  ExecutorOptions options_;
  std::function<void()> before_tick_;
  std::atomic<bool> stop_requested_{false};
  std::atomic<bool> paused_{false};
  std::atomic<int> steps_requested_{0};
};

}  // namespace costar::bt
