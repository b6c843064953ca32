// The gripper table: one row per gripper (workcell/grippers.h).

#include "workcell/grippers.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "core/files.h"
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
  model.finger_link = "fingers";
  const gripper::FingerGeometry fingers = gripper::twoFingerGripper();
  model.geometry = gripper::parallelGripperGeometry(fingers);
  model.read_stance = [stroke = fingers.max_opening](const GripperDrivers& drivers) {
    double opening = std::numeric_limits<double>::quiet_NaN();
    try {
      opening = drivers.parallel->read().opening;
    } catch (const std::exception&) {
      // unknown: see below
    }
    // An opening not known (a reading that fails, or is not a number) counts as the whole stroke.
    return std::optional<gripper::FingerStance>({.opening = std::isfinite(opening) ? opening : stroke});
  };
  model.marker_in_flange_guess = world::poseFromXyzRpy(0.035, 0, 0.075, -M_PI / 2, 0, -M_PI / 2);
  model.grasps = smartmove::kParallelGripper;
  model.make_component = &makeParallelGripper;
  return model;
}

/// "robotiq3f": the 3-finger adaptive gripper (robots/grippers/robotiq3f.json, docs/GRIPPERS.md),
/// its pieces generated at build time (robots/generate_gripper.py): the tool centre point from
/// the description (0.19 m along the flange's z axis); the calibration marker where the
/// generator puts it, on the palm's +x face. Its fingers are modelled in each mode, open or (in a
/// fingertip mode) closed part way; it opens fully, or to a position in a fingertip mode.
GripperModel robotiq3f() {
  const std::filesystem::path generated = COSTAR_GRIPPER_MODEL_DIR;
  const gripper::AdaptiveGripperDescription description =
      gripper::loadAdaptiveGripperDescription(gripper::gripperDescriptionFile("robotiq3f"));
  GripperModel model;
  model.key = "robotiq3f";
  model.mjcf = generated / "robotiq3f_mount.xml";
  model.urdf = generated / "robotiq3f.urdf";
  model.tcp_link = "tcp";
  model.tcp_in_flange.translation() = description.tcp;
  model.links = {"robotiq3f_fingers"};
  model.finger_link = "robotiq3f_fingers";
  model.geometry = gripper::adaptiveGripperGeometry(description);
  // The fingers as the mode places them: open, or in a fingertip mode closed part way as far as
  // its most open closing finger reads (rounded down to 1 %, toward open).
  model.read_stance = [description](const GripperDrivers& drivers) -> std::optional<gripper::FingerStance> {
    gripper::AdaptiveGripperReading reading;
    try {
      reading = drivers.adaptive->read();
    } catch (const std::exception&) {
      return std::nullopt;  // the component reports the failure
    }
    const gripper::AdaptiveModeDescription& mode = description.mode(reading.mode);
    double position = 0.0;
    if (mode.fingertip) {
      position = 1.0;
      for (std::size_t i = 0; i < reading.fingers.size(); ++i) {
        if (mode.closing[i]) {
          position = std::min(position, reading.fingers[i].position);
        }
      }
      position = std::clamp(std::floor(position * 100.0) / 100.0, 0.0, 0.9);
    }
    return gripper::FingerStance{.mode = std::string(gripper::toString(reading.mode)), .position = position};
  };
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
      if (!model.adaptive.empty()) {
        // The simulator mounts the models generated from the description at build time; the
        // component reads the description: they must be of the same file.
        checkGeneratedFrom(gripper::gripperDescriptionFile(model.adaptive),
                           std::filesystem::path(COSTAR_GRIPPER_MODEL_DIR) / (model.adaptive + ".fingerprint"));
      }
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
