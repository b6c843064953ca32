#pragma once
// Paces a simulated clock for a person watching: simulated time may run at most `factor`
// times as fast as wall time. The simulated cell's clock otherwise runs as fast as the machine
// allows.

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

}  // namespace costar::server
