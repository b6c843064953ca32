#pragma once
// Paces a simulated clock for a person watching: simulated time may run at most `factor`
// times as fast as wall time (Pacer), at the pace asked for now (PaceControl). The simulated
// cell's clock otherwise runs as fast as the machine allows.

#include <algorithm>
#include <atomic>
#include <chrono>

#include "core/clock.h"

namespace costar::server {

class Pacer {
 public:
  using WallClock = std::chrono::steady_clock;

  /// `factor` simulated seconds per wall second; 0 or less: no pacing.
  explicit Pacer(double factor = 1.0) : factor_(factor) {}

  double factor() const { return factor_; }
  /// Changes the factor; time is measured afresh from the next call.
  void setFactor(double factor) {
    factor_ = factor;
    anchored_ = false;
  }

  /// How long to wait at wall time `wall` so that simulated time `sim` is not ahead of the
  /// pace. When the simulation falls behind (a long computation), it is not allowed to race
  /// to catch up by more than `max_lag`: the reference moves instead.
  WallClock::duration delay(TimePoint sim, WallClock::time_point wall) {
    if (factor_ <= 0) {
      return WallClock::duration::zero();
    }
    if (!anchored_ || sim < sim_anchor_) {
      anchor(sim, wall);
      return WallClock::duration::zero();
    }
    const auto sim_elapsed = std::chrono::duration<double>(sim - sim_anchor_).count();
    const auto due = wall_anchor_ + std::chrono::duration_cast<WallClock::duration>(
                                        std::chrono::duration<double>(sim_elapsed / factor_));
    if (due > wall) {
      return due - wall;
    }
    if (wall - due > max_lag_) {
      anchor(sim, wall);  // fell behind: do not burst to catch up
    }
    return WallClock::duration::zero();
  }

  /// Forget the reference (e.g. after the simulation stood still on purpose).
  void reset() { anchored_ = false; }

 private:
  void anchor(TimePoint sim, WallClock::time_point wall) {
    sim_anchor_ = sim;
    wall_anchor_ = wall;
    anchored_ = true;
  }

  double factor_;
  bool anchored_ = false;
  TimePoint sim_anchor_{};
  WallClock::time_point wall_anchor_{};
  WallClock::duration max_lag_ = std::chrono::milliseconds(250);
};

/// The pace the engine thread keeps, asked for by any thread: `pace` simulated seconds per wall
/// second while a plan runs (0: as fast as the machine allows); between runs the idle loop runs
/// at `pace`, or at real time when it is 0.
class PaceControl {
 public:
  explicit PaceControl(double pace) : pace_(pace) { pacer_.setFactor(idleFactor(pace)); }

  /// The pace in force (any thread).
  double pace() const { return pace_.load(); }
  /// Asks for `pace` (any thread; negative: 0); in force from the engine thread's next apply().
  void request(double pace) { request_ = std::max(0.0, pace); }

  /// Engine thread, before a tick: puts the pace asked for in force, if any.
  void apply() {
    if (const double pace = request_.exchange(-1); pace >= 0) {
      pace_ = pace;
      pacer_.setFactor(running_ && pace <= 0 ? 0.0 : idleFactor(pace));
    }
  }
  /// Engine thread: a plan run begins (paced at the pace, or not at all) or has ended.
  void runBegins() {
    running_ = true;
    pacer_.setFactor(pace_.load());
  }
  void runEnds() {
    running_ = false;
    pacer_.setFactor(idleFactor(pace_.load()));
  }
  /// Engine thread: the clock stood still on purpose (a paused run, a new scene): no burst to
  /// catch up.
  void reset() { pacer_.reset(); }
  /// Engine thread: how long to wait at wall time `wall` before a tick at simulated time `sim`.
  Pacer::WallClock::duration delay(TimePoint sim, Pacer::WallClock::time_point wall) { return pacer_.delay(sim, wall); }

 private:
  static double idleFactor(double pace) { return pace > 0 ? pace : 1.0; }

  Pacer pacer_;
  std::atomic<double> pace_;
  std::atomic<double> request_{-1};
  bool running_ = false;
};

}  // namespace costar::server
