#include "perception/hand_tracker.h"

#include <stdexcept>

namespace costar::perception {

void HandTracker::update(const std::optional<HandObservation>& seen, TimePoint stamp) {
  if (started_ && stamp < last_stamp_) {
    throw std::invalid_argument("HandTracker: a frame stamped " + std::to_string(toSeconds(stamp.time_since_epoch())) +
                                " s, before the previous one's " +
                                std::to_string(toSeconds(last_stamp_.time_since_epoch())) + " s");
  }
  started_ = true;
  last_stamp_ = stamp;
  if (!seen) {
    if (hand_ && toSeconds(stamp - hand_->seen_at) > options_.lost_after) {
      hand_.reset();
    }
    return;
  }
  if (!hand_ || (seen->position - rest_).norm() > options_.still_tolerance) {
    rest_ = seen->position;
    rest_since_ = stamp;
  }
  if (!hand_ || !seen->open_palm_up || !offering_) {
    offered_since_ = stamp;
  }
  offering_ = seen->open_palm_up;
  TrackedHand hand;
  hand.seen = *seen;
  hand.seen_at = stamp;
  hand.still_seconds = toSeconds(stamp - rest_since_);
  hand.still = hand.still_seconds > 0.0;
  hand.offered_seconds = offering_ ? toSeconds(stamp - std::max(offered_since_, rest_since_)) : 0.0;
  hand.gesture = offering_ && hand.offered_seconds >= options_.hold_seconds;
  hand_ = hand;
}

}  // namespace costar::perception
