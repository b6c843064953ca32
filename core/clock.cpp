#include "core/clock.h"

#include <algorithm>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <thread>

namespace costar {

Duration checkedDuration(double seconds, std::string_view what) {
  // NaN fails every comparison: the condition is written so that it fails this one.
  if (!(seconds >= 0.0 && seconds <= kMaxDurationSeconds)) {
    char text[160];
    std::snprintf(text, sizeof text, ": must be a number of seconds from 0 to %g, not %g", kMaxDurationSeconds,
                  seconds);
    throw std::invalid_argument(std::string(what) + text);
  }
  return fromSeconds(seconds);
}

RealClock::RealClock() : start_(std::chrono::steady_clock::now()) {}

TimePoint RealClock::now() const {
  return TimePoint(std::chrono::duration_cast<Duration>(std::chrono::steady_clock::now() - start_));
}

void RealClock::sleepUntil(TimePoint t) {
  const auto deadline = start_ + t.time_since_epoch();
  if (deadline > std::chrono::steady_clock::now()) {
    std::this_thread::sleep_until(deadline);
  }
}

TimePoint SimClock::now() const { return TimePoint(Duration(now_ns_.load(std::memory_order_acquire))); }

void SimClock::advanceTo(TimePoint t) {
  const TimePoint from = now();
  if (t <= from) {
    return;
  }
  std::vector<StepListener> listeners;
  {
    std::lock_guard lock(listeners_mutex_);
    listeners.reserve(listeners_.size());
    for (const auto& [handle, listener] : listeners_) {
      listeners.push_back(listener);
    }
  }
  for (const auto& listener : listeners) {
    listener(from, t);
  }
  now_ns_.store(t.time_since_epoch().count(), std::memory_order_release);
}

int SimClock::addStepListener(StepListener listener) {
  std::lock_guard lock(listeners_mutex_);
  const int handle = next_handle_++;
  listeners_.emplace_back(handle, std::move(listener));
  return handle;
}

void SimClock::removeStepListener(int handle) {
  std::lock_guard lock(listeners_mutex_);
  std::erase_if(listeners_, [handle](const auto& entry) { return entry.first == handle; });
}

}  // namespace costar
