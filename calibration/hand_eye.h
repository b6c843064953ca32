#pragma once
// Hand-eye calibration of a fixed camera and a marker on the robot's flange (the paper, Sec.
// III-B): pure algorithms on recorded views, no robot, no camera. OpenCV stays in the .cpp.
//
// Frames: F_i = the flange in the world (from the arm's joint encoders) at view i; B_i = the
// marker in the camera (ArUco); X = the marker in the flange; Y = the camera's optical frame in
// the world. Every view satisfies F_i X = Y B_i.
//
// Two stages (docs/CALIBRATION.md):
//   (a) solveMarker: the one-time marker calibration. X and Y from many views with enough
//       rotation between them: OpenCV's hand-eye methods (Daniilidis' dual quaternions, the
//       paper's choice; Tsai, Park, Horaud, Andreff; and the robot-world methods Shah and Li),
//       then refined by minimizing the reprojection error of the marker's corners over X and Y.
//   (b) solveCamera: Calibrate. X known; Y alone from a few views, by one PnP over the corners
//       of every view (each corner's world position is F_i X c_k).

#include <array>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "camera/rgbd.h"
#include "world/pose.h"

namespace costar::calibration {

/// A calibration that cannot be trusted (too few views, too similar, degenerate, residuals too
/// large). The message says which and what to do.
class CalibrationError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// One view of the marker.
struct MarkerView {
  /// The flange in the world when the image was taken (F_i).
  world::Pose flange_in_world = world::Pose::Identity();
  /// The marker in the camera's optical frame, from ArUco (B_i).
  world::Pose marker_in_camera = world::Pose::Identity();
  /// Image corners (pixels): top-left, top-right, bottom-right, bottom-left of the marker.
  std::array<Eigen::Vector2d, 4> corners{};
};

enum class HandEyeMethod { kDaniilidis, kTsai, kPark, kHoraud, kAndreff, kShah, kLi };

/// "daniilidis", "tsai", "park", "horaud", "andreff", "shah", "li".
std::string methodName(HandEyeMethod method);
/// @throws std::invalid_argument naming the known methods.
HandEyeMethod methodFromName(const std::string& name);
/// Every method, Daniilidis first.
std::vector<HandEyeMethod> allMethods();

struct Residuals {
  /// Corner reprojection error over all views (pixels): root mean square and largest.
  double reprojection_rms_px = 0.0;
  double reprojection_max_px = 0.0;
  /// |F_i X - Y B_i| over the views: median rotation (degrees) and translation (m).
  double rotation_deg = 0.0;
  double translation_m = 0.0;
};

struct MarkerCalibration {
  HandEyeMethod method = HandEyeMethod::kDaniilidis;
  bool refined = false;
  world::Pose marker_in_flange = world::Pose::Identity();  // X
  world::Pose camera_in_world = world::Pose::Identity();   // Y
  Residuals residuals;
  int views = 0;     // views used
  int rejected = 0;  // views left out as outliers (SolveOptions::outlier_factor)
};

struct CameraCalibration {
  world::Pose camera_in_world = world::Pose::Identity();
  Residuals residuals;
  int views = 0;     // views used
  int rejected = 0;  // views left out as outliers
};

struct SolveOptions {
  /// Side of the marker's black square (m).
  double marker_size = 0.05;
  /// Stage (a): fewest views, and the rotation that must separate the most different pair.
  int min_marker_views = 6;
  double min_rotation_spread_deg = 20.0;
  /// Stage (b): fewest views, and the spread of the marker's positions (m) that makes the
  /// camera's orientation observable.
  int min_camera_views = 3;
  double min_position_spread = 0.15;
  /// A solution whose corner reprojection error exceeds this (pixels, RMS) is refused.
  double max_reprojection_rms_px = 3.0;
  /// After a first solution, a view whose corners fit worse than this many times the median
  /// view (and worse than outlier_floor_px, RMS) is left out and the solution found again
  /// without it (a misdetected or partly hidden marker); at most a quarter of the views, and
  /// never below the fewest views needed. 0: keep every view.
  double outlier_factor = 3.0;
  double outlier_floor_px = 0.75;
  /// Stage (a): where the marker roughly is on the flange (the drawings). When set, the
  /// refinement also starts from it (with the camera by PnP) and keeps the better fit: a
  /// small marker's ArUco tilt is often off by many degrees, and the hand-eye methods with it.
  std::optional<world::Pose> marker_in_flange_guess;
};

/// Stage (a) with `method`; refined on the corners' reprojection when `refine`.
/// @throws CalibrationError for too few or too similar views, a degenerate solution (rotation
/// axes all parallel) or residuals over the limit.
MarkerCalibration solveMarker(const std::vector<MarkerView>& views, const camera::Intrinsics& intrinsics,
                              HandEyeMethod method, bool refine, const SolveOptions& options = {});

/// Stage (b): the camera from views of the marker whose place on the flange is known.
/// @throws CalibrationError for too few views, views too close together, or residuals over
/// the limit.
CameraCalibration solveCamera(const std::vector<MarkerView>& views, const camera::Intrinsics& intrinsics,
                              const world::Pose& marker_in_flange, const SolveOptions& options = {});

/// Residuals of X and Y on the views.
Residuals residualsOf(const std::vector<MarkerView>& views, const camera::Intrinsics& intrinsics,
                      const world::Pose& marker_in_flange, const world::Pose& camera_in_world, double marker_size);

/// The marker's corners in its own frame (z = 0), in ArUco's order.
std::array<Eigen::Vector3d, 4> markerCorners(double marker_size);

}  // namespace costar::calibration
