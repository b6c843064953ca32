#include "trials/perception_collect.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <memory>
#include <optional>
#include <random>
#include <stdexcept>
#include <utility>
#include <vector>

#include "arm/kinematics.h"
#include "core/files.h"
#include "core/paths.h"
#include "perception/aruco_marker.h"
#include "perception/median_filter.h"
#include "perception/object_model.h"
#include "perception/pipeline.h"
#include "perception/training_data.h"
#include "perception/workspace.h"
#include "sim/simulation.h"
#include "trials/perception_scenes.h"
#include "workcell/cell_simulation.h"

namespace costar::trials {

namespace {

namespace fs = std::filesystem;

/// The simulated camera's frames for a pipeline run: `count` frames 1/30 s apart.
std::vector<camera::RgbdFrame> captureFrames(sim::Simulation& simulation, int count, std::uint64_t seed) {
  std::vector<camera::RgbdFrame> frames;
  for (int i = 0; i < count; ++i) {
    simulation.stepTo(simulation.time() + std::chrono::nanoseconds(33'333'333));
    // Colour only for the last frame: the median filter takes its colour from that one.
    frames.push_back(simulation.captureRgbd(seed + static_cast<std::uint64_t>(i), i + 1 == count));
  }
  return frames;
}

/// The label of a point from the simulator's truth: the SVM label of the part whose bounds
/// (grown by 3 mm) hold it; -1 (not learned from) within 8 mm of a part's bounds otherwise;
/// else background (0): the table's edge, the robot, the gripper, clutter.
int truthLabel(const Eigen::Vector3d& point, const std::vector<sim::PartState>& parts,
               const std::map<std::string, std::pair<Eigen::AlignedBox3d, int>>& bounds_and_label) {
  int label = 0;
  for (const sim::PartState& part : parts) {
    const auto found = bounds_and_label.find(part.object_class);
    if (found == bounds_and_label.end()) {
      continue;  // clutter: background
    }
    const Eigen::Vector3d local = part.pose.inverse() * point;
    const Eigen::AlignedBox3d& bounds = found->second.first;
    const double outside = (local - bounds.min()).cwiseMin(Eigen::Vector3d::Zero()).norm() +
                           (local - bounds.max()).cwiseMax(Eigen::Vector3d::Zero()).norm();
    if (outside <= 0.003) {
      return found->second.second;
    }
    if (outside <= 0.008) {
      label = -1;
    }
  }
  return label;
}

/// Clutter: object classes that are neither nodes nor links (negative examples), written to
/// a data root of their own next to the real sim/models.
fs::path makeClutterRoot(const fs::path& directory) {
  const fs::path root = directory / "clutter_root";
  fs::create_directories(root / "data" / "objects");
  fs::create_directories(root / "sim");
  if (!fs::exists(root / "sim" / "models")) {
    fs::create_directory_symlink(fs::absolute(dataRoot() / "sim" / "models"), root / "sim" / "models");
  }
  if (!fs::exists(root / "robots")) {  // the adaptive gripper's description
    fs::create_directory_symlink(fs::absolute(dataRoot() / "robots"), root / "robots");
  }
  const std::vector<std::pair<std::string, std::string>> clutter = {
      {"plate", R"({"name": "plate", "description": "clutter: a flat plate", "mass": 0.1,
        "boxes": [{"center": [0, 0, 0], "half_size": [0.06, 0.04, 0.006]}], "rest_height": 0.006,
        "symmetry": {"generators": []},
        "colors": {"white": [0.9, 0.9, 0.88], "teal": [0.1, 0.5, 0.5], "black": [0.08, 0.08, 0.08]}})"},
      {"tower", R"({"name": "tower", "description": "clutter: a tall block", "mass": 0.2,
        "boxes": [{"center": [0, 0, 0], "half_size": [0.02, 0.03, 0.06]}], "rest_height": 0.06,
        "symmetry": {"generators": []},
        "colors": {"purple": [0.5, 0.2, 0.6], "orange": [0.95, 0.45, 0.1], "white": [0.9, 0.9, 0.88]}})"},
      {"ell", R"({"name": "ell", "description": "clutter: an L-shaped bracket", "mass": 0.1,
        "boxes": [{"center": [0, 0, 0], "half_size": [0.05, 0.01, 0.01]},
                  {"center": [-0.04, 0.04, 0], "half_size": [0.01, 0.03, 0.01]}], "rest_height": 0.01,
        "symmetry": {"generators": []},
        "colors": {"black": [0.08, 0.08, 0.08], "pink": [0.9, 0.5, 0.6], "silver": [0.75, 0.75, 0.78]}})"}};
  for (const auto& [name, text] : clutter) {
    writeOutputFile(root / "data" / "objects" / (name + ".json"), std::string(text) + "\n");
  }
  return root;
}

}  // namespace

