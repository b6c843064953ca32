#pragma once
// SVM training data collected in the simulated workcell (the paper's Fig. 4): the workspace
// centre from the ArUco marker on the clear table, then for many random placements the
// median of a few frames, cropped around that centre, the points above the table split into
// one example per object by Euclidean clustering, labelled by what the placement holds:
// parts of one class at a time (positive examples), the robot and gripper over the table, the
// table and clutter objects (negative examples). `costar perception collect` runs it; then
// `costar perception train`. docs/PERCEPTION.md.

#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <string>

#include "world/pose.h"

namespace costar::trials {

struct CollectOptions {
  std::filesystem::path out = "perception_dataset";  // dataset.json + binary files
  /// Where to write the workspace centre (empty: OUT/workspace.json).
  std::filesystem::path workspace_file;
  int scenes_per_class = 30;
  int parts_per_scene = 6;
  int arm_scenes = 48;      // the robot over the table
  int clutter_scenes = 12;  // objects of no class
  /// Parts touching and stacked (links across nodes) with the arm over them, labelled point by
  /// point from the simulator's truth.
  int mixed_scenes = 60;
  /// The simulated cell (workcells/NAME.json) whose arm, gripper and camera are posed.
  std::string workcell = "ur5-sim";
  int frames = 9;          // per placement (median filter)
  std::uint64_t seed = 1;  // of the placements and the sensor noise
};

/// What is going on: a step begins (`scene` empty), or a placement was added.
struct CollectProgress {
  int step = 0;  // 1: workspace centre, 2: positive examples, 3: negative examples, 4: mixed
  std::string scene;
  int done = 0;  // placements so far, of `total`
  int total = 0;
  int examples = 0;  // clusters the placement gave
  int voxels = 0;
};

struct CollectResult {
  world::Pose table_center = world::Pose::Identity();
  std::filesystem::path workspace_file;
  std::filesystem::path dataset;
  std::map<int, std::string> names;  // per label
  std::map<int, long> voxels;        // rows per label
  long rows = 0;
  double seconds = 0.0;
};

/// @throws std::runtime_error when the marker is not in view, the cell cannot be read or a file
/// cannot be written.
CollectResult collectTrainingData(const CollectOptions& options,
                                  const std::function<void(const CollectProgress&)>& progress = {});

}  // namespace costar::trials
