#pragma once
// Where to show the marker to the camera: candidate marker poses in the world, in the order
// the arm should try them. Pure geometry; the arm's planning decides which are reachable and
// collision-free, the camera whether the marker is really seen.

#include <cstdint>
#include <vector>

#include "camera/rgbd.h"
#include "world/pose.h"

namespace costar::calibration {

struct ViewPlanOptions {
  /// Where the marker's centre may be, in the world.
  Eigen::Vector3d region_min{0.35, -0.25, 0.18};
  Eigen::Vector3d region_max{0.65, 0.25, 0.36};
  /// Marker poses turned away from facing the camera by up to tilt (about the marker's x and
  /// y) and roll (about its normal), degrees. Zero: facing the camera squarely, upright.
  double tilt_deg = 0.0;
  double roll_deg = 0.0;
  /// Without tilt (stage b): the spread poses turned about the marker's normal by this much in
  /// turn (+, -, +1/2, -1/2 of it, degrees), so that the marker's edges cross the image's pixel
  /// grid at different angles and their corners' sub-pixel errors average out.
  double facing_roll_deg = 0.0;
  /// Candidates differ from each earlier one by at least this rotation (degrees).
  double min_separation_deg = 0.0;
  std::uint64_t seed = 1;
};

/// The marker facing the camera from `position`: its z towards the camera's centre, its y
/// (the image's up) as close to the world's up as that allows.
world::Pose facingCamera(const Eigen::Vector3d& position, const world::Pose& camera_in_world);

/// `count` candidate marker poses. Without tilt: spread over the region (its corners and
/// centre first), facing the camera (stage b), rolled by facing_roll_deg in turn. With tilt: random positions and
/// orientations, each differing from the earlier ones by min_separation_deg (stage a).
std::vector<world::Pose> candidateMarkerPoses(const world::Pose& camera_in_world, const ViewPlanOptions& options,
                                              int count);

/// Whether a marker `size` wide at `marker` (world) would be seen whole by the camera at
/// `camera_in_world`: in front of it, `margin_px` inside the image, and facing it within
/// `max_angle_deg`.
bool markerInView(const world::Pose& marker, double size, const world::Pose& camera_in_world,
                  const camera::Intrinsics& intrinsics, double margin_px, double max_angle_deg);

}  // namespace costar::calibration
