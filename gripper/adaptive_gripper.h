#pragma once
// A 3-finger adaptive gripper (a Robotiq 3-Finger Adaptive Gripper or the simulated one) as a
// CoSTAR component implementing the abstract Gripper. Three fingers, finger_middle opposing
// finger_1 and finger_2, each closing until it stops on the part, squeezing with at most the
// commanded force; four modes set by the scissor axis (gripper/adaptive_gripper_driver.h).
// Its predicates come from the fingers' readings, never from the last command:
//   gripper_open      every finger (nearly) fully open
//   gripper_closed    every finger that closes in the current mode fully closed, touching nothing
//   gripper_holding   at least two closing fingers touch something, squeeze it and stand still
//                     (an encompassing grasp may wrap a small part with the fingers nearly closed)
//   gripper_mode(m)   m = basic, pinch, wide or scissor (the mode the scissor axis reached)
// Operations: Open, Close, SetMode(mode) and, for the abstract Gripper, BasicMode, PinchMode,
// WideMode, ScissorMode. The mode changes only with the fingers open (a change while holding
// would drop the part): SetMode with closed fingers fails and says so.

#include <functional>
#include <map>
#include <memory>

#include "component/operation_table.h"
#include "core/clock.h"
#include "gripper/adaptive_gripper_description.h"
#include "gripper/adaptive_gripper_driver.h"

namespace costar::gripper {

struct AdaptiveGripperOptions {
  std::string name = "gripper";
  double speed = 0.6;   // full strokes per second, default for Open and Close
  double force = 40.0;  // N per finger, default grip force
  /// Close, Open and SetMode fail when the fingers (or the scissor axis) have not settled after this long.
  Duration timeout = std::chrono::seconds(4);
  /// A reading older than this (by the driver's stamp) means the driver stopped updating.
  Duration reading_timeout = std::chrono::milliseconds(50);
};

class AdaptiveGripper final : public component::TableComponent {
 public:
  /// The driver and clock must outlive the component.
  AdaptiveGripper(AdaptiveGripperDriver& driver, const Clock& clock, AdaptiveGripperDescription description,
                  AdaptiveGripperOptions options = {});
  world::Report report() const override;

  /// Thresholds of the predicates (finger positions 0 open .. 1 closed): open below 0.03;
  /// closed above 0.97 without contact; holding when a finger touches something, squeezes it
  /// with more than 2 N and moves slower than 0.1 strokes/s.
  static constexpr double kOpenBelow = 0.03;
  static constexpr double kClosedAbove = 0.97;
  static constexpr double kHoldingForce = 2.0;
  static constexpr double kHoldingSpeed = 0.1;
  /// SetMode needs every finger below this (fingers open, nothing held).
  static constexpr double kModeChangeBelow = 0.1;

  /// The driver's reading, checked: finite and fresh. @throws std::runtime_error naming the problem.
  AdaptiveGripperReading checkedRead() const;
  /// How many of the mode's closing fingers hold something in `reading`.
  int holdingFingers(const AdaptiveGripperReading& reading) const;
  const AdaptiveGripperDescription& gripper() const { return gripper_; }

 private:
  std::unique_ptr<component::RunningOperation> setMode(GripperMode mode);

  AdaptiveGripperDriver& driver_;
  const Clock& clock_;
  AdaptiveGripperDescription gripper_;
  AdaptiveGripperOptions options_;
};

}  // namespace costar::gripper
