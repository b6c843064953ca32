#include "sim/force_torque.h"

#include <mujoco/mujoco.h>

#include <stdexcept>

namespace costar::sim {

namespace {

int sensorAddress(const mjModel* model, const char* name) {
  const int id = mj_name2id(model, mjOBJ_SENSOR, name);
  if (id < 0) {
    throw std::runtime_error(std::string("the workcell model has no force/torque sensor '") + name +
                             "' (sim/cell_model.h adds it at the flange)");
  }
  return model->sensor_adr[id];
}

}  // namespace

SimForceTorqueSensor::SimForceTorqueSensor(const mjModel_* model, const mjData_* data, std::uint64_t seed,
                                           ForceTorqueNoise noise, std::function<TimePoint()> now)
    : model_(model), data_(data), noise_(noise), now_(std::move(now)), random_(seed ^ 0x46545f73656e736fULL) {
  force_address_ = sensorAddress(model, kForceSensor);
  torque_address_ = sensorAddress(model, kTorqueSensor);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int i = 0; i < 3; ++i) {
    bias_.force[i] = noise_.force_bias * unit(random_);
    bias_.torque[i] = noise_.torque_bias * unit(random_);
  }
}

arm::Wrench SimForceTorqueSensor::truth() const {
  arm::Wrench wrench;
  for (int i = 0; i < 3; ++i) {
    wrench.force[i] = data_->sensordata[force_address_ + i];
    wrench.torque[i] = data_->sensordata[torque_address_ + i];
  }
  return wrench;
}

void SimForceTorqueSensor::sample() {
  arm::Wrench raw = truth();
  for (int i = 0; i < 3; ++i) {
    raw.force[i] += bias_.force[i] + noise_.force_sigma * unit_(random_);
    raw.torque[i] += bias_.torque[i] + noise_.torque_sigma * unit_(random_);
  }
  window_[static_cast<std::size_t>(next_)] = raw;
  next_ = (next_ + 1) % kWindow;
  filled_ = std::min(filled_ + 1, kWindow);
  last_.wrench.force = raw.force - tare_.force;
  last_.wrench.torque = raw.torque - tare_.torque;
  last_.stamp = now_();
}

arm::ForceTorqueReading SimForceTorqueSensor::read() const { return last_; }

void SimForceTorqueSensor::tare() {
  if (filled_ == 0) {
    return;
  }
  arm::Wrench mean;
  for (int i = 0; i < filled_; ++i) {
    mean.force += window_[static_cast<std::size_t>(i)].force / filled_;
    mean.torque += window_[static_cast<std::size_t>(i)].torque / filled_;
  }
  // The last sample, as it reads from now on.
  last_.wrench.force += tare_.force - mean.force;
  last_.wrench.torque += tare_.torque - mean.torque;
  tare_ = mean;
}

}  // namespace costar::sim
