#include "arm/arm_motion.h"

#include <cstdio>

#include "arm/motion_planner.h"

namespace costar::arm {

using component::OperationResult;

std::string formatNumber(const char* pattern, double value) {
  char text[96];
  std::snprintf(text, sizeof text, pattern, value);
  return text;
}

void stopMotion(ArmMotion& motion, ArmDriver& driver, const Clock& clock, const JointLimits& limits) {
  ++motion.counter;
  const TimePoint now = clock.now();
  if (motion.cartesian) {
    motion.cartesian = false;
    TrajectoryPoint state;
    try {
      const ArmState measured = driver.read();
      state.position = measured.position;
      state.velocity = measured.velocity.size() == measured.position.size()
                           ? measured.velocity
                           : JointVector::zero(measured.position.size());
      state.acceleration = JointVector::zero(measured.position.size());
      auto stop = std::make_shared<JointTrajectory>(JointTrajectory::stopFrom(state, limits));
      driver.execute(stop, now);
      motion.trajectory = std::move(stop);
      motion.start = now;
    } catch (const std::exception&) {
      // No trustworthy reading to stop from: the controller holds what it had (the motion's
      // reference), and the operation that reads the driver next fails.
    }
    return;
  }
  if (!motion.trajectory) {
    return;
  }
  // Where the controller is along the trajectory: a speed override may have held it back.
  const Duration along = now - motion.start - driver.heldBack();
  if (along < motion.trajectory->duration()) {
    const TrajectoryPoint state = motion.trajectory->sample(along);
    auto stop = std::make_shared<JointTrajectory>(JointTrajectory::stopFrom(state, limits));
    driver.execute(stop, now);
    motion.trajectory = std::move(stop);
    motion.start = now;
  }
}

MotionOperation::MotionOperation(ArmDriver& driver, const Clock& clock, MotionPlan plan,
                                 std::shared_ptr<ArmMotion> motion, const ArmConfig& config,
                                 std::shared_ptr<const Kinematics> kinematics, std::string what)
    : driver_(driver),
      clock_(clock),
      plan_(std::move(plan)),
      motion_(std::move(motion)),
      id_(++motion_->counter),
      config_(config),
      kinematics_(std::move(kinematics)),
      what_(std::move(what)),
      start_(clock.now()) {
  motion_->trajectory = plan_.trajectory;
  motion_->start = start_;
  motion_->cartesian = false;
  driver_.execute(plan_.trajectory, start_);
}

OperationResult MotionOperation::poll() {
  if (motion_->counter != id_) {
    return OperationResult::failure("the arm was stopped, or another motion took over, before " + what_ + " finished");
  }
  const TimePoint now = clock_.now();
  // Every poll checks the driver's reading: a driver that fails, reads NaN or stopped
  // updating stops the motion at once.
  ArmState state;
  std::string problem;
  try {
    state = driver_.read();
    problem = readingProblem(state, now, config_.state_timeout, config_.joint_names);
  } catch (const std::exception& e) {
    problem = e.what();
  }
  if (!problem.empty()) {
    stopMotion(*motion_, driver_, clock_, kinematics_->limits());
    return OperationResult::failure(what_ + ": " + problem + "; the arm was stopped");
  }
  const TimePoint end = start_ + plan_.trajectory->duration() + driver_.heldBack();
  if (now < end) {
    return OperationResult::running();
  }
  const double error = maxAbsDifference(state.position, plan_.goal);
  const double speed = maxAbs(state.velocity);
  if (error < config_.arrival_tolerance && speed < 0.05) {
    return OperationResult::success({{"duration", toSeconds(plan_.trajectory->duration())}});
  }
  if (now > end + config_.settle_time) {
    return OperationResult::failure(what_ + ": the arm stopped " + formatNumber("%.3f", error) +
                                    " rad from its goal (blocked, or the controller cannot follow)");
  }
  return OperationResult::running();
}

void MotionOperation::cancel() {
  if (motion_->counter == id_) {
    stopMotion(*motion_, driver_, clock_, kinematics_->limits());
  }
}

}  // namespace costar::arm
