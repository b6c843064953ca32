#pragma once
// Training examples for the SVM (the paper's set-up procedure, Fig. 4): in a scene that holds
// objects of one known class (or only things to ignore: robot, gripper, table, clutter), the
// points above the table are split by Euclidean clustering (PCL) into one example per object;
// every voxel of an example, with its features, becomes a labelled row.

#include <Eigen/Core>
#include <filesystem>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "camera/rgbd.h"
#include "perception/pipeline.h"

namespace costar::perception {

struct TrainingSet {
  /// One row per voxel, kFeatureCount columns.
  Eigen::MatrixXf features;
  std::vector<int> labels;
  /// Name of each label (0: "background").
  std::map<int, std::string> names;
};

struct ExamplesAdded {
  int examples = 0;  // clusters taken
  int voxels = 0;    // rows added
};

/// Adds the examples of one filtered frame (`frame`: median of the frames of one placement,
/// camera_pose set) with `label`: crop (options.workspace), normals, features, Euclidean
/// clusters of at least 60 points that are no larger than `max_extent` (m; larger groups are
/// several objects or not one of ours, and are skipped unless the label is background). With
/// `add_table`, a sample of the table's own points is added as background too.
ExamplesAdded addTrainingExamples(const camera::RgbdFrame& frame, const PipelineOptions& options, int label,
                                  bool add_table, TrainingSet& set, double max_extent = 0.25);

/// Adds the voxels of one filtered frame whose points `label_of` labels: it gets each cropped
/// point in the world frame (through frame.camera_pose) and gives its label, or -1 for a point
/// that must not be learned from (near a boundary between things). Each voxel takes the label
/// most of its points have, and is skipped when that is -1 or when fewer than `min_points` of
/// its points carry it. For placements whose truth is known (parts stacked, touching, partly
/// hidden under the robot): one scene gives every class's and the background's examples.
ExamplesAdded addLabelledExamples(const camera::RgbdFrame& frame, const PipelineOptions& options,
                                  const std::function<int(const Eigen::Vector3d& world_point)>& label_of,
                                  TrainingSet& set, int min_points = 3);

/// Writes `set` to `folder` (dataset.json, features.f32, labels.i32). @throws std::runtime_error.
void saveTrainingSet(const TrainingSet& set, const std::filesystem::path& folder);
/// @throws std::runtime_error naming the file and the problem.
TrainingSet loadTrainingSet(const std::filesystem::path& folder);

}  // namespace costar::perception
