// The gripper table: one row per gripper described in robots/grippers/ (workcell/grippers.h).

#include "workcell/grippers.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "core/files.h"
#include "gripper/adaptive_gripper.h"
#include "gripper/adaptive_gripper_description.h"
#include "gripper/parallel_gripper.h"
#include "gripper/parallel_gripper_description.h"

namespace costar::workcell {

namespace {

/// The calibration marker's pose in the flange frame as the generators put it (robots/
/// generate_gripper.py, robots/parallel_gripper.py): on the body's +x face, image right along
/// -y of the flange, image up towards the flange.
world::Pose markerOnFace(double x, double z) { return world::poseFromXyzRpy(x, 0, z, -M_PI / 2, 0, -M_PI / 2); }

/// A parallel 2-finger gripper ("kind": "parallel"): its pieces generated at build time from
/// its description (robots/parallel_gripper.py), the fingers' boxes, stroke and forces read from it.
GripperModel parallelGripper(const std::string& name) {
  const std::filesystem::path generated = COSTAR_GRIPPER_MODEL_DIR;
  const gripper::ParallelGripperDescription description =
      gripper::loadParallelGripperDescription(gripper::gripperDescriptionFile(name));
  GripperModel model;
  model.key = name;
  model.mjcf = generated / (name + "_mount.xml");
  model.urdf = generated / (name + ".urdf");
  model.tcp_link = "tcp";
  model.tcp_in_flange.translation() = description.tcp;
  model.links = {"fingers"};
  model.finger_link = "fingers";
  model.geometry = gripper::parallelGripperGeometry(description.fingers);
  model.read_stance = [stroke = description.fingers.max_opening](const GripperDrivers& drivers) {
    double opening = std::numeric_limits<double>::quiet_NaN();
    try {
      opening = drivers.parallel->read().opening;
    } catch (const std::exception&) {
      // unknown: see below
    }
    // An opening not known (a reading that fails, or is not a number) counts as the whole stroke.
    return std::optional<gripper::FingerStance>({.opening = std::isfinite(opening) ? opening : stroke});
  };
  model.marker_in_flange_guess =
      markerOnFace(description.body_centre.x() + description.body_size.x() / 2, description.body_centre.z());
  model.grasps = description.grasps;
  model.make_component = [description](const GripperDrivers& drivers,
                                       const Clock& clock) -> std::shared_ptr<component::Component> {
    if (drivers.parallel == nullptr) {
      throw std::logic_error("the parallel 2-finger gripper '" + description.name + "' needs a 2-finger driver");
    }
    gripper::ParallelGripperOptions options;
    options.force = description.default_force;
    options.max_force = description.max_force;
    return std::make_shared<gripper::ParallelGripper>(*drivers.parallel, clock, options);
  };
  return model;
}

/// A 3-finger adaptive gripper ("kind": "adaptive-3f", docs/GRIPPERS.md), its pieces generated
/// at build time (robots/generate_gripper.py): the tool centre point from the description; the
/// calibration marker where the generator puts it, on the palm's +x face. Its fingers are
/// modelled in each mode, open or (in a fingertip mode) closed part way; it opens fully, or to a
/// position in a fingertip mode.
GripperModel adaptiveGripper(const std::string& name) {
  const std::filesystem::path generated = COSTAR_GRIPPER_MODEL_DIR;
  const gripper::AdaptiveGripperDescription description =
      gripper::loadAdaptiveGripperDescription(gripper::gripperDescriptionFile(name));
  GripperModel model;
  model.key = name;
  model.mjcf = generated / (name + "_mount.xml");
  model.urdf = generated / (name + ".urdf");
  model.tcp_link = "tcp";
  model.tcp_in_flange.translation() = description.tcp;
  model.links = {name + "_fingers"};
  model.finger_link = name + "_fingers";
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
  // The palm's +x face and the 0.3 mm the generator sets the marker off it.
  model.marker_in_flange_guess =
      markerOnFace(description.palm_centre.x() + description.palm_size.x() / 2 + 0.0003, description.palm_centre.z());
  model.adaptive = name;
  model.grasps = name;
  model.make_component = [description](const GripperDrivers& drivers,
                                       const Clock& clock) -> std::shared_ptr<component::Component> {
    if (drivers.adaptive == nullptr) {
      throw std::logic_error("the 3-finger adaptive gripper '" + description.name +
                             "' needs an adaptive gripper driver");
    }
    return std::make_shared<gripper::AdaptiveGripper>(*drivers.adaptive, clock, description);
  };
  return model;
}

/// Every gripper described in robots/grippers/ (a new gripper is its file, nothing here).
const std::vector<GripperModel>& table() {
  static const std::vector<GripperModel> grippers = [] {
    std::vector<GripperModel> models;
    for (const std::string& name : gripper::gripperDescriptionNames()) {
      const std::filesystem::path file = gripper::gripperDescriptionFile(name);
      models.push_back(gripper::gripperKind(file) == "parallel" ? parallelGripper(name) : adaptiveGripper(name));
    }
    return models;
  }();
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
      // The simulator mounts the models generated from the description at build time; the
      // component reads the description: they must be of the same file.
      checkGeneratedFrom(gripper::gripperDescriptionFile(model.key),
                         std::filesystem::path(COSTAR_GRIPPER_MODEL_DIR) / (model.key + ".fingerprint"));
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
