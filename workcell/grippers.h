#pragma once
// The grippers a simulated workcell can carry (workcells/NAME.json, "gripper": KEY): one row
// per gripper described in robots/grippers/KEY.json (a table, workcell/grippers.cpp, made by
// listing that folder) with its models and the numbers the cell's components need. A new
// gripper of a known kind ("parallel", "adaptive-3f") is its description file: the build
// generates its MJCF and URDF pieces (robots/generate_gripper.py).

#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "component/component.h"
#include "core/clock.h"
#include "gripper/adaptive_gripper_driver.h"
#include "gripper/gripper_driver.h"
#include "gripper/gripper_geometry.h"
#include "world/pose.h"

namespace costar::workcell {

/// The drivers a gripper component may sit on: the cell's one for its gripper, the other null.
struct GripperDrivers {
  gripper::GripperDriver* parallel = nullptr;          // a 2-finger gripper's fingers
  gripper::AdaptiveGripperDriver* adaptive = nullptr;  // a 3-finger adaptive gripper
};

struct GripperModel {
  std::string key;
  /// MJCF piece (sim/cell_model.h: its body "mount" is the flange, with the site "tcp" and the
  /// geom "gripper_marker") and URDF piece (planning::mountUrdf: its link "mount" is the
  /// flange); relative to the data root, or absolute (generated at build time).
  std::filesystem::path mjcf;
  std::filesystem::path urdf;
  /// The URDF link at the tool centre point, and the tool centre point in the flange frame.
  std::string tcp_link;
  world::Pose tcp_in_flange = world::Pose::Identity();
  /// The gripper's links that may touch a part being grasped (SmartMove allows it).
  std::vector<std::string> links;
  /// The URDF link whose collision shapes are the fingers: the cell keeps them there as the
  /// gripper reads them (read_stance, geometry); SmartMove's queries put them where a motion
  /// will have them.
  std::string finger_link;
  /// The fingers' geometry (gripper/gripper_geometry.h: one implementation per kind of gripper).
  std::shared_ptr<const gripper::GripperGeometry> geometry;
  /// How the fingers stand as the cell's driver reads them; nullopt when the reading fails and
  /// they are left as they were.
  std::function<std::optional<gripper::FingerStance>(const GripperDrivers& drivers)> read_stance;
  /// Where the drawings put the hand-eye calibration marker in the flange frame.
  world::Pose marker_in_flange_guess = world::Pose::Identity();
  /// A 3-finger adaptive gripper's description (robots/grippers/NAME.json): the simulation
  /// drives it (sim::SimulationOptions::adaptive_gripper). Empty: a 2-finger gripper.
  std::string adaptive;
  /// The key of its grasps in data/grasps.json (smartmove::GraspLibrary).
  std::string grasps;
  /// The gripper component on its driver (the driver and clock outlive it).
  /// @throws std::logic_error when the driver it needs is null.
  std::function<std::shared_ptr<component::Component>(const GripperDrivers& drivers, const Clock& clock)>
      make_component;
};

/// The gripper with key `key`. @throws std::invalid_argument naming the known ones.
const GripperModel& gripperModel(const std::string& key);

/// The keys of every gripper, sorted.
std::vector<std::string> gripperKeys();

}  // namespace costar::workcell
