#pragma once
// The gripper marker's image corners to a fraction of a pixel. ArUco's own corner refinement
// (cornerSubPix) works on the corner's neighbourhood only; the marker on the gripper is small
// (~30 px at a metre) and, in an image without anti-aliasing, its corners stay on whole pixels
// and a single corner can be off by pixels. Here each of the marker's four outer edges is
// located along its whole length (the black-to-white step, sub-pixel, at every half pixel) and
// a line is fitted to it (cv::fitLine, Huber); the corners are where adjacent lines meet. The
// marker's pose in the camera then follows by PnP on those corners (cv::solvePnP IPPE_SQUARE,
// refined by Levenberg-Marquardt). OpenCV stays in the .cpp.

#include <array>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "camera/rgbd.h"
#include "core/image.h"
#include "world/pose.h"

namespace costar::calibration {

struct MarkerCornerOptions {
  /// Edge samples are taken this far into the edge from each end (fraction of its length),
  /// away from the corners where two edges meet.
  double end_margin = 0.15;
  /// Half-width of the search across the edge (pixels): black inside, white outside.
  double search_px = 2.5;
  /// Least black-to-white contrast (grey levels) for an edge sample to count.
  double min_contrast = 40.0;
  /// A refined corner further than this from ArUco's (pixels) is not trusted: ArUco's is kept.
  double max_shift_px = 4.0;
  /// Rounds of sampling along the fitted lines (the first along ArUco's corners).
  int rounds = 2;
};

/// The four corners (ArUco's order: top-left, top-right, bottom-right, bottom-left of the
/// marker) refined on the marker's outer edges in `image`. Corners whose edges cannot be
/// located (too few contrasting samples, a shift larger than allowed) are returned as given.
std::array<Eigen::Vector2d, 4> refineMarkerCorners(const RgbImage& image, const std::array<Eigen::Vector2d, 4>& corners,
                                                   const MarkerCornerOptions& options = {});

/// The marker (black square `marker_size` wide, frame as calibration::markerCorners) in the
/// camera from its four image corners: IPPE for squares, then Levenberg-Marquardt. Empty when
/// no pose explains them.
std::optional<world::Pose> markerPoseFromCorners(const std::array<Eigen::Vector2d, 4>& corners,
                                                 const camera::Intrinsics& intrinsics, double marker_size);

}  // namespace costar::calibration
