#pragma once
// Inside the Arm component (arm/arm_component.h): the motion its driver follows, shared by the
// component and the operation that started it, and the operation that follows a joint motion.
// Not for other components.

#include <cstdint>
#include <memory>
#include <string>

#include "arm/arm_config.h"
#include "arm/arm_driver.h"
#include "arm/kinematics.h"
#include "arm/motion_service.h"
#include "arm/trajectory.h"
#include "component/component.h"

namespace costar::arm {

/// The motion the driver follows, shared by the component and the motion's operation.
struct ArmMotion {
  std::uint64_t counter = 0;  // bumped by every new motion and every stop
  std::shared_ptr<const JointTrajectory> trajectory;
  TimePoint start{};
  /// A Cartesian motion (the controller's, arm/cartesian_controller.h) is in control: a stop
  /// decelerates from the joints' measured state.
  bool cartesian = false;
};

/// Stops the motion being followed: decelerates along its path within the acceleration limits
/// (a Cartesian motion: from the joints' measured state) and holds there.
void stopMotion(ArmMotion& motion, ArmDriver& driver, const Clock& clock, const JointLimits& limits);

/// A joint motion being executed by the driver: fails when the driver's readings cannot be
/// trusted (stopping the arm), when another motion takes over, or when the arm does not arrive.
class MotionOperation final : public component::RunningOperation {
 public:
  MotionOperation(ArmDriver& driver, const Clock& clock, MotionPlan plan, std::shared_ptr<ArmMotion> motion,
                  const ArmConfig& config, std::shared_ptr<const Kinematics> kinematics, std::string what);
  component::OperationResult poll() override;
  void cancel() override;

 private:
  ArmDriver& driver_;
  const Clock& clock_;
  MotionPlan plan_;
  std::shared_ptr<ArmMotion> motion_;
  std::uint64_t id_;
  const ArmConfig& config_;
  std::shared_ptr<const Kinematics> kinematics_;
  std::string what_;
  TimePoint start_;
};

/// "%.3f"-style formatting of one number.
std::string formatNumber(const char* pattern, double value);

}  // namespace costar::arm
