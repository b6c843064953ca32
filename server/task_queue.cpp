#include "server/task_queue.h"

namespace costar::server {

bool TaskQueue::open() {
  const std::lock_guard lock(mutex_);
  if (open_ || closed_) {
    return false;
  }
  open_ = true;
  return true;
}

bool TaskQueue::close() {
  {
    const std::lock_guard lock(mutex_);
    if (!open_) {
      return false;
    }
    open_ = false;
    closed_ = true;
  }
  cv_.notify_all();
  return true;
}

void TaskQueue::runPending() {
  while (true) {
    std::function<void()> task;
    {
      const std::lock_guard lock(mutex_);
      if (tasks_.empty()) {
        return;
      }
      task = std::move(tasks_.front());
      tasks_.pop_front();
    }
    task();  // exceptions are carried by the packaged_task's future
  }
}

void TaskQueue::waitUntil(std::chrono::steady_clock::time_point deadline) {
  std::unique_lock lock(mutex_);
  cv_.wait_until(lock, deadline, [this] { return !tasks_.empty() || closed_; });
}

}  // namespace costar::server
