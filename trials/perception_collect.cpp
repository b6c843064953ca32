#include "trials/perception_collect.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <optional>
#include <random>
#include <stdexcept>
#include <utility>
#include <vector>

#include "core/files.h"
#include "core/paths.h"
#include "perception/aruco_marker.h"
#include "perception/median_filter.h"
#include "perception/object_model.h"
#include "perception/pipeline.h"
#include "perception/training_data.h"
#include "perception/workspace.h"
#include "sim/simulation.h"

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

/// Random joint configurations of the UR5 that may put the gripper over the table.
sim::ArmJoints armOverTable(std::mt19937_64& random) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  sim::ArmJoints q = sim::ArmJoints::zero(6);
  q[0] = -0.9 + 1.8 * unit(random);
  q[1] = -2.3 + 1.3 * unit(random);
  q[2] = 0.6 + 1.6 * unit(random);
  q[3] = -M_PI + 2 * M_PI * unit(random);
  q[4] = -M_PI + 2 * M_PI * unit(random);
  q[5] = -M_PI + 2 * M_PI * unit(random);
  return q;
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
  const int total =
      static_cast<int>(models.size()) * options.scenes_per_class + options.arm_scenes + options.clutter_scenes;

  // 1. The workspace centre from the ArUco marker on the clear table.
  report({1, "", 0, total});
  sim::Scene empty;
  empty.label = "clear table";
  empty.regions = sim::defaultRegions();
  camera::RgbdFrame clear;
  {
    auto simulation = sim::Simulation::create(empty);
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
      sim::SimulationOptions sim_options;
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
    std::unique_ptr<sim::Simulation> simulation;
    for (int attempt = 0; attempt < 50 && !simulation; ++attempt) {
      sim::SimulationOptions sim_options;
      sim_options.initial_arm = armOverTable(random);
      sim_options.settle_seconds = 0.05;
      auto candidate = sim::Simulation::create(empty, sim_options);
      const Eigen::Vector3d tcp = candidate->tcpPose().translation();
      if (tcp.x() > 0.25 && tcp.x() < 0.75 && std::abs(tcp.y()) < 0.4 && tcp.z() > 0.06 && tcp.z() < 0.3 &&
          candidate->armTableContactSteps() == 0) {
        simulation = std::move(candidate);
      }
    }
    if (simulation) {
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
    sim::SimulationOptions sim_options;
    sim_options.data_root = clutter_root;
    sim_options.placement_seed = random();
    auto simulation = sim::Simulation::create(scene, sim_options);
    addScene(*simulation, "clutter scene " + std::to_string(s + 1), 3, 0, random(), false);
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
