#pragma once
// The simulated UR5 behind the ArmDriver interface: joint encoders, and trajectories followed
// by the simulator's computed-torque controller, sampled at every physics step.

#include <memory>
#include <mutex>

#include "arm/arm_driver.h"
#include "sim/simulation.h"

namespace costar::sim {

class SimArmDriver final : public arm::ArmDriver {
 public:
  explicit SimArmDriver(Simulation& simulation) : simulation_(simulation) {}

  arm::ArmState read() const override {
    return {simulation_.armPositions(), simulation_.armVelocities(), simulation_.time()};
  }

  void execute(std::shared_ptr<const arm::JointTrajectory> trajectory, TimePoint start) override {
    simulation_.setArmSetpointSource([trajectory = std::move(trajectory), start](TimePoint t) {
      const arm::TrajectoryPoint point = trajectory->sample(t - start);
      return ArmSetpoint{point.position, point.velocity, point.acceleration};
    });
  }

  Duration heldBack() const override { return simulation_.trajectoryLag(); }

 private:
  Simulation& simulation_;
};

}  // namespace costar::sim
