#pragma once
// What a gripper's hardware (or the simulator) offers the Gripper component: finger state
// from its sensors, and a command.

#include <string>

#include "core/clock.h"

namespace costar::gripper {

struct FingerReading {
  double opening = 0.0;        // distance between the fingers, m
  double opening_speed = 0.0;  // m/s (negative while closing)
  double force = 0.0;          // squeezing force, N
  bool contact = false;        // the fingers touch something (tactile/current sensing)
  /// When it was measured; TimePoint{} from a driver that does not stamp its readings.
  TimePoint stamp{};
};

class GripperDriver {
 public:
  virtual ~GripperDriver() = default;
  virtual FingerReading read() const = 0;
  /// Moves toward `opening` (m) at `speed` (m/s), squeezing with at most `force` (N).
  virtual void command(double opening, double speed, double force) = 0;
  virtual double maxOpening() const = 0;
};

}  // namespace costar::gripper
