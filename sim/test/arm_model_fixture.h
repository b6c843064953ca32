#pragma once
// A generated arm model (robots/generate_models.py) loaded alone in MuJoCo, for the model tests of
// each arm: the flange site's pose, the joint positions, and the simulation's arm control to hold
// a configuration under gravity.

#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <Eigen/Core>
#include <array>
#include <memory>
#include <string>

#include "world/pose.h"

namespace costar::sim::testing {

struct ModelDeleter {
  void operator()(mjModel* model) const { mj_deleteModel(model); }
};
struct DataDeleter {
  void operator()(mjData* data) const { mj_deleteData(data); }
};

class ArmModelTest : public ::testing::Test {
 protected:
  /// Loads `mjcf`, whose flange is the site `flange_site`.
  void load(const char* mjcf, const char* flange_site) {
    std::array<char, 1000> error{};
    model_.reset(mj_loadXML(mjcf, nullptr, error.data(), static_cast<int>(error.size())));
    ASSERT_TRUE(model_) << error.data();
    data_.reset(mj_makeData(model_.get()));
    flange_site_ = mj_name2id(model_.get(), mjOBJ_SITE, flange_site);
    ASSERT_GE(flange_site_, 0) << flange_site;
  }

  world::Pose flange() const {
    world::Pose pose = world::Pose::Identity();
    for (int i = 0; i < 3; ++i) {
      pose.translation()[i] = data_->site_xpos[3 * flange_site_ + i];
      for (int j = 0; j < 3; ++j) {
        pose.linear()(i, j) = data_->site_xmat[9 * flange_site_ + 3 * i + j];
      }
    }
    return pose;
  }

  Eigen::VectorXd positions() const { return Eigen::Map<const Eigen::VectorXd>(data_->qpos, model_->nq); }
  Eigen::VectorXd velocities() const { return Eigen::Map<const Eigen::VectorXd>(data_->qvel, model_->nv); }
  Eigen::VectorXd keyframe(const char* name) const {
    const int key = mj_name2id(model_.get(), mjOBJ_KEY, name);
    EXPECT_GE(key, 0) << name;
    return Eigen::Map<const Eigen::VectorXd>(model_->key_qpos + std::max(key, 0) * model_->nq, model_->nq);
  }

  /// The simulation's arm control (sim/simulation.cpp): computed torque with critically damped
  /// PD gains (omega 50 rad/s), tau = M (Kp e + Kd de) + bias, clamped by the motors' ranges.
  void hold(const Eigen::VectorXd& target, double seconds) {
    constexpr double kOmega = 50.0;
    const int n = model_->nv;
    Eigen::VectorXd acceleration(n);
    Eigen::VectorXd torque(n);
    const int steps = static_cast<int>(seconds / model_->opt.timestep);
    for (int step = 0; step < steps; ++step) {
      mj_step1(model_.get(), data_.get());
      for (int i = 0; i < n; ++i) {
        acceleration[i] = kOmega * kOmega * (target[i] - data_->qpos[i]) - 2.0 * kOmega * data_->qvel[i];
      }
      mj_mulM(model_.get(), data_.get(), torque.data(), acceleration.data());
      for (int i = 0; i < n; ++i) {
        data_->ctrl[i] = torque[i] + data_->qfrc_bias[i];
      }
      mj_step2(model_.get(), data_.get());
    }
  }

  std::unique_ptr<mjModel, ModelDeleter> model_;
  std::unique_ptr<mjData, DataDeleter> data_;
  int flange_site_ = -1;
};

}  // namespace costar::sim::testing
