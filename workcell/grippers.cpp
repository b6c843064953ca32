// The gripper table: one row per gripper (workcell/grippers.h).

#include "workcell/grippers.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "gripper/adaptive_gripper.h"
#include "gripper/adaptive_gripper_description.h"
#include "gripper/parallel_gripper.h"
#include "smartmove/grasps.h"

namespace costar::workcell {

namespace {

std::shared_ptr<component::Component> makeParallelGripper(const GripperDrivers& drivers, const Clock& clock) {
  if (drivers.parallel == nullptr) {
    throw std::logic_error("the parallel 2-finger gripper needs a 2-finger driver");
  }
  return std::make_shared<gripper::ParallelGripper>(*drivers.parallel, clock);
}

std::shared_ptr<component::Component> makeRobotiq3f(const GripperDrivers& drivers, const Clock& clock) {
  if (drivers.adaptive == nullptr) {
    throw std::logic_error("the 3-finger adaptive gripper needs an adaptive gripper driver");
  }
  return std::make_shared<gripper::AdaptiveGripper>(
      *drivers.adaptive, clock, gripper::loadAdaptiveGripperDescription(gripper::gripperDescriptionFile("robotiq3f")));
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
  model.grasps = smartmove::kParallelGripper;
  model.make_component = &makeParallelGripper;
  return model;
}

/// "robotiq3f": the 3-finger adaptive gripper (robots/grippers/robotiq3f.json, docs/GRIPPERS.md),
/// its pieces generated at build time (robots/generate_gripper.py): the tool centre point from
/// the description (0.19 m along the flange's z axis); the calibration marker where the
/// generator puts it, on the palm's +x face. No finger geometry for SmartMove: the planner's
/// fingers hold the open fingers at any mode, and the gripper opens fully.
GripperModel robotiq3f() {
  const std::filesystem::path generated = COSTAR_GRIPPER_MODEL_DIR;
  GripperModel model;
  model.key = "robotiq3f";
  model.mjcf = generated / "robotiq3f_mount.xml";
  model.urdf = generated / "robotiq3f.urdf";
  model.tcp_link = "tcp";
  model.tcp_in_flange.translation() =
      gripper::loadAdaptiveGripperDescription(gripper::gripperDescriptionFile("robotiq3f")).tcp;
  model.links = {"robotiq3f_fingers"};
  model.finger_link = "robotiq3f_fingers";
  model.marker_in_flange_guess = world::poseFromXyzRpy(0.0653, 0, 0.045, -M_PI / 2, 0, -M_PI / 2);
  model.adaptive = "robotiq3f";
  model.grasps = smartmove::kAdaptiveGripper;
  model.make_component = &makeRobotiq3f;
  return model;
}

const std::vector<GripperModel>& table() {
  static const std::vector<GripperModel> grippers = {parallelTwoFinger(), robotiq3f()};
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
