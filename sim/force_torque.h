#pragma once
// The simulated wrist force/torque sensor: MuJoCo's force and torque sensors at a site on the
// arm's flange (the interaction between the flange body, with the gripper and whatever the
// gripper touches, and the arm's last link), with what a strain-gauge sensor adds: a bias drawn
// once from a seed and white noise on every sample (MuJoCo's MJCF `noise` is metadata only).
// Sampled at every physics step (500 Hz); tare() averages the last 0.1 s of samples.
//
// The composed cell model has the site and the sensors (sim/cell_model.h, CellModelPieces::
// force_torque_site). No MuJoCo type appears here.

#include <array>
#include <cstdint>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "arm/force_torque.h"

struct mjModel_;
struct mjData_;

namespace costar::sim {

/// The sensor's imperfections, as a Robotiq FT 300 or an ATI Gamma shows them.
struct ForceTorqueNoise {
  double force_sigma = 0.15;    // N, per axis and sample
  double torque_sigma = 0.005;  // N m
  double force_bias = 3.0;      // N: each axis's bias drawn uniformly within +/- this
  double torque_bias = 0.15;    // N m
};

/// The names the composed model gives the site and its two sensors.
inline constexpr const char* kForceTorqueSite = "wrist_ft";
inline constexpr const char* kForceSensor = "wrist_force";
inline constexpr const char* kTorqueSensor = "wrist_torque";

class SimForceTorqueSensor final : public arm::ForceTorqueSensor {
 public:
  /// @throws std::runtime_error when the model lacks the site or its sensors.
  SimForceTorqueSensor(const mjModel_* model, const mjData_* data, std::uint64_t seed, ForceTorqueNoise noise,
                       std::function<TimePoint()> now);

  arm::ForceTorqueReading read() const override;
  void tare() override;
  world::Pose inFlange() const override { return world::Pose::Identity(); }

  /// Takes a sample of the present physics state (after every mj_step).
  void sample();
  /// The true wrench (no bias, no noise, never tared), for tests and the trial judge.
  arm::Wrench truth() const;
  /// The bias drawn from the seed.
  const arm::Wrench& bias() const { return bias_; }

 private:
  static constexpr int kWindow = 50;  // samples in ForceTorqueSensor::kTareWindow at 500 Hz

  const mjModel_* model_;
  const mjData_* data_;
  ForceTorqueNoise noise_;
  std::function<TimePoint()> now_;
  int force_address_ = 0;
  int torque_address_ = 0;
  std::mt19937_64 random_;
  std::normal_distribution<double> unit_{0.0, 1.0};
  arm::Wrench bias_;
  arm::Wrench tare_;
  arm::ForceTorqueReading last_;
  std::array<arm::Wrench, kWindow> window_{};  // raw samples, oldest overwritten
  int filled_ = 0;
  int next_ = 0;
};

}  // namespace costar::sim
