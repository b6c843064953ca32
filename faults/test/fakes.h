#pragma once
// Test doubles: drivers and a component that always work, on a SimClock.

#include <limits>
#include <memory>

#include "arm/arm_driver.h"
#include "camera/rgbd.h"
#include "component/component.h"
#include "core/clock.h"
#include "gripper/adaptive_gripper_driver.h"
#include "gripper/gripper_driver.h"

namespace costar::faults::test {

class GoodArm final : public arm::ArmDriver {
 public:
  explicit GoodArm(const Clock& clock) : clock_(clock) {}
  arm::ArmState read() const override {
    arm::ArmState state;
    state.position = {0.1, -1.0, 1.0, -1.5, -1.5, toSeconds(clock_.now())};  // wrist 3 turns with time
    state.velocity = arm::JointVector::zero(6);
    state.stamp = clock_.now();
    return state;
  }
  void execute(std::shared_ptr<const arm::JointTrajectory> trajectory, TimePoint) override {
    ++commands;
    last = std::move(trajectory);
  }
  int commands = 0;
  std::shared_ptr<const arm::JointTrajectory> last;

 private:
  const Clock& clock_;
};

class GoodFingers final : public gripper::GripperDriver {
 public:
  explicit GoodFingers(const Clock& clock) : clock_(clock) {}
  gripper::FingerReading read() const override { return {0.085, 0.0, 0.0, false, clock_.now()}; }
  void command(double, double, double) override { ++commands; }
  double maxOpening() const override { return 0.085; }
  int commands = 0;

 private:
  const Clock& clock_;
};

class GoodAdaptiveFingers final : public gripper::AdaptiveGripperDriver {
 public:
  explicit GoodAdaptiveFingers(const Clock& clock) : clock_(clock) {}
  gripper::AdaptiveGripperReading read() const override {
    gripper::AdaptiveGripperReading reading;
    for (auto& finger : reading.fingers) {
      finger.position = 0.25;
    }
    reading.stamp = clock_.now();
    return reading;
  }
  void commandFingers(const std::array<double, gripper::kFingerCount>&, double, double) override { ++commands; }
  void commandMode(gripper::GripperMode) override { ++commands; }
  int commands = 0;

 private:
  const Clock& clock_;
};

class GoodCamera final : public camera::RgbdCamera {
 public:
  explicit GoodCamera(const Clock& clock) : clock_(clock) {}
  std::string name() const override { return "good"; }
  const camera::Intrinsics& intrinsics() const override { return intrinsics_; }
  Duration framePeriod() const override { return std::chrono::milliseconds(33); }
  camera::RgbdFrame capture() override {
    camera::RgbdFrame frame;
    frame.intrinsics = intrinsics_;
    frame.points.assign(static_cast<std::size_t>(intrinsics_.width) * intrinsics_.height,
                        Eigen::Vector3f(0.0f, 0.0f, 1.0f));
    frame.rgb = RgbImage(intrinsics_.width, intrinsics_.height);
    frame.stamp = clock_.now();
    return frame;
  }
  /// A live stream: its newest frame is now, every pixel valid.
  std::optional<camera::StreamStatus> streamStatus() override {
    const std::size_t pixels = static_cast<std::size_t>(intrinsics_.width) * intrinsics_.height;
    return camera::StreamStatus{clock_.now(), pixels, pixels};
  }

 private:
  const Clock& clock_;
  camera::Intrinsics intrinsics_ = camera::Intrinsics::fromHorizontalFov(8, 6, 1.0);
};

/// "Work": RUNNING for 3 polls, then SUCCESS.
class GoodComponent final : public component::LocalComponent {
 public:
  explicit GoodComponent(std::string name) {
    description_.name = std::move(name);
    description_.type = "Good";
    description_.operations = {{"Work", "three polls, then SUCCESS", {}}};
    description_.predicates = {{"good", 0, "always"}};
  }
  const component::ComponentDescription& description() const override { return description_; }
  world::Report report() const override { return {{}, {{"good", {}, true, ""}}}; }

 private:
  class Work final : public component::RunningOperation {
   public:
    component::OperationResult poll() override {
      return ++polls_ > 3 ? component::OperationResult::success() : component::OperationResult::running();
    }
    void cancel() override {}

   private:
    int polls_ = 0;
  };
  std::unique_ptr<component::RunningOperation> begin(const std::string&, const component::ParamMap&) override {
    return std::make_unique<Work>();
  }
  component::ComponentDescription description_;
};

}  // namespace costar::faults::test
