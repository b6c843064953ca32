#pragma once
// Stage 4 of the pipeline: 6-DOF poses of a class's instances in the points the SVM gave that
// class, with PCL's ObjRecRANSAC (Papazov & Burschka 2010; multi-instance), each hypothesis
// refined by point-to-plane ICP onto the class model and scored against the organized depth
// image; hypotheses below a confidence threshold are dropped.
//
// One job a file: seeded_obj_rec_ransac (the hypotheses), icp (refinement), depth_check
// (scoring), pose_seeds (starts besides ObjRecRANSAC's), class_pose_estimator (this class: the
// search per cluster), touching_parts (parts of a class against each other), merge_detections.
//
// All poses here are object frame -> camera OPTICAL frame (x right, y down, z forward): that
// is the frame ObjRecRANSAC needs its scene in (it projects the scene along z).

#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "camera/rgbd.h"
#include "perception/cloud.h"
#include "perception/depth_check.h"
#include "perception/icp.h"
#include "perception/object_model.h"
#include "perception/pose_seeds.h"
#include "perception/workspace.h"
#include "world/pose.h"

namespace costar::perception {

struct PoseEstimationOptions {
  /// ObjRecRANSAC's probability of finding every instance (sets its number of samples).
  double success_probability = 0.995;
  /// Seed of ObjRecRANSAC's sampling (PCL seeds it with the time; this project does not).
  std::uint32_t seed = 1;
  /// The class's points are split into connected clusters (neighbouring pixels closer than
  /// this, m); ObjRecRANSAC runs on each cluster of at least min_cluster_points, with its
  /// "relative object size" set from the cluster's size and the model's.
  double cluster_tolerance = 0.01;
  int min_cluster_points = 25;
  /// Upper bound of the per-cluster relative object size (larger: fewer samples).
  double max_relative_object_size = 0.6;
  /// When a cluster has points left that no detection explains (at least this fraction of
  /// a detected instance's points, or the whole cluster when nothing was found), ObjRecRANSAC
  /// runs again on those points with another seed, up to max_attempts runs per cluster.
  int max_attempts = 3;
  double unexplained_fraction = 0.25;
  /// ObjRecRANSAC's hypotheses are checked best first: a coarse ICP (10 iterations, the
  /// correspondence distance shrinking from icp_initial_distance to icp_coarse_final_distance)
  /// and a quick render-and-compare; a hypothesis that passes is refined with icp_iterations
  /// more (down to icp_final_distance) and checked again in full. Metres.
  double icp_initial_distance = 0.025;
  double icp_coarse_final_distance = 0.008;
  double icp_final_distance = 0.003;
  int icp_iterations = 15;
  /// Tolerance of the render-and-compare check against the depth image (m).
  double depth_tolerance = 0.006;
  /// A detection needs this agreement: of the model surface the camera should see, the
  /// fraction seen where the model says (occluded parts do not count against it).
  double min_confidence = 0.93;
  /// ... and this fraction of the model's camera-facing surface seen at all.
  double min_visible_fraction = 0.2;
};

/// One object instance found in a camera frame.
struct Detection {
  std::string object_class;
  /// Object frame in the camera optical frame.
  world::Pose pose_in_camera = world::Pose::Identity();
  /// Object frame in the world (camera_pose * pose_in_camera), filled by the pipeline.
  world::Pose pose = world::Pose::Identity();
  /// Agreement of the refined pose with the depth image, in [0, 1] (see min_confidence).
  double confidence = 0.0;
  /// ObjRecRANSAC's own match confidence (fraction of the model surface it matched).
  double recognition_score = 0.0;
  /// Fraction of the model's camera-facing surface seen where the model predicts it.
  double visible_fraction = 0.0;
  /// RMS point-to-plane residual of ICP's inliers (m) and their number.
  double fit_rms = 0.0;
  int support = 0;
  /// Mean colour of the points it explains (its class's points inside its boxes, from the
  /// frame's RGB), RGB in [0, 1]; filled by the pipeline, absent when no point had colour.
  std::optional<Eigen::Vector3f> color;
};

/// ObjRecRANSAC loaded with one class's model. Building it hashes the model's point pairs
/// (milliseconds). One instance must not be used by two threads at once; distinct instances
/// may run in parallel.
class ClassPoseEstimator {
 public:
  /// `model` must outlive the estimator.
  explicit ClassPoseEstimator(const ObjectModel& model, PoseEstimationOptions options = {});
  ~ClassPoseEstimator();
  ClassPoseEstimator(const ClassPoseEstimator&) = delete;
  ClassPoseEstimator& operator=(const ClassPoseEstimator&) = delete;

