#pragma once
// Time for the whole system comes from a Clock that can be swapped: RealClock on hardware,
// SimClock (lockstep, as fast as the machine allows) for simulation, tests and trials.

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <mutex>
#include <string_view>
#include <vector>

namespace costar {

/// Durations and time points are integer nanoseconds since the clock's epoch (its creation).
using Duration = std::chrono::nanoseconds;
struct ClockEpoch {};
using TimePoint = std::chrono::time_point<ClockEpoch, Duration>;

/// Seconds as a double, for printing and JSON.
inline double toSeconds(Duration d) { return std::chrono::duration<double>(d).count(); }
inline double toSeconds(TimePoint t) { return toSeconds(t.time_since_epoch()); }
inline Duration fromSeconds(double s) { return std::chrono::duration_cast<Duration>(std::chrono::duration<double>(s)); }

/// The longest duration a person may give (an option, a fault's moment): 1e9 s, about 31 years.
/// Durations hold about 292 years; the margin keeps a moment plus such a duration in range.
inline constexpr double kMaxDurationSeconds = 1e9;

/// A number of seconds a person gave (`what`: "--time-limit") as a Duration, checked: NaN,
/// infinite, negative and above kMaxDurationSeconds are refused, as fromSeconds would overflow
/// (1e10 s became -9.2e9 s) or make a NaN mean something.
/// @throws std::invalid_argument "WHAT: must be a number of seconds from 0 to 1e+09, not X".
Duration checkedDuration(double seconds, std::string_view what);

/// A source of time. Implementations are thread-safe for now(); sleepUntil() is called by
/// one thread (the executor's).
class Clock {
 public:
  Clock() = default;
  Clock(const Clock&) = delete;
  Clock& operator=(const Clock&) = delete;
  virtual ~Clock() = default;

  /// Current time since this clock's epoch.
  virtual TimePoint now() const = 0;
  /// Waits (RealClock) or advances simulated time (SimClock) until `t`; returns at once if
  /// `t <= now()`.
  virtual void sleepUntil(TimePoint t) = 0;
  /// True when time is simulated and advances only through sleepUntil()/advance.
  virtual bool simulated() const = 0;
};

/// Wall time from std::chrono::steady_clock; epoch = construction.
class RealClock final : public Clock {
 public:
  RealClock();
  TimePoint now() const override;
  void sleepUntil(TimePoint t) override;
  bool simulated() const override { return false; }

 private:
  std::chrono::steady_clock::time_point start_;
};

/// Lockstep simulated time. Advancing it calls every step listener (e.g. the physics
/// simulator) with the interval to simulate, in registration order, before now() changes.
class SimClock final : public Clock {
 public:
  /// Called with (from, to) for each advance; the listener simulates that interval.
  using StepListener = std::function<void(TimePoint from, TimePoint to)>;

  TimePoint now() const override;
  void sleepUntil(TimePoint t) override { advanceTo(t); }
  bool simulated() const override { return true; }

  /// Advances to `t` (no-op when `t <= now()`).
  void advanceTo(TimePoint t);
  void advanceBy(Duration d) { advanceTo(now() + d); }

  /// Registers a listener; returns a handle for removeStepListener().
  int addStepListener(StepListener listener);
  void removeStepListener(int handle);

 private:
  std::atomic<std::int64_t> now_ns_{0};
  std::mutex listeners_mutex_;
  std::vector<std::pair<int, StepListener>> listeners_;
  int next_handle_ = 1;
};

}  // namespace costar
