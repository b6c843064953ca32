#pragma once
// The ArUco marker that marks the workspace centre on a new set-up (the paper used AR Track
// Alvar; this uses OpenCV's ArUco, dictionary DICT_4X4_50). The marker frame: origin at the
// marker's centre, x towards the right edge of the marker image, y towards its top edge, z out
// of the marker. Lying face up on the table with its image's right edge towards the world's +x
// and its top edge towards +y, the marker's frame is the table_center frame.

#include <optional>
#include <vector>

#include "camera/rgbd.h"
#include "core/image.h"
#include "world/pose.h"

namespace costar::perception {

struct MarkerOptions {
  int id = 0;
  /// Side of the black square (m).
  double size = 0.10;
};

struct MarkerDetection {
  int id = 0;
  /// Marker frame in the camera optical frame.
  world::Pose pose_in_camera = world::Pose::Identity();
  /// Image corners (pixels): top-left, top-right, bottom-right, bottom-left of the marker.
  std::vector<Eigen::Vector2d> corners;
};

/// The marker `id` as an image (black marker with its 1-cell black border, on white):
/// `cell_pixels` per cell of the 6 x 6 grid, `quiet_cells` white cells around it.
RgbImage arucoMarkerImage(int id, int cell_pixels = 40, int quiet_cells = 1);

/// Markers in `image` with their poses (square pixels, no distortion: `intrinsics`), each
/// marker `marker_size` (m) wide.
std::vector<MarkerDetection> detectArucoMarkers(const RgbImage& image, const camera::Intrinsics& intrinsics,
                                                double marker_size);

/// The workspace centre (table_center, world frame) from the marker in `frame`:
/// camera_pose * marker pose; nullopt when the marker is not seen. With depth in `frame`, the
/// marker's plane and position come from the depth points inside the marker (ArUco's distance
/// from the marker's apparent size is off by about 1 % at 640 x 480) and its in-plane
/// direction from ArUco.
std::optional<world::Pose> locateWorkspaceCenter(const camera::RgbdFrame& frame, const MarkerOptions& options = {});

}  // namespace costar::perception
