#pragma once
// The simulator behind the interfaces that hardware drivers implement, so components cannot
// tell the simulated workcell from a real one: an RGB-D camera and gripper fingers. (The
// arm's driver is in sim/arm_driver.h.)

#include "camera/rgbd.h"
#include "gripper/gripper_driver.h"
#include "sim/simulation.h"

namespace costar::sim {

/// The workcell's RGB-D camera: each capture renders the present state with fresh sensor
/// noise (the noise seed advances with every frame, from `seed`).
class SimRgbdCamera final : public camera::RgbdCamera {
 public:
  SimRgbdCamera(Simulation& simulation, std::uint64_t seed) : simulation_(simulation), next_seed_(seed) {}
  std::string name() const override { return "rgbd (simulated PrimeSense Carmine)"; }
  const camera::Intrinsics& intrinsics() const override { return simulation_.rgbdIntrinsics(); }
  Duration framePeriod() const override { return std::chrono::nanoseconds(33'333'333); }
  camera::RgbdFrame capture() override { return taken(simulation_.captureRgbd(next_seed_++)); }
  camera::RgbdFrame captureDepth() override { return taken(simulation_.captureRgbd(next_seed_++, false)); }
  /// Frames are rendered only when taken (rendering costs), so the simulated stream never
  /// stalls: its newest frame is the present instant, with the valid depth of the last frame
  /// taken (all pixels before the first).
  std::optional<camera::StreamStatus> streamStatus() override {
    const camera::Intrinsics& intrinsics = simulation_.rgbdIntrinsics();
    const std::size_t pixels = static_cast<std::size_t>(intrinsics.width) * intrinsics.height;
    return camera::StreamStatus{simulation_.time(), pixels, last_valid_.value_or(pixels)};
  }

 private:
  camera::RgbdFrame taken(camera::RgbdFrame frame) {
    last_valid_ = frame.validCount();
    return frame;
  }

  Simulation& simulation_;
  std::uint64_t next_seed_;
  std::optional<std::size_t> last_valid_;
};

/// The gripper's fingers.
class SimGripperDriver final : public gripper::GripperDriver {
 public:
  explicit SimGripperDriver(Simulation& simulation) : simulation_(simulation) {}
  gripper::FingerReading read() const override {
    const FingerState state = simulation_.fingers();
    return {state.opening, state.opening_speed, state.force, state.pads_in_contact, simulation_.time()};
  }
  void command(double opening, double speed, double force) override {
    simulation_.commandFingers(opening, speed, force);
  }
  double maxOpening() const override { return simulation_.maxOpening(); }

 private:
  Simulation& simulation_;
};

}  // namespace costar::sim
