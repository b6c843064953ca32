#pragma once
// Where a parallel gripper's fingers are at an opening, as boxes for collision checking: a
// grasp planned with the fingers opened only as far as the part needs fits beside neighbours
// that a box over the fingers' whole travel would hit.

#include <Eigen/Core>
#include <vector>

namespace costar::gripper {

/// A box of a finger, in the gripper's mounting frame (the arm's flange): z along the approach,
/// the fingers closing along y.
struct FingerBox {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  Eigen::Vector3d size = Eigen::Vector3d::Zero();  // full side lengths
};

/// The two fingers of a parallel gripper. Each moves half the opening away from the centre
/// line; the inner faces of the pads are `opening` apart.
struct FingerGeometry {
  /// The +y finger's boxes when the gripper is closed; the other finger is its mirror image.
  std::vector<FingerBox> closed;
  double max_opening = 0.0;  // m

  /// Both fingers' boxes at `opening` (m, clamped to 0..max_opening): the +y finger's first.
  std::vector<FingerBox> at(double opening) const;
};

}  // namespace costar::gripper
