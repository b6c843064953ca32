#pragma once
// Work handed to one thread (the engine's, which alone touches the workcell) by others, who
// wait for its answer: call() from any thread, runPending() and waitUntil() on the owner.

#include <chrono>
#include <condition_variable>
#include <deque>
#include <functional>
#include <future>
#include <memory>
#include <mutex>
#include <string>

#include "core/clock.h"
#include "server/backend.h"

namespace costar::server {

class TaskQueue {
 public:
  /// Takes tasks from now on; false when it was open or closed before.
  bool open();
  /// Refuses tasks from now on and wakes the owner; false when it was not open.
  bool close();
  /// Wakes the owner waiting in waitUntil() (a request it should look at).
  void notify() { cv_.notify_all(); }

  /// Runs `task` on the owner and waits up to `timeout` for its result (or its exception).
  /// The task owns what it uses (captured by value): it may run after the caller gave up.
  /// @throws BackendBusy when the queue is not open, the owner did not answer in time or
  /// closed the queue before answering.
  template <typename F>
  auto call(F task, std::chrono::milliseconds timeout) -> decltype(task());

  /// Owner: runs the tasks queued, in order, until none is left.
  void runPending();
  /// Owner: waits until `deadline`, a task comes or the queue closes, whichever is first.
  void waitUntil(std::chrono::steady_clock::time_point deadline);

 private:
  std::mutex mutex_;
  std::condition_variable cv_;
  std::deque<std::function<void()>> tasks_;
  bool open_ = false;
  bool closed_ = false;
};

template <typename F>
auto TaskQueue::call(F task, std::chrono::milliseconds timeout) -> decltype(task()) {
  using Result = decltype(task());
  auto packaged = std::make_shared<std::packaged_task<Result()>>(std::move(task));
  std::future<Result> future = packaged->get_future();
  {
    const std::lock_guard lock(mutex_);
    if (!open_) {
      throw BackendBusy("the engine is not running (the server is stopping)");
    }
    tasks_.emplace_back([packaged] { (*packaged)(); });
  }
  cv_.notify_all();
  if (future.wait_for(timeout) != std::future_status::ready) {
    throw BackendBusy("the engine did not answer within " + std::to_string(toSeconds(timeout)) +
                      " s (busy with a long computation); try again");
  }
  try {
    return future.get();
  } catch (const std::future_error&) {
    throw BackendBusy("the engine stopped before answering");
  }
}

}  // namespace costar::server