CollectResult collectTrainingData(const CollectOptions& options,
                                  const std::function<void(const CollectProgress&)>& progress) {
  const auto started = std::chrono::steady_clock::now();
  const auto report = [&progress](const CollectProgress& event) {
    if (progress) {
      progress(event);
    }
  };
  CollectResult result;
  result.dataset = options.out;
  fs::create_directories(options.out);
  const workcell::CellSimulation cell = workcell::cellSimulation(options.workcell);
  const std::shared_ptr<const arm::Kinematics> kinematics = arm::makeKinematics(cell.robot);
  const perception::PipelineFiles files = perception::PipelineFiles::under();
  const std::vector<perception::ObjectModel> models =
      perception::loadObjectModels(files.objects_dir, files.classes_file);
  std::mt19937_64 random(options.seed);
  perception::PipelineOptions pipeline;
  perception::TrainingSet dataset;
  dataset.names[0] = "background";
  for (const auto& model : models) {
    dataset.names[model.parameters.svm_label] = model.name();
  }
  const int total = static_cast<int>(models.size()) * options.scenes_per_class + options.arm_scenes +
                    options.clutter_scenes + options.mixed_scenes;
  std::map<std::string, std::pair<Eigen::AlignedBox3d, int>> bounds_and_label;
  for (const auto& model : models) {
    bounds_and_label[model.name()] = {model.object_class.bounds(), model.parameters.svm_label};
  }

  // 1. The workspace centre from the ArUco marker on the clear table.
  report({1, "", 0, total});
  sim::Scene empty;
  empty.label = "clear table";
  empty.regions = sim::defaultRegions();
  camera::RgbdFrame clear;
  {
    auto simulation = sim::Simulation::create(empty, cell.options);
    clear = perception::medianFrame(captureFrames(*simulation, options.frames, options.seed));
  }
  const std::optional<world::Pose> table_center = perception::locateWorkspaceCenter(clear);
  if (!table_center) {
    throw std::runtime_error("the ArUco marker is not in view: cannot find the workspace centre");
  }
  result.table_center = *table_center;
  result.workspace_file = options.workspace_file.empty() ? options.out / "workspace.json" : options.workspace_file;
  perception::saveTableCenter(result.workspace_file, *table_center,
                              "costar perception collect: ArUco marker DICT_4X4_50 id 0 (10 cm) in the simulated "
                              "workcell, median of " +
                                  std::to_string(options.frames) + " frames");
  pipeline.workspace.table_center = *table_center;

  // Each placement: frames -> median -> crop -> normals -> features; Euclidean clusters (PCL)
  // are the training examples, labelled by what the placement holds.
  int done = 0;
  const auto addScene = [&](sim::Simulation& simulation, const std::string& what, int step, int label,
                            std::uint64_t seed, bool add_table) {
    const camera::RgbdFrame median = perception::medianFrame(captureFrames(simulation, options.frames, seed));
    const perception::ExamplesAdded added =
        perception::addTrainingExamples(median, pipeline, label, add_table, dataset);
    report({step, what, ++done, total, added.examples, added.voxels});
  };

  // 2. Positive examples: placements of one class only, well apart.
  report({2, "", done, total});
  for (const auto& model : models) {
    for (int s = 0; s < options.scenes_per_class; ++s) {
      sim::Scene scene;
      scene.label = model.name() + " scene";
      scene.regions = sim::defaultRegions();
      scene.min_gap = 0.04;
      sim::PartRequest request;
      request.object_class = model.name();
      request.count = options.parts_per_scene;
      request.region = "table";
      scene.parts.push_back(request);
      sim::SimulationOptions sim_options = cell.options;
      sim_options.placement_seed = random();
      auto simulation = sim::Simulation::create(scene, sim_options);
      addScene(*simulation, model.name() + " scene " + std::to_string(s + 1), 2, model.parameters.svm_label, random(),
               false);
    }
  }
  // 3. Negative examples: the robot and gripper over the table (the table itself with every
  // 4th), clutter.
  report({3, "", done, total});
  for (int s = 0; s < options.arm_scenes; ++s) {
    sim::SimulationOptions sim_options = cell.options;
    sim_options.settle_seconds = 0.05;
    const std::unique_ptr<sim::Simulation> simulation =
        armOverTableSimulation(cell, *kinematics, empty, sim_options, 0.06, random);
    if (simulation) {
      simulation->stepTo(simulation->time() + std::chrono::milliseconds(600));  // the fingers
      addScene(*simulation, "robot over the table " + std::to_string(s + 1), 3, 0, random(), s % 4 == 0);
    }
  }
  const fs::path clutter_root = makeClutterRoot(options.out);
  for (int s = 0; s < options.clutter_scenes; ++s) {
    sim::Scene scene;
    scene.label = "clutter scene";
    scene.regions = sim::defaultRegions();
    scene.min_gap = 0.04;
    for (const char* name : {"plate", "tower", "ell"}) {
      sim::PartRequest request;
      request.object_class = name;
      request.count = 2;
      request.region = "table";
      scene.parts.push_back(request);
    }
    sim::SimulationOptions sim_options = cell.options;
    sim_options.data_root = clutter_root;
    sim_options.placement_seed = random();
    auto simulation = sim::Simulation::create(scene, sim_options);
    addScene(*simulation, "clutter scene " + std::to_string(s + 1), 3, 0, random(), false);
  }
  // 4. Both at once, labelled point by point from the simulator's truth: cluttered parts, some
  // touching, links lying across nodes, the arm over them (hiding some of them in part, its
  // gripper among them).
  report({4, "", done, total});
  std::vector<world::ObjectClass> classes;
  for (const auto& model : models) {
    classes.push_back(model.object_class);
  }
  for (int s = 0; s < options.mixed_scenes; ++s) {
    std::uniform_int_distribution<int> nodes(3, 6);
    std::uniform_int_distribution<int> links(1, 3);
    std::vector<std::pair<std::string, int>> counts;
    for (const auto& object_class : classes) {
      counts.emplace_back(object_class.name, object_class.name == "link" ? links(random) : nodes(random));
    }
    const std::string label = "mixed scene " + std::to_string(s + 1);
    sim::Scene scene = sim::clutteredScene(classes, counts, 0.4, random, label).scene;
    stackLinksOnNodes(scene, classes, 1 + s % 2, random);
    sim::SimulationOptions sim_options = cell.options;
    sim_options.settle_seconds = 0.5;
    const std::unique_ptr<sim::Simulation> simulation =
        armOverTableSimulation(cell, *kinematics, scene, sim_options, 0.1, random);
    if (!simulation) {
      continue;
    }
    simulation->stepTo(simulation->time() + std::chrono::milliseconds(600));  // the fingers
    const camera::RgbdFrame median = perception::medianFrame(captureFrames(*simulation, options.frames, random()));
    const std::vector<sim::PartState> parts = simulation->parts();
    const perception::ExamplesAdded added = perception::addLabelledExamples(
        median, pipeline,
        [&parts, &bounds_and_label](const Eigen::Vector3d& point) {
          return truthLabel(point, parts, bounds_and_label);
        },
        dataset);
    report({4, label, ++done, total, added.examples, added.voxels});
  }
  perception::saveTrainingSet(dataset, options.out);
  result.names = dataset.names;
  for (const auto& [label, name] : dataset.names) {
    result.voxels[label] = static_cast<long>(std::count(dataset.labels.begin(), dataset.labels.end(), label));
  }
  result.rows = static_cast<long>(dataset.labels.size());
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return result;
}

}  // namespace costar::trials
