// The gripper table: one row per gripper (workcell/grippers.h).

#include "workcell/grippers.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "gripper/parallel_gripper.h"

namespace costar::workcell {

namespace {

std::shared_ptr<component::Component> makeParallelGripper(gripper::GripperDriver& driver, const Clock& clock) {
  return std::make_shared<gripper::ParallelGripper>(driver, clock);
}

/// "parallel-2f": the parallel 2-finger gripper (sim/models/gripper_parallel-2f.xml): tool
/// centre point 0.14 m along the flange's z axis, between the pads; the calibration marker on
/// the body's +x face, 7.5 cm from the flange.
GripperModel parallelTwoFinger() {
  GripperModel model;
  model.key = "parallel-2f";
  model.mjcf = "sim/models/gripper_parallel-2f.xml";
  model.urdf = "sim/models/gripper_parallel-2f.urdf";
  model.tcp_link = "tcp";
  model.tcp_in_flange.translation() = Eigen::Vector3d(0.0, 0.0, 0.14);
  model.links = {"fingers"};
  model.fingers = gripper::twoFingerGripper();
  model.marker_in_flange_guess = world::poseFromXyzRpy(0.035, 0, 0.075, -M_PI / 2, 0, -M_PI / 2);
  model.make_component = &makeParallelGripper;
  return model;
}

const std::vector<GripperModel>& table() {
  static const std::vector<GripperModel> grippers = {parallelTwoFinger()};
  return grippers;
}

}  // namespace

std::vector<std::string> gripperKeys() {
  std::vector<std::string> keys;
  for (const GripperModel& model : table()) {
    keys.push_back(model.key);
  }
  std::sort(keys.begin(), keys.end());
  return keys;
}

const GripperModel& gripperModel(const std::string& key) {
  for (const GripperModel& model : table()) {
    if (model.key == key) {
      return model;
    }
  }
  std::string known;
  for (const std::string& name : gripperKeys()) {
    known += (known.empty() ? "" : ", ") + name;
  }
  throw std::invalid_argument("unknown gripper '" + key + "' (known: " + known + ")");
}

}  // namespace costar::workcell
