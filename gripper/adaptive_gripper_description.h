#pragma once
// A 3-finger adaptive gripper's description as the component needs it, read from the same
// file the simulator's model is generated from (robots/grippers/NAME.json, format
// costar-gripper-description/1, robots/README.md): its modes (which fingers close, where a
// part sits between the fingers) and its force limit.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "gripper/adaptive_gripper_driver.h"
#include "gripper/gripper_description.h"

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

/// Where a finger stands on the palm (the generator's "fingers" entries).
struct AdaptiveFingerPlacement {
  Eigen::Vector3d base = Eigen::Vector3d::Zero();  // its knuckle, in the flange frame
  double yaw_deg = 0.0;                            // about the flange's z: the finger closes along its +y
  int scissor_sign = 0;                            // how it turns on the scissor axis (0: it does not)
};

/// A box in the flange frame (for collision checking).
struct OrientedBox {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  // its centre and axes
  Eigen::Vector3d size = Eigen::Vector3d::Zero();          // full side lengths
};

struct AdaptiveGripperDescription {
  std::string name;
  std::array<AdaptiveFingerPlacement, kFingerCount> fingers{};  // in kFingerNames order
  double finger_length = 0.0;                                   // m: the three phalanges, knuckle to fingertip
  double finger_width = 0.0;                                    // m
  double finger_thickness = 0.0;                                // m, pad included
  double open_lean_deg = 0.0;       // how far an open finger leans out (the proximal joint's lower limit, negated)
  double proximal_upper_deg = 0.0;  // the proximal joint's upper limit: a fingertip mode's finger fully closed
  std::map<GripperMode, AdaptiveModeDescription> modes;
  double min_force = 0.0;                                 // N per finger: the least grip the servos hold steadily
  double max_force = 0.0;                                 // N per finger
  double lever = 0.0;                                     // m: the grip force is the flexion torque over this lever
  Eigen::Vector3d tcp = Eigen::Vector3d::Zero();          // the tool centre point in the flange frame
  Eigen::Vector3d palm_centre = Eigen::Vector3d::Zero();  // the palm's box in the flange frame
  Eigen::Vector3d palm_size = Eigen::Vector3d::Zero();    // full side lengths
  double scissor_lower_deg = 0.0;
  double scissor_upper_deg = 0.0;
  double scissor_speed_deg_s = 0.0;

  const AdaptiveModeDescription& mode(GripperMode mode) const { return modes.at(mode); }
};

/// @throws std::runtime_error naming the file, the field and the problem.
AdaptiveGripperDescription loadAdaptiveGripperDescription(const std::filesystem::path& file);

/// The open fingers in `mode` (the scissor axis at the mode's angle), one box per finger from
/// its knuckle to 1 mm past its tip, leaning out as open fingers do: what a planner must keep
/// clear of neighbours when the gripper comes down open. Closing fingers move inward, into the
/// grasp.
std::vector<OrientedBox> openFingerBoxes(const AdaptiveGripperDescription& description, GripperMode mode);

/// The fingers in `mode` stopped at `position` (0 open .. 1 closed, the driver's units), as
/// openFingerBoxes. Only a fingertip mode's fingers stay straight as they close (the proximal
/// joint turns from its lower to its upper limit); in the other modes they curl, and only open
/// fingers (position 0) are modelled: @throws std::invalid_argument for another position there.
std::vector<OrientedBox> fingerBoxesAt(const AdaptiveGripperDescription& description, GripperMode mode,
                                       double position);

/// Half the clear width between the closing fingers' tips (m, along the flange's y, from its z
/// axis) with the fingers at `position` in `mode` (a fingertip mode for positions above 0).
double fingertipClearance(const AdaptiveGripperDescription& description, GripperMode mode, double position);

/// The most closed position (0 .. 1, in steps of 0.01) at which the fingertips in `mode` leave
/// at least `half_width` (m) clear either side of the flange's z axis: how far to close the
/// fingers before going down round a part among neighbours. 0 (fully open) in a mode that is
/// not a fingertip mode, or when even open fingers leave less.
double fingertipPositionFor(const AdaptiveGripperDescription& description, GripperMode mode, double half_width);

/// How far (m) the fingertips in `mode` reach along the flange's x either side of its z axis,
/// open (and closed, in a fingertip mode): a grasp shifted along a part keeps them this far
/// inside its end, so that the fingers still close on it.
double fingerReachAcross(const AdaptiveGripperDescription& description, GripperMode mode);

}  // namespace costar::gripper
