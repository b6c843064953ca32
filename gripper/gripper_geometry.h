#pragma once
// What a planner needs to know of a gripper's fingers (SmartMove plans grasps, pushes and
// releases with them; the workcell keeps the fingers as read in the collision world): where
// they stand for a motion, how far a grasp opens them, how far they reach. One implementation
// per kind of gripper, chosen once from the cell's data (workcell/grippers.cpp): a parallel
// gripper that opens to a width, an adaptive gripper with modes, and a gripper whose fingers
// are not modelled. A new kind of gripper is one more implementation, not a branch.

#include <Eigen/Core>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "component/value.h"
#include "gripper/adaptive_gripper_description.h"
#include "gripper/finger_geometry.h"

namespace costar::gripper {

/// How the fingers stand for a motion. A gripper reads what it has: a parallel gripper its
/// opening, an adaptive gripper its mode and position.
struct FingerStance {
  /// m between the pads (nullopt: as they are).
  std::optional<double> opening;
  /// A gripper mode by name (the gripper_mode predicate's argument; empty: as they are) ...
  std::string mode;
  /// ... with the fingers stopped at this position (0 open .. 1 closed).
  double position = 0.0;
};

class GripperGeometry {
 public:
  GripperGeometry() = default;
  GripperGeometry(const GripperGeometry&) = delete;
  GripperGeometry& operator=(const GripperGeometry&) = delete;
  virtual ~GripperGeometry() = default;

  /// The fingers' boxes in the gripper's mounting frame (the flange) standing so, or nullopt
  /// when this gripper does not model that stance (a planner keeps them as the cell has them).
  virtual std::optional<std::vector<OrientedBox>> fingerBoxes(const FingerStance& stance) const = 0;
  /// The widest opening (m) of a gripper that opens to a width; nullopt for one that opens fully.
  virtual std::optional<double> stroke() const = 0;
  /// The opening a grasp needs for a part `half_width` (m) either side of the tool's axis,
  /// `margin` added, at most the stroke; nullopt when the part is wider than the stroke; 0 (open
  /// fully) for a gripper without a width.
  virtual std::optional<double> graspOpening(double half_width, double margin) const = 0;
  /// Whether a grasp taught in `mode` is planned with that mode's fingers.
  virtual bool plansMode(const std::string& mode) const = 0;
  /// The most closed position in `mode` that leaves `half_width` (m) clear either side of the
  /// tool's axis between the fingertips: how far to close them before going down round a part
  /// among neighbours; 0 when the fingers cannot close part way.
  virtual double fingertipPosition(const std::string& mode, double half_width) const = 0;
  /// How far (m) the fingers reach along the tool's x either side of its axis when they hold a
  /// part (in `mode`, for a gripper with modes); nullopt when not modelled (no shifted grasps).
  virtual std::optional<double> reachAcross(const std::string& mode) const = 0;
  /// Half the closed fingers' extent (m) along the tool's x and y: a push leads with them.
  virtual Eigen::Vector2d closedHalfExtent() const = 0;
  /// Adds to the Open operation's `params` what makes the fingers stand so (an opening, or a
  /// position); without it they open fully.
  virtual void openTo(const FingerStance& stance, component::ParamMap& params) const = 0;
  /// The gripper's modes by name (empty for a gripper without modes).
  virtual std::vector<std::string> modes() const = 0;
};

/// A parallel gripper with these fingers: they are modelled at every opening; it opens as far
/// as a grasp needs.
std::unique_ptr<GripperGeometry> parallelGripperGeometry(FingerGeometry fingers);
/// An adaptive gripper with modes: its fingers are modelled in each mode, open or (in a
/// fingertip mode) closed part way; it opens fully, or to a position in a fingertip mode.
std::unique_ptr<GripperGeometry> adaptiveGripperGeometry(AdaptiveGripperDescription description);
/// A gripper whose fingers are not modelled: the robot model's finger shapes stay; it opens
/// fully; its closed fingers are taken as 3 cm square.
std::unique_ptr<GripperGeometry> rigidGripperGeometry();

}  // namespace costar::gripper
