#pragma once
// A wrist force/torque sensor between the arm's flange and its tool (an ATI or Robotiq FT 300 on
// a UR, or the simulator's): what it offers the Arm component. Like a real sensor it reads a
// bias, the tool's weight and the forces that accelerate the tool besides what the tool touches;
// tare() zeroes it at the present load (the sensor's bias command).

#include <Eigen/Core>

#include "core/clock.h"
#include "world/pose.h"

namespace costar::arm {

/// A force (N) and a torque (N m) about a point, in the axes of a frame.
struct Wrench {
  Eigen::Vector3d force = Eigen::Vector3d::Zero();
  Eigen::Vector3d torque = Eigen::Vector3d::Zero();
};

struct ForceTorqueReading {
  /// What the flange pushes the tool side with, in the sensor frame about its origin, less what
  /// it read at the last tare(): at rest, what the tool pushes its surroundings with.
  Wrench wrench;
  /// When it was measured; TimePoint{} from a driver that does not stamp its readings.
  TimePoint stamp{};
};

/// What the sensor carries (the tool, as a UR's installation or a Franka's end-effector setting
/// states it): its mass (kg) and centre of mass (m, in the sensor frame). Free-drive
/// (arm/free_drive.h) takes its weight out of the readings as the tool turns.
struct Payload {
  double mass = 0.0;
  Eigen::Vector3d center_of_mass = Eigen::Vector3d::Zero();
};

class ForceTorqueSensor {
 public:
  virtual ~ForceTorqueSensor() = default;
  virtual ForceTorqueReading read() const = 0;
  /// Zeroes the reading at the present load: from now on readings are relative to the mean of
  /// the last kTareWindow of samples (taken while nothing touches the tool and the arm is still).
  virtual void tare() = 0;
  /// The sensor frame in the flange frame.
  virtual world::Pose inFlange() const = 0;

  static constexpr Duration kTareWindow = std::chrono::milliseconds(100);
};

}  // namespace costar::arm
