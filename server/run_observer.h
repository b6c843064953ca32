#pragma once
// The tree observer of one run: each status transition sets the node's status in the run (what
// the stream and GET /api/runs/{id} show) and, for a plan run, goes to the run log. Runs on the
// engine thread (the executor's), which ticks the tree.

#include <cstddef>
#include <mutex>

#include "bt/tree.h"
#include "server/run_log_writer.h"
#include "server/run_state.h"

namespace costar::server {

class RunObserver final : public bt::TreeObserver {
 public:
  /// `run` (its statuses guarded by `mutex`, which network threads take to read them) and `log`
  /// (null: nothing logged) must outlive the observer. A plan run's log keeps its first
  /// `max_logged_transitions` transitions; the rest are counted and the run marked truncated.
  RunObserver(RunState& run, std::mutex& mutex, RunLogWriter* log, std::size_t max_logged_transitions)
      : run_(run), mutex_(mutex), log_(log), max_logged_transitions_(max_logged_transitions) {}

  void onTransition(TimePoint time, const bt::TreeNode& node, bt::Status from, bt::Status to) override;

 private:
  RunState& run_;
  std::mutex& mutex_;
  RunLogWriter* log_;
  std::size_t max_logged_transitions_;
};

}  // namespace costar::server
