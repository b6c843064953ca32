#pragma once
// Parts seen from above: how far apart two parts' footprints are on the table (their bounding
// boxes projected onto x, y). Used to push a part where it has room (SmartPush) and, in trials,
// to nudge a part into free space.

#include "world/object_class.h"
#include "world/pose.h"

namespace costar::smartmove {

/// The gap (m) between the footprints of part `a` at `pose_a` and part `b` at `pose_b`, along
/// the separating axes their boxes' sides give: negative when they overlap (a lower bound of
/// the overlap's depth).
double footprintGap(const world::ObjectClass& a, const world::Pose& pose_a, const world::ObjectClass& b,
                    const world::Pose& pose_b);

/// The distance (m, in x and y) from `point` to part `b`'s bounding box at `pose_b`, the point
/// taken at the part's height (0 inside it).
double distanceToFootprint(const Eigen::Vector2d& point, const world::ObjectClass& b, const world::Pose& pose_b);

}  // namespace costar::smartmove
