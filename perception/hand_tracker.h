#pragma once
// The hand over time (issue 31): from one HandObservation per camera frame, how long the hand has
// been still and whether it makes the offer gesture: an open palm turned up, held still for
// hold_seconds. A hand missed by a few frames in a row (the arm passing in front of it) keeps its
// state; longer, it is gone.

#include <optional>

#include "core/clock.h"
#include "perception/hand_detector.h"

namespace costar::perception {

struct HandTrackerOptions {
  /// Still: the hand's centre stays within this distance (m) of where it came to rest.
  double still_tolerance = 0.015;
  /// The gesture: an open palm up, still at least this long (s).
  double hold_seconds = 0.5;
  /// A hand not seen for longer than this (s) is gone.
  double lost_after = 0.3;
};

struct TrackedHand {
  HandObservation seen;  // the latest observation
  TimePoint seen_at{};
  /// How long the hand has been still (s), and how long its open palm has been up meanwhile.
  double still_seconds = 0.0;
  double offered_seconds = 0.0;
  bool still = false;
  bool gesture = false;
};

class HandTracker {
 public:
  explicit HandTracker(HandTrackerOptions options = {}) : options_(options) {}
  /// One frame's result (nothing: no hand seen) taken at `stamp`; stamps must not go back.
  /// @throws std::invalid_argument when `stamp` is before the previous one.
  void update(const std::optional<HandObservation>& seen, TimePoint stamp);
  /// The hand, when one has been seen within lost_after.
  const std::optional<TrackedHand>& hand() const { return hand_; }
  const HandTrackerOptions& options() const { return options_; }

 private:
  HandTrackerOptions options_;
  std::optional<TrackedHand> hand_;
  Eigen::Vector3d rest_ = Eigen::Vector3d::Zero();  // where the hand came to rest
  TimePoint rest_since_{};
  TimePoint offered_since_{};
  bool offering_ = false;
  TimePoint last_stamp_{};
  bool started_ = false;
};

}  // namespace costar::perception