  const ObjectModel& model() const { return model_; }
  const PoseEstimationOptions& options() const { return options_; }

  /// The table the objects stand on (optical frame), for the next estimates: a hypothesis
  /// that puts part of the object more than 4 mm below it is rejected (the depth check alone
  /// cannot see that: the table hides what lies below it). Absent: no such test.
  void setSupportPlane(std::optional<TablePlane> plane) { support_plane_ = plane; }

  /// Time spent: ObjRecRANSAC, then verification (ICP and scoring), seconds.
  struct Timing {
    double recognition = 0.0;
    double refinement = 0.0;
    int runs = 0;        // ObjRecRANSAC runs
    int candidates = 0;  // hypotheses it accepted
    int checked = 0;     // hypotheses verified with the coarse ICP
  };

  /// The clusters estimateCluster() works on: connected groups of `points` (which carry
  /// pixel indices into an image of `intrinsics`' size) of at least min_cluster_points.
  std::vector<std::vector<int>> clusters(const Cloud& points, const camera::Intrinsics& intrinsics) const;

  /// Finds the instances of the class in one cluster of `points` (optical frame, with normals
  /// towards the camera and pixel indices), refining each with the class's points nearby and
  /// checking it against the organized `frame` it came from. `task` seeds the sampling
  /// (deterministic for the same input and task); nothing is printed. Adds its time to
  /// `timing` when given.
  std::vector<Detection> estimateCluster(const Cloud& points, const std::vector<int>& cluster,
                                         const camera::RgbdFrame& frame, std::uint32_t task, Timing* timing = nullptr);

  /// Refines detections of this class that touch each other: each refines on the points of
  /// `points` nearer its own surface than its neighbours' (two rounds), so that touching
  /// parts do not pull each other; an elongated one then slides along its long axes with its
  /// neighbours' surface counted against it. Confidence and visible fraction are updated.
  void refineTouching(const Cloud& points, std::vector<Detection>& detections, const camera::RgbdFrame& frame) const;

  /// Parts lie flat, on the table or on each other: a detection with a face within 20° of the
  /// support plane's normal (and more than 1° off it) is turned about its centre to rest on that
  /// face when the depth image agrees with the levelled pose as well (to 0.005). The depth check
  /// (6 mm tolerance) cannot tell a square link rolled 17° about its length from a flat one, and
  /// SmartRelease puts nothing on a part whose top is tilted. Needs setSupportPlane().
  void levelResting(std::vector<Detection>& detections, const camera::RgbdFrame& frame) const;

  /// Points of `cluster` (indices into `points`) farther than the depth tolerance from every
  /// detection's surface.
  std::vector<int> unexplainedPoints(const Cloud& points, const std::vector<int>& cluster,
                                     const std::vector<Detection>& detections) const;

  /// All clusters in turn, refineTouching(), then mergeDetections(): the instances of the
  /// class in `points`.
  std::vector<Detection> estimate(const Cloud& points, const camera::RgbdFrame& frame, Timing* timing = nullptr);

 private:
  static double meanSupport(const std::vector<Detection>& detections);
  /// An axis of a model's box at least 1.5 times its shortest is long: point-to-plane ICP
  /// cannot tell where along it the object lies (slideAlongLongAxes).
  static bool isLongAxis(const Eigen::Vector3d& size, int axis);

