#pragma once
// The calibration component (the paper's HandEyeCalibration, Sec. III-B): an ArUco marker is
// fixed to the gripper; the arm shows it to the fixed RGB-D camera from poses it chooses
// itself (reachable, collision-free by the arm's own planning, the marker facing the camera,
// rotated enough between views), and the camera's pose in the world follows.
//
// Operations
//   CalibrateMarker(views, method, speed)  the one-time marker calibration: the marker's place
//                                         on the flange by hand-eye calibration (Daniilidis'
//                                         dual quaternions by default), refined on the corners'
//                                         reprojection; also sets the camera
//   Calibrate(views, speed)               the menu's Calibrate button: the camera's pose from a
//                                         few views of the marker, once its place is known
// Both move the arm back to where it started, save the result with the cell, and keep the
// previous calibration when anything is wrong (marker not seen, too few or too similar views,
// a degenerate solution, residuals too large), failing with the reason.
// The table's part area (CalibrationConfig::keep_out, from the workcell's description) is an
// obstacle of every motion a calibration plans: the camera is not calibrated yet, so no part
// seen can be trusted, and the arm, gripper and marker stay out of everywhere a part may lie.
// Every view pose and every motion between views (and back) is planned and checked against it
// by the cell's motion service (arm/motion_service.h), the keep-out in the query's scene (no
// other query sees it); a view that would enter it is tried higher
// (CalibrationConfig::lift_step), or left out. The arm moves by its FollowJointPath operation,
// as SmartMove moves it, so the calibration needs neither the arm's class nor its process.
// Symbols: `camera` (the RGB-D camera's optical frame in the world, as calibrated).
// Predicate: camera_calibrated (the camera's pose comes from a Calibrate, not the drawings).

#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "arm/motion_service.h"
#include "calibration/calibration_file.h"
#include "calibration/hand_eye.h"
#include "camera/rgbd.h"
#include "component/operation_table.h"
#include "core/clock.h"

namespace costar::calibration {

struct CalibrationConfig {
  std::string name = "calibration";
  int marker_id = 1;
  SolveOptions solve;
  /// Where the marker roughly is on the flange (the drawings): aims the views before the
  /// marker is calibrated; never used as a result.
  world::Pose marker_in_flange_guess = world::Pose::Identity();
  /// The tool centre point (the motion service's poses) in the flange's frame.
  world::Pose tcp_in_flange = world::Pose::Identity();
  /// Where the marker's centre may be put, in the world (in front of the camera, above the
  /// table and the parts).
  Eigen::Vector3d region_min{0.35, -0.25, 0.18};
  Eigen::Vector3d region_max{0.65, 0.25, 0.36};
  /// Largest angle between the marker's normal and the direction to the camera (degrees).
  double max_view_angle_deg = 50.0;
  /// Stage (a): the views differ by at least this rotation from each other (degrees), and
  /// tilt this far from facing the camera.
  double min_view_separation_deg = 12.0;
  double tilt_deg = 35.0;
  double roll_deg = 60.0;
  /// Stage (b): the marker facing the camera, turned about its normal by up to this much
  /// (degrees; ViewPlanOptions::facing_roll_deg).
  double camera_roll_deg = 20.0;
  /// Refine ArUco's corners on the marker's edges (marker_corners.h) and take each view's
  /// marker pose from them (IPPE); off: ArUco's corners and pose as they are.
  bool refine_corners = true;
  int marker_views = 12;
  int camera_views = 10;
  /// Fraction of the arm's top speed.
  double speed = 0.7;
  /// Time the arm rests at a view before the frame is taken.
  Duration settle = std::chrono::milliseconds(150);
  /// Pixels kept free between the marker and the image's border.
  double image_margin_px = 30.0;
  std::uint64_t seed = 1;
  /// No new view is started this long after the operation began (simulated or real time).
  Duration time_budget = std::chrono::seconds(50);
  /// Where the calibration is saved (empty: not saved, e.g. trials and tests).
  std::filesystem::path file;
  /// The table's part area (world; the workcell description's `part_area`): where parts may
  /// lie or stand. No part of the arm enters it while calibrating. Absent: nothing kept out.
  std::optional<Eigen::AlignedBox3d> keep_out;
  /// With a keep-out: a view the arm cannot reach is tried again this much higher (m), and
  /// again, up to the top of the region.
  double lift_step = 0.03;
};

/// The name of the keep-out obstacle in the scene of a calibration's motion queries.
inline constexpr const char* kKeepOutObstacle = "calibration_keep_out";

class CalibrationComponent final : public component::TableComponent {
 public:
  /// `initial` is the calibration the cell starts with (saved earlier); without a camera pose
  /// in it, `drawn_camera_pose` (where the cell's drawings put the camera) is used. `motion`:
  /// the cell's motion service for the arm; `arm`: the component whose FollowJointPath moves it.
  /// The motion service, arm, camera and clock must outlive the component.
  CalibrationComponent(const arm::MotionService& motion, component::Component& arm, camera::RgbdCamera& camera,
                       const Clock& clock, const world::Pose& drawn_camera_pose, CellCalibration initial,
                       CalibrationConfig config);

  world::Report report() const override;

  /// The camera's optical frame in the world that perception uses now. Thread-safe.
  world::Pose cameraPose() const;
  /// The calibration now (marker, camera).
  CellCalibration calibration() const;
  const CalibrationConfig& config() const { return config_; }

 private:
  friend class CalibrationRun;
  /// Starts Calibrate, or CalibrateMarker with `marker_stage` (the operations' handlers).
  std::unique_ptr<component::RunningOperation> beginCalibration(bool marker_stage, const component::ParamMap& params);
  /// Saves and applies an accepted calibration; returns a problem saving it, or "".
  std::string accept(const CellCalibration& next);

  const arm::MotionService& motion_;
  component::Component& arm_;
  camera::RgbdCamera& camera_;
  const Clock& clock_;
  world::Pose drawn_camera_pose_;
  CalibrationConfig config_;
  mutable std::mutex mutex_;
  CellCalibration calibration_;
  bool running_ = false;
};

}  // namespace costar::calibration
