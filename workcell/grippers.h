#pragma once
// The grippers a simulated workcell can carry (workcells/NAME.json, "gripper": KEY): one row
// per gripper in a table (workcell/grippers.cpp) with its models and the numbers the cell's
// components need. A new gripper adds its MJCF and URDF pieces (sim/models/) and a row.

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "component/component.h"
#include "core/clock.h"
#include "gripper/finger_geometry.h"
#include "gripper/gripper_driver.h"
#include "world/pose.h"

namespace costar::workcell {

struct GripperModel {
  std::string key;
  /// MJCF piece (sim/cell_model.h: its body "mount" is the flange) and URDF piece
  /// (planning::mountUrdf: its link "mount" is the flange); relative to the data root.
  std::filesystem::path mjcf;
  std::filesystem::path urdf;
  /// The URDF link at the tool centre point, and the tool centre point in the flange frame.
  std::string tcp_link;
  world::Pose tcp_in_flange = world::Pose::Identity();
  /// The gripper's links that may touch a part being grasped (SmartMove allows it).
  std::vector<std::string> links;
  /// The fingers' shapes by opening (SmartMove plans grasps with them), if the gripper has some.
  std::optional<gripper::FingerGeometry> fingers;
  /// Where the drawings put the hand-eye calibration marker in the flange frame.
  world::Pose marker_in_flange_guess = world::Pose::Identity();
  /// The gripper component on its driver (the driver and clock outlive it).
  std::shared_ptr<component::Component> (*make_component)(gripper::GripperDriver& driver, const Clock& clock) = nullptr;
};

/// The gripper with key `key`. @throws std::invalid_argument naming the known ones.
const GripperModel& gripperModel(const std::string& key);

/// The keys of every gripper, sorted.
std::vector<std::string> gripperKeys();

}  // namespace costar::workcell
