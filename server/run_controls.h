#pragma once
// Pause, resume, step and stop of the active run: network threads (and the fatal-error path)
// ask, the engine thread applies the requests before each tick of the run. Pausing holds the
// cell (the Engine does not advance the clock while paused); a step ticks the tree once and
// lets one tick period pass, then the run is paused.

#include <atomic>

#include "bt/executor.h"
#include "server/backend.h"

namespace costar::server {

class RunControls {
 public:
  /// Asks for `control` (any thread).
  void request(RunControl control);
  /// Asks the run to stop (any thread). Async-signal-safe.
  void requestStop() noexcept { stop_requested_ = true; }

  /// Engine thread: forgets every request; the run starts (or stays) paused or not.
  void reset(bool paused);
  /// Engine thread: sets whether the run is paused, keeping the requests.
  void setPaused(bool paused) { paused_ = paused; }
  /// Whether the run is paused (any thread).
  bool paused() const { return paused_.load(); }

  /// Engine thread, before a tick: applies the stop (asks `executor` to stop: true), pause and
  /// resume requests; a step asked for while running pauses after it.
  bool apply(bt::Executor& executor);
  /// Engine thread, while paused: true (taking it) when a step was asked for.
  bool takeStep();

 private:
  std::atomic<bool> stop_requested_{false};
  std::atomic<int> pause_requested_{0};  // +1 pause, -1 resume
  std::atomic<int> steps_requested_{0};
  std::atomic<bool> paused_{false};
};

}  // namespace costar::server
