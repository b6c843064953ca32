#pragma once
// What an arm's controller (a UR's RTDE interface, or the simulator) offers the Arm
// component: the joint state from its encoders, and execution of timed joint trajectories.

#include <memory>

#include "arm/joints.h"
#include "arm/trajectory.h"
#include "core/clock.h"

namespace costar::arm {

struct ArmState {
  JointVector position{};  // one angle per joint
  JointVector velocity{};  // one per joint, or empty from a driver that does not measure them
  /// When the controller measured it; TimePoint{} from a driver that does not stamp its
  /// readings (the Arm component then cannot tell a reading that stopped updating).
  TimePoint stamp{};
};

class ArmDriver {
 public:
  virtual ~ArmDriver() = default;
  virtual ArmState read() const = 0;
  /// Follows `trajectory` from clock time `start` (its sample at t - start), replacing any
  /// trajectory being followed; after its end, holds its final position.
  virtual void execute(std::shared_ptr<const JointTrajectory> trajectory, TimePoint start) = 0;
  /// How far a speed override (a controller's speed and separation monitoring slowing or
  /// stopping the arm for a person) has held the present trajectory back: the controller
  /// follows its sample at t - start - heldBack(). Zero from a controller without one.
  virtual Duration heldBack() const { return Duration::zero(); }
};

}  // namespace costar::arm
