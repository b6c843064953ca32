#pragma once
// A 3-finger adaptive gripper's description as the component needs it, read from the same
// file the simulator's model is generated from (robots/grippers/NAME.json, format
// costar-gripper-description/1, robots/README.md): its modes (which fingers close, where a
// part sits between the fingers) and its force limit.

#include <Eigen/Core>
#include <array>
#include <filesystem>
#include <map>
#include <string>

#include "gripper/adaptive_gripper_driver.h"

namespace costar::gripper {

struct AdaptiveModeDescription {
  GripperMode mode = GripperMode::kBasic;
  std::string description;
  double scissor_deg = 0.0;                  // the scissor axis' angle in this mode
  std::array<bool, kFingerCount> closing{};  // in kFingerNames order
  /// The medial and distal phalanges held straight (a fingertip grasp, Pinch).
  bool fingertip = false;
  /// Where a grasped part's centre sits in the gripper's mounting frame (the flange).
  Eigen::Vector3d grasp_centre = Eigen::Vector3d::Zero();
};

struct AdaptiveGripperDescription {
  std::string name;
  std::map<GripperMode, AdaptiveModeDescription> modes;
  double min_force = 0.0;                         // N per finger: the least grip the servos hold steadily
  double max_force = 0.0;                         // N per finger
  double lever = 0.0;                             // m: the grip force is the flexion torque over this lever
  Eigen::Vector3d tcp = Eigen::Vector3d::Zero();  // the tool centre point in the flange frame
  double scissor_lower_deg = 0.0;
  double scissor_upper_deg = 0.0;
  double scissor_speed_deg_s = 0.0;

  const AdaptiveModeDescription& mode(GripperMode mode) const { return modes.at(mode); }
};

/// robots/grippers/NAME.json under `data_root` (default: dataRoot()).
std::filesystem::path gripperDescriptionFile(const std::string& name, const std::filesystem::path& data_root = {});

/// @throws std::runtime_error naming the file, the field and the problem.
AdaptiveGripperDescription loadAdaptiveGripperDescription(const std::filesystem::path& file);

}  // namespace costar::gripper
