#include "bt/executor.h"

#include <algorithm>

namespace costar::bt {

Executor::Executor(Tree& tree, Clock& clock, ExecutorOptions options) : tree_(tree), clock_(clock), options_(options) {}

RunResult Executor::run() {
  RunResult result;
  stop_requested_.store(false);
  const TimePoint start = clock_.now();
  TimePoint next_tick = start;
  std::uint32_t immediate_ticks = 0;
  TreeContext& context = tree_.context();
  context.takeImmediateTickRequest();

  while (true) {
    if (stop_requested_.load()) {
      tree_.halt();
      result.stopped = true;
      result.status = Status::kIdle;
      break;
    }
    if (options_.time_limit && clock_.now() - start >= *options_.time_limit) {
      tree_.halt();
      result.status = Status::kFailure;
      result.failure_path = tree_.mainTreeId();
      result.failure_reason =
          "run exceeded its time limit of " + std::to_string(toSeconds(*options_.time_limit)) + " s";
      break;
    }
    if (before_tick_) {
      before_tick_();
    }
    if (paused_.load()) {
      if (steps_requested_.load() == 0) {
        next_tick += options_.tick_period;
        clock_.sleepUntil(std::max(next_tick, clock_.now()));
        continue;  // paused: no tick, but time (and the robot) goes on
      }
      steps_requested_.fetch_sub(1);
    }
    const Status status = tree_.tick();
    ++result.ticks;
    if (status == Status::kSkipped) {
      // BehaviorTree.CPP returns SKIPPED from the root; a run that did nothing did not succeed.
      result.status = Status::kFailure;
      result.failure_path = tree_.root().path();
      result.failure_reason = "the whole tree was skipped: nothing in it ran (RunOnce had run already)";
      break;
    }
    if (isCompleted(status)) {
      result.status = status;
      if (status == Status::kFailure) {
        const TreeNode& root = tree_.root();
        result.failure_path = root.failureOrigin().path();
        result.failure_reason = std::string(root.failureReason());
      }
      break;
    }
    if (context.takeImmediateTickRequest() && !paused_.load() && immediate_ticks < options_.max_immediate_ticks) {
      ++immediate_ticks;
      continue;
    }
    immediate_ticks = 0;
    next_tick += options_.tick_period;
    const TimePoint now = clock_.now();
    if (next_tick < now) {
      next_tick = now;  // overran: do not try to catch up with a burst of ticks
    }
    clock_.sleepUntil(next_tick);
  }
  result.elapsed = clock_.now() - start;
  return result;
}

}  // namespace costar::bt
