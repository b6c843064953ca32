#pragma once
// The perception pipeline of DetectObjects (the paper's Sec. IV-A), stage by stage:
//   1. median filter over N organized frames            (median_filter.h)
//   2. workspace crop: box around table_center, table plane fit, height band (workspace.h)
//   3. surface normals, then SVM segmentation into classes and background (segmentation.h)
//   4. per class: ObjRecRANSAC on each cluster, ICP, depth check (pose_estimation.h); each
//      found object's mean colour from the class's points inside it (measureColors)
// and the poses into the world frame through the frames' camera_pose. Canonical orientation
// and persistence (stages 5 and 6) keep state across detections: PersistenceFilter.
//
// It never reads simulator ground truth: its inputs are camera frames, the camera's pose
// (calibration) and the data files.

#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "camera/rgbd.h"
#include "perception/object_model.h"
#include "perception/pose_estimation.h"
#include "perception/segmentation.h"
#include "perception/svm_classifier.h"
#include "perception/workspace.h"

namespace costar::perception {

/// Where the pipeline's data lives (defaults: the repository's data/ folder, see core/paths.h).
struct PipelineFiles {
  /// Object classes (data/objects).
  std::filesystem::path objects_dir;
  /// Per-class perception parameters (data/perception/classes.json).
  std::filesystem::path classes_file;
  /// The trained SVM: the default is the UR5 cell's (data/perception/svm/ur5-sim.json); a
  /// simulated cell names its own (workcells/NAME.json "perception_model").
  std::filesystem::path svm_file;
  /// The workspace centre found by `costar perception collect` (data/perception/workspace.json).
  std::filesystem::path workspace_file;

  /// The files under `root` (dataRoot() when empty).
  static PipelineFiles under(const std::filesystem::path& root = {});
};

struct PipelineOptions {
  WorkspaceOptions workspace;
  SegmentationOptions segmentation;
  PoseEstimationOptions pose;
  /// Normal estimation window (pixels around each point) and neighbour distance (m).
  int normal_window = 3;
  double normal_max_distance = 0.012;
  /// A detection's colour is the mean of its class's points within this distance of its
  /// boxes (m).
  double color_margin = 0.004;
  /// A detection is kept only when it rests on the table or on another detection, within this
  /// (m; keepSupported in pose_estimation.h): boxes on the robot's arm and gripper are not parts.
  double support_tolerance = 0.01;
  /// Worker threads of the median filter, the FPFH histograms and the pose estimation
  /// (results do not depend on it; it sets segmentation.features.threads).
  int threads = 2;
};

/// Wall time of each stage of one detection (seconds). Stage 1 filters only the pixels the
/// crop can keep (workspaceMask); the depth checks see the last raw frame elsewhere.
struct StageTimes {
  double median = 0.0;
  double crop = 0.0;  // box, plane fit, height band
  double normals = 0.0;
  double features = 0.0;        // voxels + FPFH + colour
  double classification = 0.0;  // SVM + smoothing
  double recognition = 0.0;     // ObjRecRANSAC (summed over threads: CPU time)
  double refinement = 0.0;      // ICP + depth checks (summed over threads)
  double pose = 0.0;            // wall time of stage 4
  double total = 0.0;
};

struct PipelineResult {
  /// Found objects: class, pose in the camera and in the world, confidence. Ordered by class
  /// (models order), then best first.
  std::vector<Detection> detections;
  StageTimes times;
  /// Points above the table, and how many the SVM gave each label.
  int workspace_points = 0;
  std::vector<std::pair<int, int>> points_per_label;
  /// Stage 4's work: clusters, ObjRecRANSAC runs, hypotheses it accepted, hypotheses checked.
  int pose_clusters = 0;
  int pose_runs = 0;
  int pose_candidates = 0;
  int pose_checked = 0;
  /// The points above the table (optical frame, pixel indices) and the SVM label of each.
  Cloud workspace;
  std::vector<int> labels;
  /// The median-filtered frame the stages worked on (for pictures and evaluation).
  std::shared_ptr<const camera::RgbdFrame> filtered;
};

/// Sets each detection's `color`: the mean RGB of the points of `class_points` (one cloud per
/// model, optical frame, with colours) that lie within `margin` (m) of the detection's boxes
/// under its pose_in_camera. A detection of a class not in `models`, or with no such point,
/// gets none. Linear in points x detections of their class.
void measureColors(const std::vector<ObjectModel>& models, const std::vector<Cloud>& class_points,
                   std::vector<Detection>& detections, double margin);

class Pipeline {
 public:
  /// @throws std::runtime_error when a file is missing or inconsistent (e.g. the SVM does not
  /// know a class), naming it and what to do.
  Pipeline(std::vector<ObjectModel> models, SvmClassifier classifier, PipelineOptions options = {});
  static std::unique_ptr<Pipeline> load(const PipelineFiles& files, PipelineOptions options = {});
  ~Pipeline();
  Pipeline(const Pipeline&) = delete;
  Pipeline& operator=(const Pipeline&) = delete;

  /// Runs stages 1-4 on a frame set (same camera, same pose, capture order). Not reentrant:
  /// one detect() at a time. Deterministic for the same frames.
  /// @throws std::invalid_argument for an empty or inconsistent frame set; std::runtime_error
  /// when the table is not found.
  PipelineResult detect(std::span<const camera::RgbdFrame> frames);

  /// Stages 2-4 on an already filtered frame (e.g. from medianFrame()). The depth checks of
  /// stage 4 use `depth_reference` when given (a frame with readings where `frame` has none).
  PipelineResult detectFiltered(const camera::RgbdFrame& frame, const camera::RgbdFrame* depth_reference = nullptr);

  const std::vector<ObjectModel>& models() const { return models_; }
  const ObjectModel* model(const std::string& name) const;
  const SvmClassifier& classifier() const { return classifier_; }
  const PipelineOptions& options() const { return options_; }

 private:
  struct Workers;
  std::vector<ObjectModel> models_;
  SvmClassifier classifier_;
  PipelineOptions options_;
  std::vector<int> label_of_model_;
  std::unique_ptr<Workers> workers_;
};

}  // namespace costar::perception