  /// For an elongated model: the shift along its long axes (up to 24 mm) that the depth image
  /// agrees with best, if better than `pose`; nullopt otherwise. With `claimed` pixels (see
  /// compareWithDepth): up to 40 mm, every sample scored.
  std::optional<world::Pose> slideAlongLongAxes(const world::Pose& pose, const camera::RgbdFrame& frame,
                                                const std::vector<std::uint8_t>* claimed = nullptr) const;
  /// Verifies a start pose: coarse ICP (narrow when its raw depth score already fits, else
  /// wide) on the points not yet `taken`, a quick depth check, the fine ICP, the slide along
  /// long axes and the full depth check. Nullopt when a check fails or the pose overlaps one of
  /// `accepted`. Counts verified starts in `checked`.
  std::optional<Detection> verify(const Cloud& points, const world::Pose& start, double raw_score,
                                  const camera::RgbdFrame& frame, const std::vector<bool>& taken,
                                  const std::vector<Detection>& accepted, int* checked) const;
  /// (raw depth score, index) of `starts`, best first; those from `last_resort` on after all others.
  std::vector<std::pair<double, std::size_t>> rankStarts(const std::vector<world::Pose>& starts,
                                                         const camera::RgbdFrame& frame, std::size_t last_resort) const;
  /// True when `unexplained` points of a cluster are few enough for `accepted` to explain it.
  bool explained(std::size_t unexplained, const std::vector<Detection>& accepted) const;
  /// A cluster left unexplained: each accepted detection tried replaced by detections started
  /// at both ends of the points it alone explains (see estimateCluster).
  void splitStraddling(const Cloud& points, const std::vector<int>& cluster, const camera::RgbdFrame& frame,
                       std::vector<Detection>& accepted, int* checked) const;
  /// Marks the points of `points` near `detection`'s surface in `taken`.
  void markExplained(const Cloud& points, const Detection& detection, std::vector<bool>& taken) const;

  /// True when the object under `pose` lies (almost) entirely above the support plane.
  bool aboveSupport(const world::Pose& pose) const;
  /// True when all of the object under `pose` is more than 1.5 cm above the support plane: it
  /// rests on another part.
  bool raised(const world::Pose& pose) const;

  struct Impl;
  const ObjectModel& model_;
  PoseEstimationOptions options_;
  std::optional<TablePlane> support_plane_;
  std::unique_ptr<Impl> impl_;
};

/// A detection more than this fraction of whose volume the better ones claim, one or several
/// together, is not kept (mergeDetections, and a candidate against a cluster's accepted ones).
inline constexpr double kOverlapTaken = 0.2;

/// Detections of the same space merged: best (confidence x visible fraction) first, a detection
/// dropped when more than a fifth of its volume lies in better ones kept, one or several together
/// (a node fitted into the gap between four touching nodes' tops, each holding a fifth or less of
/// it: iiwa-3f-sim, perception eval seed 502 scene 8). `models` must hold every detection's class.
std::vector<Detection> mergeDetections(std::vector<Detection> detections, const std::vector<ObjectModel>& models);
/// The same for detections of one class, of `model`.
std::vector<Detection> mergeDetections(std::vector<Detection> detections, const ObjectModel& model);

/// A detection with no face within this of lying flat leans (levelResting lays flat what is
/// nearer).
inline constexpr double kLeaning = 20.0 * M_PI / 180.0;
/// A leaning detection with nothing found under its raised end needs this much of its
/// camera-facing surface seen (what holds it up may be hidden: a link leaning on a node the arm
/// hides).
inline constexpr double kLeaningSeen = 0.3;

/// Only detections that rest on something: a part lies on the table or on another part, while a
/// box the robot's arm or gripper shows can be matched anywhere above it. A detection is kept
/// when its lowest box corner lies within `tolerance` (m) of `table` (heights in the detections'
/// optical frame), or of the highest corner of a kept detection whose footprint on the table
/// meets its own (a link across a node), repeated until nothing more is kept. A leaning one
/// (kLeaning) must also be held up at its raised end: a kept detection (or cluster, below) whose
/// top rises above its bottom, its footprint within half the leaning one's footprint radius of
/// it (a link leaning from a node onto the table), or else show kLeaningSeen of its facing
/// surface; tilted boxes matched on the arm stood on the table with nothing under them (iiwa-sim,
/// perception eval seed 203 scene 3: a link tilted 45 degrees on the iiwa's orange elbow,
/// confidence 0.98, 22 % of it seen). `unfound` are
/// clusters of a part class's points where no part was found (optical frame): one standing on
/// the table (its 5th percentile height at most kRaisedSupport) holds up a detection as a kept
/// one does, its top its 95th percentile height: a part hidden but for its sides, a node under
/// a link put across it, is seen only as such slivers. `models` must hold every detection's
/// class; the order of the kept ones is kept.
std::vector<Detection> keepSupported(const std::vector<Detection>& detections, const std::vector<ObjectModel>& models,
                                     const TablePlane& table, double tolerance,
                                     const std::vector<std::vector<Eigen::Vector3f>>& unfound = {});

}  // namespace costar::perception
