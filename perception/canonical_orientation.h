#pragma once
// Stage 5 of the pipeline: setCanonicalOrientation. An object with symmetries has several
// equally valid frames (a cube: 24). Of the rotations R * S (S one of the class's
// symmetries, object frame), the canonical one is the one whose axes best match a reference
// frame, axis by axis in the class's priority order: first the one whose axis_priority[0]
// axis points most nearly along the reference's same axis; among ties, by axis_priority[1];
// then axis_priority[2]. The reference is the world frame for a new object (so a cube's z
// points up and its x as close to the world's x as its symmetry allows) and the previous
// pose for a tracked one (so its frame does not flip between detections).

#include <Eigen/Geometry>

#include "world/object_class.h"
#include "world/pose.h"

namespace costar::perception {

struct CanonicalPose {
  world::Pose pose = world::Pose::Identity();
  /// Index in object_class.symmetries of the S applied (0: the identity).
  int symmetry = 0;
};

/// The canonical equivalent of `pose` (object frame in some frame F) with respect to
/// `reference` (a rotation in the same frame F). The position is unchanged: symmetries are
/// rotations about the object frame's origin. Axis comparisons treat differences below
/// `tolerance` (in cosine) as ties.
CanonicalPose setCanonicalOrientation(const world::Pose& pose, const world::ObjectClass& object_class,
                                      const Eigen::Matrix3d& reference = Eigen::Matrix3d::Identity(),
                                      double tolerance = 1e-6);

/// Smallest rotation angle (rad) between `a` and any symmetric equivalent of `b`: the rotation
/// error of a detection when the object looks the same in several orientations.
double symmetricRotationDistance(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b,
                                 const world::ObjectClass& object_class);

}  // namespace costar::perception
