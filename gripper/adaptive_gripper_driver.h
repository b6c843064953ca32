#pragma once
// What a 3-finger adaptive gripper's hardware (or the simulator) offers the AdaptiveGripper
// component, modelled on the Robotiq 3-Finger Adaptive Gripper's interface: a mode (how the
// scissor axis places fingers 1 and 2), and per finger a position from open (0) to closed (1),
// a speed, a force limit, and the finger's own report that it stopped on something.

#include <array>
#include <optional>
#include <string>
#include <string_view>

#include "core/clock.h"

namespace costar::gripper {

/// The four grasping modes of a Robotiq-style 3-finger gripper.
enum class GripperMode {
  kBasic,    // fingers parallel, finger_middle opposing fingers 1 and 2: encompassing grasps
  kPinch,    // fingers 1 and 2 turned toward each other: fingertip grasps
  kWide,     // fingers 1 and 2 spread apart: long or wide parts
  kScissor,  // fingers 1 and 2 face each other and close sideways; finger_middle stays open
};
inline constexpr std::array<GripperMode, 4> kGripperModes = {GripperMode::kBasic, GripperMode::kPinch,
                                                             GripperMode::kWide, GripperMode::kScissor};
/// "basic", "pinch", "wide", "scissor" (the argument of the gripper_mode predicate).
std::string_view toString(GripperMode mode);
std::optional<GripperMode> modeFromString(std::string_view name);

/// The fingers in the driver's order: finger_middle, finger_1, finger_2.
inline constexpr int kFingerCount = 3;
inline constexpr std::array<std::string_view, kFingerCount> kFingerNames = {"finger_middle", "finger_1", "finger_2"};

struct AdaptiveFingerReading {
  double position = 0.0;  // 0 open .. 1 closed (the flexion tendon's travel)
  double speed = 0.0;     // per second, positive while closing
  double force = 0.0;     // the finger's squeezing force, N
  bool contact = false;   // the finger touches something (current/tactile sensing)
};

struct AdaptiveGripperReading {
  std::array<AdaptiveFingerReading, kFingerCount> fingers{};
  GripperMode mode = GripperMode::kBasic;  // the mode last commanded
  bool mode_reached = true;                // the scissor axis is where the mode puts it
  /// When it was measured; TimePoint{} from a driver that does not stamp its readings.
  TimePoint stamp{};
};

class AdaptiveGripperDriver {
 public:
  virtual ~AdaptiveGripperDriver() = default;
  virtual AdaptiveGripperReading read() const = 0;
  /// Moves each finger toward its position (0 open .. 1 closed) at `speed` (full strokes per
  /// second), squeezing with at most `force` (N per finger).
  virtual void commandFingers(const std::array<double, kFingerCount>& positions, double speed, double force) = 0;
  /// Turns the scissor axis to where `mode` puts fingers 1 and 2.
  virtual void commandMode(GripperMode mode) = 0;
};

}  // namespace costar::gripper
