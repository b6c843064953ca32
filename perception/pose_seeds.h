#pragma once
// Start poses for stage 4 besides ObjRecRANSAC's hypotheses: from the points' principal axes,
// and upright on the table (or on another part) under the points, turned in steps. Poses are
// object frame -> camera optical frame, the camera at the origin.

#include <vector>

#include "perception/cloud.h"
#include "perception/workspace.h"
#include "world/object_class.h"
#include "world/pose.h"

namespace costar::perception {

/// m: points whose lowest lie this far above the table may rest on another part.
inline constexpr double kRaisedSupport = 0.015;

/// How high the lowest of `indices` of `points` lie above `support`: their 5th percentile
/// height (m); 0 for no points.
double lowHeight(const Cloud& points, const std::vector<int>& indices, const TablePlane& support);

/// Start poses of an object of `object_class` from the principal axes of `indices` of `points`:
/// every proper rotation taking the object frame's axes to them (24), the object pushed back
/// along the smallest one (away from the camera) by half its size. Empty for fewer than 10
/// points.
std::vector<world::Pose> principalAxisSeeds(const Cloud& points, const std::vector<int>& indices,
                                            const world::ObjectClass& object_class);

/// Start poses (in the optical frame, the camera at the origin) of an object of
/// `object_class` resting upright on `support` under `indices` of `points`: its z along the
/// plane's normal, its bottom on the plane under the points (pushed back from the camera by a
/// quarter of its width: the seen faces are its top and the side facing the camera), turned
/// about the normal in 15° steps from the points' main horizontal axis (12 poses: 0..165°);
/// the same 12 with the middle a quarter of the footprint's width along and across that axis
/// (a part partly in view: its points' mean is not over its middle): 60 poses. When the points'
/// lowest (their 5th percentile) lie more than 1.5 cm above the plane, as many more with its
/// bottom at that height: resting on another part (a link on a node). Empty for fewer than 10
/// points.
std::vector<world::Pose> restingSeeds(const Cloud& points, const std::vector<int>& indices, const TablePlane& support,
                                      const world::ObjectClass& object_class);

/// The same poses at both ends of the points instead of under their middle, when the points
/// spread along their main horizontal axis over more than one and a half times the object's
/// length (touching parts of a class, whose middle lies between them), or, for an elongated
/// object, over less than 0.8 of it (one end hidden: its middle lies nearer the hidden end than
/// the points' mean): half an object in from the points' extremes (2nd and 98th percentiles);
/// 24 poses (48 raised), else none.
std::vector<world::Pose> restingSeedsAtEnds(const Cloud& points, const std::vector<int>& indices,
                                            const TablePlane& support, const world::ObjectClass& object_class);

/// restingSeeds (`middle`) and restingSeedsAtEnds (`ends`) from one pass over the points.
struct RestingStarts {
  std::vector<world::Pose> middle;
  std::vector<world::Pose> ends;
};
RestingStarts restingStarts(const Cloud& points, const std::vector<int>& indices, const TablePlane& support,
                            const world::ObjectClass& object_class);

}  // namespace costar::perception
