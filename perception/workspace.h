#pragma once
// Stage 2 of the pipeline: the workspace crop. A box around the `table_center` frame (on the
// table top, z up), a plane fitted to the table (PCL RANSAC), and the points within a band
// of heights above that plane: what lies on the table.

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "camera/rgbd.h"
#include "perception/cloud.h"
#include "world/pose.h"

namespace costar::perception {

struct WorkspaceOptions {
  /// The workspace centre: a frame on the table top, z out of the table (world frame; the
  /// ArUco marker of `costar perception collect` finds it on a new set-up).
  world::Pose table_center = world::Pose(Eigen::Translation3d(0.5, 0.0, 0.0));
  /// Half extents of the crop box along table_center's x and y axes (m).
  double half_size_x = 0.3;
  double half_size_y = 0.5;
  /// Points kept: heights above the fitted table plane within [min_height, max_height] (m).
  /// min_height clears the table's depth noise (about 1.5 mm after the median at 1.2 m, plus
  /// the sensor's disparity steps of 4 mm).
  double min_height = 0.007;
  double max_height = 0.25;
  /// Candidates for the plane fit: points within this distance of table_center's xy plane (m).
  double plane_search_band = 0.015;
  /// RANSAC inlier distance of the plane fit (m).
  double plane_inlier_distance = 0.004;
  /// The plane fit uses every k-th pixel in both directions (speed: the median filter runs on
  /// those pixels of the table only).
  int plane_fit_stride = 5;
};

/// The table plane in the optical frame: normal . p + offset = 0, the normal pointing out of
/// the table (towards the camera).
struct TablePlane {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  double offset = 0.0;
  int inliers = 0;

  double height(const Eigen::Vector3f& point) const { return normal.dot(point.cast<double>()) + offset; }
};

struct WorkspaceCloud {
  /// Points in the box and the height band: optical frame, with colours and pixel indices.
  Cloud cloud;
  /// Height of each point above the table plane (m).
  std::vector<float> heights;
  TablePlane plane;
  /// Pixels of the table inside the box, every `plane_fit_stride`-th (for negative training data).
  Cloud table;
};

/// Reads the table_center pose that `costar perception collect` found and saved
/// (data/perception/workspace.json: {"table_center": {"xyz": [m], "rpy_deg": [deg]}}).
/// @throws std::runtime_error naming the file and the problem.
world::Pose loadTableCenter(const std::filesystem::path& file);
/// Writes it, with a note on where it came from. @throws std::runtime_error.
void saveTableCenter(const std::filesystem::path& file, const world::Pose& table_center, const std::string& note);

/// The pixels whose rays can meet the crop box (its corners projected, bounding rectangle,
/// clipped to the image): the median filter needs to run there only.
PixelRect workspaceRegion(const camera::Intrinsics& intrinsics, const world::Pose& camera_pose,
                          const WorkspaceOptions& options);

/// The pixels the workspace crop can keep, judged cheaply on three of the raw `frames` (the
/// first, middle and last; camera_pose set) so that the median filter need not run elsewhere:
/// inside the box, and either higher above the table_center plane than min_height - `margin`
/// (m) by the median of those three samples, or on the plane fit's pixel grid; then grown by
/// one pixel (lateral jitter at edges). @throws std::invalid_argument without frames.
std::vector<std::uint8_t> workspaceMask(std::span<const camera::RgbdFrame> frames, const WorkspaceOptions& options,
                                        double margin = 0.004);

/// Crops an organized frame (optical frame, camera_pose set) to the workspace.
/// @throws std::runtime_error when no table plane is found in the box (the camera does not
/// see the table, or table_center is wrong).
WorkspaceCloud cropWorkspace(const camera::RgbdFrame& frame, const WorkspaceOptions& options);

/// Estimates a unit normal for each point of `cloud` (which must carry pixel indices into the
/// organized `frame`) by principal component analysis of its neighbours in a window of
/// (2 * window_radius + 1)^2 pixels that are in `cloud` too and within `max_distance` (m).
/// Normals are oriented towards the camera; a point with fewer than 5 neighbours gets the
/// viewing direction's opposite.
void estimateNormals(const camera::RgbdFrame& frame, Cloud& cloud, int window_radius = 3, float max_distance = 0.012f);

}  // namespace costar::perception
