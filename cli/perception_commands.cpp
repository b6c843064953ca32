#include "cli/perception_commands.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "core/clock.h"
#include "core/image.h"
#include "core/paths.h"
#include "perception/aruco_marker.h"
#include "perception/canonical_orientation.h"
#include "perception/clustering.h"
#include "perception/drawing.h"
#include "perception/features.h"
#include "perception/median_filter.h"
#include "perception/perception_component.h"
#include "perception/pipeline.h"
#include "perception/svm_classifier.h"
#include "perception/training_data.h"
#include "perception/workspace.h"
#include "sim/drivers.h"
#include "sim/simulation.h"

namespace costar::cli {

namespace {

namespace fs = std::filesystem;
using perception::Cloud;

constexpr int kExitSuccess = 0;
constexpr int kExitBelowFloor = 1;
constexpr int kExitError = 2;

double millis(double seconds) { return seconds * 1000.0; }

/// Percentile (0..100) of `values` by linear interpolation; 0 for none.
double percentile(std::vector<double> values, double p) {
  if (values.empty()) {
    return 0.0;
  }
  std::sort(values.begin(), values.end());
  const double at = p / 100.0 * static_cast<double>(values.size() - 1);
  const auto low = static_cast<std::size_t>(std::floor(at));
  const std::size_t high = std::min(values.size() - 1, low + 1);
  return values[low] + (values[high] - values[low]) * (at - static_cast<double>(low));
}

double round3(double value) { return std::round(value * 1000.0) / 1000.0; }

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

// ---------------------------------------------------------------------------------------------
// Scenes for collection and evaluation.

struct Footprint {
  Eigen::Vector2d center;
  double yaw = 0.0;
  Eigen::Vector2d half;  // half sizes along the part's x and y
};

Footprint footprintOf(const world::ObjectClass& object_class, double x, double y, double yaw) {
  const Eigen::AlignedBox3d bounds = object_class.bounds();
  return {{x, y}, yaw, bounds.sizes().head<2>() / 2.0};
}

/// Separating-axis test: true when the rectangles, each grown by `margin`, overlap.
bool overlaps(const Footprint& a, const Footprint& b, double margin) {
  const auto axes = [](const Footprint& f) {
    return std::array<Eigen::Vector2d, 2>{Eigen::Vector2d(std::cos(f.yaw), std::sin(f.yaw)),
                                          Eigen::Vector2d(-std::sin(f.yaw), std::cos(f.yaw))};
  };
  const auto a_axes = axes(a);
  const auto b_axes = axes(b);
  const auto extent = [](const Footprint& f, const std::array<Eigen::Vector2d, 2>& f_axes,
                         const Eigen::Vector2d& axis) {
    return f.half.x() * std::abs(f_axes[0].dot(axis)) + f.half.y() * std::abs(f_axes[1].dot(axis));
  };
  for (const auto& axis : {a_axes[0], a_axes[1], b_axes[0], b_axes[1]}) {
    const double distance = std::abs((a.center - b.center).dot(axis));
    if (distance > extent(a, a_axes, axis) + extent(b, b_axes, axis) + 2 * margin) {
      return false;
    }
  }
  return true;
}

const world::ObjectClass& findClass(const std::vector<world::ObjectClass>& classes, const std::string& name) {
  for (const auto& object_class : classes) {
    if (object_class.name == name) {
      return object_class;
    }
  }
  throw std::runtime_error("unknown object class '" + name + "'");
}

/// A random cluttered scene: `counts` parts per class in x [0.3, 0.7], y [-0.4, 0.4], any yaw;
/// with probability `touching`, a part is placed against an already placed one (touching,
/// 1 mm apart before the physics settles them), else at least 1 cm from every other.
struct GeneratedScene {
  sim::Scene scene;
  int touching_pairs = 0;
};

GeneratedScene clutteredScene(const std::vector<world::ObjectClass>& classes,
                              const std::vector<std::pair<std::string, int>>& counts, double touching,
                              std::mt19937_64& random, const std::string& label) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  GeneratedScene out;
  out.scene.label = label;
  out.scene.min_gap = 0.0;
  std::vector<Footprint> placed;
  std::vector<std::string> order;
  for (const auto& [name, count] : counts) {
    for (int i = 0; i < count; ++i) {
      order.push_back(name);
    }
  }
  std::shuffle(order.begin(), order.end(), random);
  for (const std::string& name : order) {
    const world::ObjectClass& object_class = findClass(classes, name);
    bool done = false;
    for (int attempt = 0; attempt < 400 && !done; ++attempt) {
      Footprint candidate;
      bool touches = false;
      if (!placed.empty() && unit(random) < touching && attempt < 200) {
        // Against a side of an earlier part, turned like it give or take 12 degrees.
        const Footprint& other = placed[static_cast<std::size_t>(unit(random) * placed.size()) % placed.size()];
        const double yaw = other.yaw + (unit(random) < 0.5 ? 0.0 : M_PI / 2) + (unit(random) - 0.5) * 0.42;
        candidate = footprintOf(object_class, 0, 0, yaw);
        const double side_angle = other.yaw + std::floor(unit(random) * 4.0) * M_PI / 2;
        const Eigen::Vector2d normal(std::cos(side_angle), std::sin(side_angle));
        const Eigen::Vector2d tangent(-normal.y(), normal.x());
        const auto support = [&normal](const Footprint& f) {
          const Eigen::Vector2d x_axis(std::cos(f.yaw), std::sin(f.yaw));
          const Eigen::Vector2d y_axis(-x_axis.y(), x_axis.x());
          return f.half.x() * std::abs(x_axis.dot(normal)) + f.half.y() * std::abs(y_axis.dot(normal));
        };
        const Eigen::Vector2d other_x(std::cos(other.yaw), std::sin(other.yaw));
        const double side_half = std::abs(other_x.dot(tangent)) > 0.5 ? other.half.x() : other.half.y();
        const double slide = (unit(random) - 0.5) * 1.2 * side_half;
        candidate.center = other.center + normal * (support(other) + support(candidate) + 0.001) + tangent * slide;
        touches = true;
      } else {
        candidate =
            footprintOf(object_class, 0.3 + 0.4 * unit(random), -0.4 + 0.8 * unit(random), 2 * M_PI * unit(random));
      }
      if (candidate.center.x() < 0.3 || candidate.center.x() > 0.7 || std::abs(candidate.center.y()) > 0.4) {
        continue;
      }
      bool free = true;
      for (const Footprint& other : placed) {
        // Touching parts may meet their neighbour, nothing else.
        if (overlaps(candidate, other, touches ? -0.0002 : 0.005)) {
          free = false;
          break;
        }
      }
      if (!free) {
        continue;
      }
      placed.push_back(candidate);
      sim::PartRequest request;
      request.object_class = name;
      request.at = Eigen::Vector3d(candidate.center.x(), candidate.center.y(), candidate.yaw * 180.0 / M_PI);
      out.scene.parts.push_back(request);
      out.touching_pairs += touches ? 1 : 0;
      done = true;
    }
  }
  return out;
}

// ---------------------------------------------------------------------------------------------
// marker

struct MarkerOptions {
  int id = 0;
  int cell_pixels = 40;
  std::string out;
};

int writeMarker(const MarkerOptions& options) {
  try {
    const RgbImage image = perception::arucoMarkerImage(options.id, options.cell_pixels, 1);
    writePng(options.out, image);
    std::printf("wrote %s: ArUco DICT_4X4_50 id %d, %dx%d pixels (marker 6 x 6 cells of %d px, 1 white cell around)\n",
                options.out.c_str(), options.id, image.width, image.height, options.cell_pixels);
    return kExitSuccess;
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return kExitError;
  }
}

// ---------------------------------------------------------------------------------------------
// collect

struct CollectOptions {
  std::string out = "perception_dataset";
  std::string workspace_file;
  int scenes_per_class = 30;
  int parts_per_scene = 6;
  int arm_scenes = 24;
  int clutter_scenes = 12;
  int frames = 9;
  std::uint64_t seed = 1;
};

/// Random joint configurations that put the gripper over the table in the camera's view.
std::optional<sim::ArmJoints> armOverTable(std::mt19937_64& random) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  sim::ArmJoints q{};
  q[0] = -0.9 + 1.8 * unit(random);
  q[1] = -2.3 + 1.3 * unit(random);
  q[2] = 0.6 + 1.6 * unit(random);
  q[3] = -M_PI + 2 * M_PI * unit(random);
  q[4] = -M_PI + 2 * M_PI * unit(random);
  q[5] = -M_PI + 2 * M_PI * unit(random);
  return q;
}

/// Clutter: object classes that are neither nodes nor links (negative examples), written to
/// a temporary data root next to the real sim/models.
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
    std::ofstream(root / "data" / "objects" / (name + ".json")) << text << "\n";
  }
  return root;
}

int collect(const CollectOptions& options) {
  try {
    const auto started = std::chrono::steady_clock::now();
    const fs::path out = options.out;
    fs::create_directories(out);
    const perception::PipelineFiles files = perception::PipelineFiles::under();
    const std::vector<perception::ObjectModel> models =
        perception::loadObjectModels(files.objects_dir, files.classes_file);
    std::vector<world::ObjectClass> classes;
    for (const auto& model : models) {
      classes.push_back(model.object_class);
    }
    std::mt19937_64 random(options.seed);
    perception::PipelineOptions pipeline;
    perception::TrainingSet dataset;
    dataset.names[0] = "background";
    for (const auto& model : models) {
      dataset.names[model.parameters.svm_label] = model.name();
    }

    // 1. The workspace centre from the ArUco marker on the clear table.
    std::printf("collect: 1. finding the workspace centre (ArUco marker DICT_4X4_50 id 0, 10 cm) on a clear table\n");
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
      std::cerr << "error: the ArUco marker is not in view: cannot find the workspace centre\n";
      return kExitError;
    }
    const Eigen::Vector3d rpy = world::rpyOf(table_center->linear()) * 180.0 / M_PI;
    std::printf("   table_center at (%.4f, %.4f, %.4f) m, roll/pitch/yaw (%.2f, %.2f, %.2f) deg\n",
                table_center->translation().x(), table_center->translation().y(), table_center->translation().z(),
                rpy.x(), rpy.y(), rpy.z());
    const fs::path workspace_file =
        options.workspace_file.empty() ? out / "workspace.json" : fs::path(options.workspace_file);
    perception::saveTableCenter(workspace_file, *table_center,
                                "costar perception collect: ArUco marker DICT_4X4_50 id 0 (10 cm) in the simulated "
                                "workcell, median of " +
                                    std::to_string(options.frames) + " frames");
    std::printf("   wrote %s\n", workspace_file.string().c_str());
    pipeline.workspace.table_center = *table_center;

    // Each scene: frames -> median -> crop -> normals -> features; Euclidean clusters (PCL)
    // are the training examples, labelled by what the scene was set up to hold.
    const auto addScene = [&](sim::Simulation& sim, int label, std::uint64_t seed, bool add_table) {
      const auto scene_frames = captureFrames(sim, options.frames, seed);
      const camera::RgbdFrame median = perception::medianFrame(scene_frames);
      return perception::addTrainingExamples(median, pipeline, label, add_table, dataset);
    };
    const int total =
        static_cast<int>(models.size()) * options.scenes_per_class + options.arm_scenes + options.clutter_scenes;
    int done = 0;
    const auto progress = [&](const std::string& what, const perception::ExamplesAdded& added) {
      ++done;
      std::printf("  [%3d/%3d] %-34s %2d example(s), %5d voxels\n", done, total, what.c_str(), added.examples,
                  added.voxels);
      std::fflush(stdout);
    };

    // 2. Positive examples: scenes holding parts of one class only.
    std::printf("collect: 2. positive examples: %d scenes per class, %d parts each, well apart\n",
                options.scenes_per_class, options.parts_per_scene);
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
        auto sim = sim::Simulation::create(scene, sim_options);
        progress(model.name() + " scene " + std::to_string(s + 1),
                 addScene(*sim, model.parameters.svm_label, random(), false));
      }
    }
    // 3. Negative examples: the robot and gripper over the table, the table itself, clutter.
    std::printf("collect: 3. negative examples: robot and gripper over the table (%d), clutter (%d), table\n",
                options.arm_scenes, options.clutter_scenes);
    for (int s = 0; s < options.arm_scenes; ++s) {
      std::unique_ptr<sim::Simulation> sim;
      for (int attempt = 0; attempt < 50; ++attempt) {
        sim::SimulationOptions sim_options;
        sim_options.initial_arm = armOverTable(random);
        sim_options.settle_seconds = 0.05;
        auto candidate = sim::Simulation::create(empty, sim_options);
        const Eigen::Vector3d tcp = candidate->tcpPose().translation();
        if (tcp.x() > 0.25 && tcp.x() < 0.75 && std::abs(tcp.y()) < 0.4 && tcp.z() > 0.06 && tcp.z() < 0.3 &&
            candidate->armTableContactSteps() == 0) {
          sim = std::move(candidate);
          break;
        }
      }
      if (!sim) {
        continue;
      }
      progress("robot over the table " + std::to_string(s + 1), addScene(*sim, 0, random(), s % 4 == 0));
    }
    const fs::path clutter_root = makeClutterRoot(out);
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
      auto sim = sim::Simulation::create(scene, sim_options);
      progress("clutter scene " + std::to_string(s + 1), addScene(*sim, 0, random(), false));
    }
    perception::saveTrainingSet(dataset, out);
    std::printf("collect: wrote %s (%zu examples of %d features) in %.0f s\n", out.string().c_str(),
                dataset.labels.size(), perception::kFeatureCount,
                std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count());
    for (const auto& [label, name] : dataset.names) {
      std::printf("   %-10s (label %d): %6ld voxels\n", name.c_str(), label,
                  static_cast<long>(std::count(dataset.labels.begin(), dataset.labels.end(), label)));
    }
    std::printf("next: costar perception train --dataset %s\n", out.string().c_str());
    return kExitSuccess;
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return kExitError;
  }
}

// ---------------------------------------------------------------------------------------------
// train

struct TrainOptions {
  std::string dataset = "perception_dataset";
  std::string out;
  perception::SvmTrainingOptions svm;
};

int train(const TrainOptions& options) {
  try {
    const perception::TrainingSet dataset = perception::loadTrainingSet(options.dataset);
    std::printf("train: %zu examples from %s\n", dataset.labels.size(), options.dataset.c_str());
    perception::SvmTrainingReport report;
    const auto classifier = perception::SvmClassifier::train(dataset.features, dataset.labels, dataset.names,
                                                             options.svm, &report, [](const std::string& step) {
                                                               std::printf("train: %s ...\n", step.c_str());
                                                               std::fflush(stdout);
                                                             });
    const fs::path out = options.out.empty() ? perception::PipelineFiles::under().svm_file : fs::path(options.out);
    classifier.save(out);
    std::printf("train: %d support vectors, C = %g, gamma = %s, %.1f s\n", report.support_vectors, options.svm.cost,
                options.svm.gamma > 0 ? std::to_string(options.svm.gamma).c_str() : "1/features", report.seconds);
    if (report.folds >= 2) {
      std::printf("cross-validated accuracy (%d folds, per label: examples used, correct):\n", report.folds);
      for (const auto& [label, entry] : report.labels) {
        std::printf("   %-10s %5d  %6.2f %%\n", entry.name.c_str(), entry.examples, 100.0 * entry.accuracy());
      }
      std::printf("   %-10s        %6.2f %%\n", "overall", 100.0 * report.overall_accuracy);
    }
    std::printf("train: wrote %s\n", out.string().c_str());
    return kExitSuccess;
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return kExitError;
  }
}

// ---------------------------------------------------------------------------------------------
// eval

struct EvalOptions {
  int scenes = 10;
  std::uint64_t seed = 1;
  std::string json;
  std::string out;
  int repeats = 10;
  int pushes = 2;
  int frames = 15;
  int long_run = 0;
  double min_found = -1.0;
  double touching = 0.4;
};

/// A camera whose simulation can be swapped (a push recreates the scene).
class SwitchableCamera final : public camera::RgbdCamera {
 public:
  void use(sim::Simulation& simulation, std::uint64_t seed) {
    camera_ = std::make_unique<sim::SimRgbdCamera>(simulation, seed);
  }
  std::string name() const override { return camera_->name(); }
  const camera::Intrinsics& intrinsics() const override { return camera_->intrinsics(); }
  Duration framePeriod() const override { return camera_->framePeriod(); }
  camera::RgbdFrame capture() override { return camera_->capture(); }
  camera::RgbdFrame captureDepth() override { return camera_->captureDepth(); }

 private:
  std::unique_ptr<sim::SimRgbdCamera> camera_;
};

/// A clock that reads the current simulation's SimClock.
class SwitchableClock final : public Clock {
 public:
  void use(SimClock& clock) { clock_ = &clock; }
  TimePoint now() const override { return clock_->now(); }
  void sleepUntil(TimePoint t) override { clock_->sleepUntil(t); }
  bool simulated() const override { return true; }

 private:
  SimClock* clock_ = nullptr;
};

struct PartTruth {
  sim::PartState state;
  double visible_fraction = 0.0;
};

/// How much of each part's camera-facing surface the filtered depth image shows.
std::vector<PartTruth> truthWithVisibility(const sim::Simulation& simulation, const camera::RgbdFrame& frame,
                                           const perception::Pipeline& pipeline) {
  std::vector<PartTruth> out;
  for (const sim::PartState& part : simulation.parts()) {
    PartTruth truth{part, 0.0};
    if (const perception::ObjectModel* model = pipeline.model(part.object_class)) {
      const perception::DepthAgreement agreement =
          perception::compareWithDepth(*model, frame.camera_pose.inverse() * part.pose, frame, 0.008);
      truth.visible_fraction = agreement.visibleFraction();
    }
    out.push_back(truth);
  }
  return out;
}

struct RoundMatch {
  std::vector<int> detection_of_part;  // -1: missed
  std::vector<int> part_of_detection;  // -1: false positive
  std::vector<double> translation_error;
  std::vector<double> rotation_error;
};

/// One-to-one matching of detections to true parts: same class, centres within 2.5 cm,
/// closest pairs first.
RoundMatch matchToTruth(const std::vector<perception::TrackedObject>& objects, const std::vector<PartTruth>& truth,
                        const perception::Pipeline& pipeline) {
  RoundMatch match;
  match.detection_of_part.assign(truth.size(), -1);
  match.part_of_detection.assign(objects.size(), -1);
  match.translation_error.assign(truth.size(), 0.0);
  match.rotation_error.assign(truth.size(), 0.0);
  std::vector<std::tuple<double, int, int>> pairs;
  for (std::size_t d = 0; d < objects.size(); ++d) {
    for (std::size_t p = 0; p < truth.size(); ++p) {
      if (objects[d].object_class != truth[p].state.object_class) {
        continue;
      }
      const double distance = (objects[d].pose.translation() - truth[p].state.pose.translation()).norm();
      if (distance < 0.025) {
        pairs.emplace_back(distance, static_cast<int>(d), static_cast<int>(p));
      }
    }
  }
  std::sort(pairs.begin(), pairs.end());
  for (const auto& [distance, d, p] : pairs) {
    if (match.part_of_detection[static_cast<std::size_t>(d)] >= 0 ||
        match.detection_of_part[static_cast<std::size_t>(p)] >= 0) {
      continue;
    }
    match.part_of_detection[static_cast<std::size_t>(d)] = p;
    match.detection_of_part[static_cast<std::size_t>(p)] = d;
    match.translation_error[static_cast<std::size_t>(p)] = distance;
    const perception::ObjectModel* model = pipeline.model(truth[static_cast<std::size_t>(p)].state.object_class);
    match.rotation_error[static_cast<std::size_t>(p)] = perception::symmetricRotationDistance(
        objects[static_cast<std::size_t>(d)].pose.linear(), truth[static_cast<std::size_t>(p)].state.pose.linear(),
        model->object_class);
  }
  return match;
}

struct ClassStats {
  int visible = 0;
  int visible_found = 0;     // matched, any error
  int visible_accurate = 0;  // matched within 5 mm and 5 degrees
  int detections = 0;
  int false_positives = 0;
  std::vector<double> translation_mm;
  std::vector<double> rotation_deg;
};

struct Accumulated {
  std::map<std::string, ClassStats> classes;
  std::vector<std::string> problems;  // lines for the report
  std::map<std::string, std::vector<double>> latency_ms;
  int occluded_parts = 0;
  // persistence
  int repeat_checks = 0;
  int repeat_stable = 0;
  int scenes_all_stable = 0;
  int scenes_with_repeats = 0;
  int push_checks = 0;
  int push_stable = 0;
  int pushed_part_checks = 0;
  int pushed_part_stable = 0;
  int long_run_checks = 0;
  int long_run_stable = 0;
};

constexpr double kTranslationTolerance = 0.005;
constexpr double kRotationTolerance = 5.0 * M_PI / 180.0;

/// Runs DetectObjects on the component, stepping simulated time as the executor would.
/// The objects the latest detection saw (not those only remembered by keep_for): what is scored.
std::vector<perception::TrackedObject> seenObjects(const perception::PerceptionComponent& component) {
  std::vector<perception::TrackedObject> seen = component.objects();
  std::erase_if(seen, [](const perception::TrackedObject& object) { return object.missed > 0; });
  return seen;
}

perception::PipelineResult detectOnce(perception::PerceptionComponent& component, SimClock& clock, int frames) {
  component::ParamMap params;
  params["frames"] = frames;
  const component::OperationId id = component.start("DetectObjects", params);
  for (int tick = 0; tick < 100000; ++tick) {
    const component::OperationResult result = component.poll(id);
    if (result.state == component::OperationState::kSuccess) {
      return *component.lastResult();
    }
    if (result.state == component::OperationState::kFailure) {
      throw std::runtime_error(result.reason);
    }
    clock.advanceBy(std::chrono::milliseconds(10));
  }
  throw std::runtime_error("DetectObjects did not finish");
}

void recordLatency(Accumulated& total, const perception::StageTimes& t) {
  total.latency_ms["median_filter"].push_back(millis(t.median));
  total.latency_ms["crop_plane"].push_back(millis(t.crop));
  total.latency_ms["normals"].push_back(millis(t.normals));
  total.latency_ms["features"].push_back(millis(t.features));
  total.latency_ms["svm"].push_back(millis(t.classification));
  total.latency_ms["pose_wall"].push_back(millis(t.pose));
  total.latency_ms["objrecransac_cpu"].push_back(millis(t.recognition));
  total.latency_ms["icp_check_cpu"].push_back(millis(t.refinement));
  total.latency_ms["total"].push_back(millis(t.total));
}

/// Scores one detection round against the truth; returns the match and appends problems.
RoundMatch scoreRound(const std::vector<perception::TrackedObject>& objects, const std::vector<PartTruth>& truth,
                      const perception::Pipeline& pipeline, Accumulated& total, const std::string& where) {
  const RoundMatch match = matchToTruth(objects, truth, pipeline);
  for (std::size_t p = 0; p < truth.size(); ++p) {
    const std::string& name = truth[p].state.object_class;
    ClassStats& stats = total.classes[name];
    const bool visible = truth[p].visible_fraction >= 0.3;
    if (!visible) {
      ++total.occluded_parts;
      continue;
    }
    ++stats.visible;
    if (match.detection_of_part[p] < 0) {
      char text[200];
      const Eigen::Vector3d at = truth[p].state.pose.translation();
      std::snprintf(text, sizeof text, "%s: missed %s (%s) at (%.3f, %.3f, %.3f), %.0f %% of it in view", where.c_str(),
                    truth[p].state.name.c_str(), name.c_str(), at.x(), at.y(), at.z(),
                    100.0 * truth[p].visible_fraction);
      total.problems.push_back(text);
      continue;
    }
    ++stats.visible_found;
    const double t = match.translation_error[p];
    const double r = match.rotation_error[p];
    stats.translation_mm.push_back(t * 1000.0);
    stats.rotation_deg.push_back(r * 180.0 / M_PI);
    if (t <= kTranslationTolerance && r <= kRotationTolerance) {
      ++stats.visible_accurate;
    } else {
      const Eigen::Vector3d offset = truth[p].state.pose.inverse() *
                                     objects[static_cast<std::size_t>(match.detection_of_part[p])].pose.translation();
      char text[200];
      std::snprintf(text, sizeof text,
                    "%s: %s (%s) found with %.1f mm / %.1f deg error (in its frame: %+.1f %+.1f %+.1f mm)",
                    where.c_str(), truth[p].state.name.c_str(), name.c_str(), t * 1000.0, r * 180.0 / M_PI,
                    offset.x() * 1000.0, offset.y() * 1000.0, offset.z() * 1000.0);
      total.problems.push_back(text);
    }
  }
  for (std::size_t d = 0; d < objects.size(); ++d) {
    ClassStats& stats = total.classes[objects[d].object_class];
    ++stats.detections;
    if (match.part_of_detection[d] < 0) {
      ++stats.false_positives;
      char text[200];
      const Eigen::Vector3d at = objects[d].pose.translation();
      std::snprintf(text, sizeof text, "%s: false detection %s at (%.3f, %.3f, %.3f), confidence %.3f", where.c_str(),
                    objects[d].name.c_str(), at.x(), at.y(), at.z(), objects[d].confidence);
      total.problems.push_back(text);
    }
  }
  return match;
}

/// The picture of a round: detections over the RGB image, green within tolerance, red not,
/// orange a false detection; missed parts' outlines yellow.
RgbImage pictureOf(const camera::RgbdFrame& frame, const std::vector<perception::TrackedObject>& objects,
                   const std::vector<PartTruth>& truth, const RoundMatch& match, const perception::Pipeline& pipeline) {
  RgbImage image = frame.rgb;
  std::vector<perception::Overlay> overlays;
  for (std::size_t d = 0; d < objects.size(); ++d) {
    const perception::ObjectModel* model = pipeline.model(objects[d].object_class);
    perception::Overlay overlay;
    overlay.pose = objects[d].pose;
    overlay.boxes = model->object_class.boxes.size() == 1
                        ? model->object_class.boxes
                        : std::vector<world::Box>{
                              {model->object_class.bounds().center(), model->object_class.bounds().sizes() / 2.0}};
    overlay.label = objects[d].name;
    const int p = match.part_of_detection[d];
    if (p < 0) {
      overlay.color = {255, 140, 0};
    } else if (match.translation_error[static_cast<std::size_t>(p)] <= kTranslationTolerance &&
               match.rotation_error[static_cast<std::size_t>(p)] <= kRotationTolerance) {
      overlay.color = {40, 220, 60};
    } else {
      overlay.color = {230, 30, 30};
    }
    overlay.draw_axes = true;
    overlays.push_back(overlay);
  }
  for (std::size_t p = 0; p < truth.size(); ++p) {
    if (match.detection_of_part[p] >= 0) {
      continue;
    }
    const perception::ObjectModel* model = pipeline.model(truth[p].state.object_class);
    perception::Overlay overlay;
    overlay.pose = truth[p].state.pose;
    overlay.boxes = {{model->object_class.bounds().center(), model->object_class.bounds().sizes() / 2.0}};
    overlay.color = {255, 230, 0};
    overlay.label = "missed " + truth[p].state.name;
    overlays.push_back(overlay);
  }
  // A close-up of where the parts lie (x 0.25..0.75, y -0.45..0.45 m, up to 6 cm high), twice enlarged.
  perception::WorkspaceOptions area;
  area.table_center = world::Pose(Eigen::Translation3d(0.5, 0.0, 0.0));
  area.half_size_x = 0.25;
  area.half_size_y = 0.45;
  area.max_height = 0.06;
  area.plane_search_band = 0.0;
  return perception::drawOverlaysZoomed(image, frame.intrinsics, frame.camera_pose, overlays,
                                        perception::workspaceRegion(frame.intrinsics, frame.camera_pose, area), 2.0);
}

/// The SVM's labels over the image: background dark red, the classes in turn blue, green, ...
RgbImage labelPicture(const perception::PipelineResult& result, const perception::Pipeline& pipeline) {
  RgbImage image = result.filtered->rgb;
  for (auto& value : image.pixels) {
    value = static_cast<std::uint8_t>(value / 3);
  }
  const std::vector<perception::Rgb> colors = {{60, 120, 255}, {60, 230, 60}, {255, 230, 0}, {230, 60, 230}};
  for (std::size_t i = 0; i < result.workspace.size(); ++i) {
    const int label = result.labels[i];
    perception::Rgb color{160, 20, 20};
    for (std::size_t m = 0; m < pipeline.models().size(); ++m) {
      if (pipeline.classifier().labelOf(pipeline.models()[m].name()) == label) {
        color = colors[m % colors.size()];
      }
    }
    const int pixel = result.workspace.pixels[i];
    std::uint8_t* p = &image.pixels[static_cast<std::size_t>(pixel) * 3];
    p[0] = color[0];
    p[1] = color[1];
    p[2] = color[2];
  }
  perception::WorkspaceOptions area;
  area.table_center = world::Pose(Eigen::Translation3d(0.5, 0.0, 0.0));
  area.half_size_x = 0.25;
  area.half_size_y = 0.45;
  area.max_height = 0.06;
  area.plane_search_band = 0.0;
  return perception::drawOverlaysZoomed(
      image, result.filtered->intrinsics, result.filtered->camera_pose, {},
      perception::workspaceRegion(result.filtered->intrinsics, result.filtered->camera_pose, area), 2.0);
}

/// The parts of a simulation as a scene with fixed placements (to re-create it after a push).
sim::Scene sceneOf(const std::vector<sim::PartState>& parts, const std::string& label) {
  sim::Scene scene;
  scene.label = label;
  scene.min_gap = 0.0;
  for (const auto& part : parts) {
    sim::PartRequest request;
    request.object_class = part.object_class;
    request.color = part.color;
    const Eigen::Vector3d rpy = world::rpyOf(part.pose.linear());
    request.at = Eigen::Vector3d(part.pose.translation().x(), part.pose.translation().y(), rpy.z() * 180.0 / M_PI);
    scene.parts.push_back(request);
  }
  return scene;
}

nlohmann::json statsJson(const std::vector<double>& values) {
  return {{"median", round3(percentile(values, 50))},
          {"p95", round3(percentile(values, 95))},
          {"max", round3(values.empty() ? 0.0 : *std::max_element(values.begin(), values.end()))}};
}

int evaluate(const EvalOptions& options) {
  try {
    const auto started = std::chrono::steady_clock::now();
    perception::PerceptionConfig config;
    const auto pipeline = perception::loadPipeline(config);
    config.frames = options.frames;
    std::vector<world::ObjectClass> classes;
    for (const auto& model : pipeline->models()) {
      classes.push_back(model.object_class);
    }
    if (!options.out.empty()) {
      fs::create_directories(options.out);
    }
    std::printf(
        "eval: %d random cluttered scene(s), seed %llu, %d frames per DetectObjects, %d repeat(s), %d push(es)\n",
        options.scenes, static_cast<unsigned long long>(options.seed), options.frames, options.repeats, options.pushes);
    std::mt19937_64 random(options.seed);
    Accumulated total;
    int total_parts = 0;
    int total_touching = 0;
    for (int s = 0; s < options.scenes; ++s) {
      std::uniform_int_distribution<int> nodes(3, 6);
      std::uniform_int_distribution<int> links(1, 3);
      std::vector<std::pair<std::string, int>> counts;
      for (const auto& object_class : classes) {
        counts.emplace_back(object_class.name, object_class.name == "link" ? links(random) : nodes(random));
      }
      const std::string label = "scene " + std::to_string(s + 1);
      GeneratedScene generated = clutteredScene(classes, counts, options.touching, random, label);
      total_touching += generated.touching_pairs;
      SwitchableCamera camera;
      SwitchableClock clock;
      auto sim_clock = std::make_unique<SimClock>();
      auto simulation = sim::Simulation::create(generated.scene);
      simulation->attach(*sim_clock);
      camera.use(*simulation, random());
      clock.use(*sim_clock);
      perception::PerceptionComponent component(camera, clock, pipeline, config);

      // First look.
      perception::PipelineResult result = detectOnce(component, *sim_clock, options.frames);
      recordLatency(total, result.times);
      std::vector<PartTruth> truth = truthWithVisibility(*simulation, *result.filtered, *pipeline);
      total_parts += static_cast<int>(truth.size());
      std::vector<perception::TrackedObject> objects = seenObjects(component);
      RoundMatch first = scoreRound(objects, truth, *pipeline, total, label);
      if (!options.out.empty()) {
        char file[64];
        std::snprintf(file, sizeof file, "scene_%03d.png", s + 1);
        writePng(fs::path(options.out) / file, pictureOf(*result.filtered, objects, truth, first, *pipeline));
        std::snprintf(file, sizeof file, "scene_%03d_labels.png", s + 1);
        writePng(fs::path(options.out) / file, labelPicture(result, *pipeline));
      }
      int accurate = 0;
      for (std::size_t p = 0; p < truth.size(); ++p) {
        accurate += first.detection_of_part[p] >= 0 && first.translation_error[p] <= kTranslationTolerance &&
                    first.rotation_error[p] <= kRotationTolerance;
      }
      // Names of the parts after the first look.
      std::vector<std::string> names(truth.size());
      for (std::size_t p = 0; p < truth.size(); ++p) {
        if (first.detection_of_part[p] >= 0) {
          names[p] = objects[static_cast<std::size_t>(first.detection_of_part[p])].name;
        }
      }
      // Repeats while the parts stay still.
      int stable_here = 0;
      int checks_here = 0;
      const int repeats = options.repeats + (s == 0 ? options.long_run : 0);
      for (int r = 0; r < repeats; ++r) {
        result = detectOnce(component, *sim_clock, options.frames);
        recordLatency(total, result.times);
        objects = seenObjects(component);
        const RoundMatch match =
            scoreRound(objects, truth, *pipeline, total, label + " repeat " + std::to_string(r + 1));
        for (std::size_t p = 0; p < truth.size(); ++p) {
          if (names[p].empty()) {
            continue;
          }
          const bool same = match.detection_of_part[p] >= 0 &&
                            objects[static_cast<std::size_t>(match.detection_of_part[p])].name == names[p];
          ++checks_here;
          stable_here += same ? 1 : 0;
          if (s == 0 && r >= options.repeats) {
            ++total.long_run_checks;
            total.long_run_stable += same ? 1 : 0;
          }
          if (!same) {
            total.problems.push_back(label + " repeat " + std::to_string(r + 1) + ": " + truth[p].state.name +
                                     " lost its name " + names[p]);
          }
        }
      }
      total.repeat_checks += checks_here;
      total.repeat_stable += stable_here;
      if (repeats > 0) {
        ++total.scenes_with_repeats;
        total.scenes_all_stable += stable_here == checks_here ? 1 : 0;
      }
      // Small pushes: one part moved 1-2 cm and turned up to 10 degrees; the others stay.
      int push_ok = 0;
      for (int push = 0; push < options.pushes && !truth.empty(); ++push) {
        std::vector<sim::PartState> parts = simulation->parts();
        std::uniform_int_distribution<std::size_t> which(0, parts.size() - 1);
        std::uniform_real_distribution<double> unit(0.0, 1.0);
        std::size_t pushed = which(random);
        bool placed = false;
        for (int attempt = 0; attempt < 60 && !placed; ++attempt) {
          if (attempt % 10 == 9) {
            pushed = which(random);
          }
          const double distance = 0.01 + 0.01 * unit(random);
          const double direction = 2 * M_PI * unit(random);
          const double turn = (unit(random) - 0.5) * 20.0 * M_PI / 180.0;
          const world::Pose& before = parts[pushed].pose;
          const double yaw = world::rpyOf(before.linear()).z() + turn;
          const double x = before.translation().x() + distance * std::cos(direction);
          const double y = before.translation().y() + distance * std::sin(direction);
          const Footprint moved = footprintOf(findClass(classes, parts[pushed].object_class), x, y, yaw);
          bool free = true;
          for (std::size_t o = 0; o < parts.size() && free; ++o) {
            if (o == pushed) {
              continue;
            }
            const Eigen::Vector3d rpy = world::rpyOf(parts[o].pose.linear());
            free = !overlaps(moved,
                             footprintOf(findClass(classes, parts[o].object_class), parts[o].pose.translation().x(),
                                         parts[o].pose.translation().y(), rpy.z()),
                             0.0005);
          }
          if (free) {
            parts[pushed].pose = world::poseFromXyzRpy(x, y, parts[pushed].pose.translation().z(), 0, 0, yaw);
            placed = true;
          }
        }
        if (!placed) {
          continue;
        }
        const std::string where = label + " push " + std::to_string(push + 1);
        // One simulation at a time (destroying one ends the EGL display all renderers share).
        simulation.reset();
        sim_clock = std::make_unique<SimClock>();
        simulation = sim::Simulation::create(sceneOf(parts, where));
        simulation->attach(*sim_clock);
        camera.use(*simulation, random());
        clock.use(*sim_clock);
        result = detectOnce(component, *sim_clock, options.frames);
        recordLatency(total, result.times);
        // The re-created scene names its parts in the same order.
        truth = truthWithVisibility(*simulation, *result.filtered, *pipeline);
        objects = seenObjects(component);
        const RoundMatch match = scoreRound(objects, truth, *pipeline, total, where);
        bool all_same = true;
        for (std::size_t p = 0; p < truth.size(); ++p) {
          if (names[p].empty()) {
            continue;
          }
          const bool same = match.detection_of_part[p] >= 0 &&
                            objects[static_cast<std::size_t>(match.detection_of_part[p])].name == names[p];
          ++total.push_checks;
          total.push_stable += same ? 1 : 0;
          if (p == pushed) {
            ++total.pushed_part_checks;
            total.pushed_part_stable += same ? 1 : 0;
          }
          if (!same) {
            all_same = false;
            total.problems.push_back(where + ": " + truth[p].state.name + (p == pushed ? " (pushed)" : "") +
                                     " lost its name " + names[p]);
          }
        }
        push_ok += all_same ? 1 : 0;
      }
      std::printf(
          "  scene %2d/%d: %zu parts (%d placed touching), first look %d/%zu within 5 mm and 5 deg, "
          "identities %d/%d stable over %d repeats, %d/%d pushes kept every name, %.0f ms\n",
          s + 1, options.scenes, truth.size(), generated.touching_pairs, accurate, truth.size(), stable_here,
          checks_here, repeats, push_ok, options.pushes, millis(result.times.total));
      std::fflush(stdout);
    }

    // Summary.
    nlohmann::json summary;
    summary["command"] = "costar perception eval --scenes " + std::to_string(options.scenes) + " --seed " +
                         std::to_string(options.seed) + " --repeats " + std::to_string(options.repeats) + " --pushes " +
                         std::to_string(options.pushes) + " --frames " + std::to_string(options.frames);
    summary["scenes"] = options.scenes;
    summary["parts"] = total_parts;
    summary["parts_placed_touching"] = total_touching;
    summary["tolerance"] = {{"translation_mm", 5.0}, {"rotation_deg", 5.0}};
    int visible = 0;
    int accurate = 0;
    std::printf(
        "\nper class (every DetectObjects of every scene; parts with >= 30 %% of their facing surface in view):\n");
    std::printf("  %-6s %8s %9s %7s %10s %12s %12s %12s %12s\n", "class", "visible", "precision", "recall",
                "within tol", "t med (mm)", "t p95 (mm)", "r med (deg)", "r p95 (deg)");
    for (const auto& [name, stats] : total.classes) {
      const double precision = stats.detections == 0
                                   ? 1.0
                                   : static_cast<double>(stats.detections - stats.false_positives) / stats.detections;
      const double recall = stats.visible == 0 ? 1.0 : static_cast<double>(stats.visible_found) / stats.visible;
      const double within = stats.visible == 0 ? 1.0 : static_cast<double>(stats.visible_accurate) / stats.visible;
      visible += stats.visible;
      accurate += stats.visible_accurate;
      std::printf("  %-6s %8d %9.4f %7.4f %10.4f %12.2f %12.2f %12.2f %12.2f\n", name.c_str(), stats.visible, precision,
                  recall, within, percentile(stats.translation_mm, 50), percentile(stats.translation_mm, 95),
                  percentile(stats.rotation_deg, 50), percentile(stats.rotation_deg, 95));
      summary["classes"][name] = {{"visible", stats.visible},
                                  {"detections", stats.detections},
                                  {"false_positives", stats.false_positives},
                                  {"precision", round3(precision)},
                                  {"recall", round3(recall)},
                                  {"found_within_tolerance", round3(within)},
                                  {"translation_error_mm", statsJson(stats.translation_mm)},
                                  {"rotation_error_deg", statsJson(stats.rotation_deg)}};
    }
    const double found = visible == 0 ? 1.0 : static_cast<double>(accurate) / visible;
    std::printf(
        "  all    %8d parts seen, %.2f %% found within 5 mm and 5 deg (target >= 99 %%); %d part views "
        "mostly hidden, not counted\n",
        visible, 100.0 * found, total.occluded_parts);
    summary["found_within_tolerance"] = round3(found);
    summary["visible_part_views"] = visible;
    summary["hidden_part_views"] = total.occluded_parts;
    const auto fraction = [](int good, int all) { return all == 0 ? 1.0 : static_cast<double>(good) / all; };
    std::printf("\npersistence:\n");
    std::printf("  parts still: %d of %d name checks kept the name (%.2f %%); %d of %d scenes kept every name\n",
                total.repeat_stable, total.repeat_checks, 100.0 * fraction(total.repeat_stable, total.repeat_checks),
                total.scenes_all_stable, total.scenes_with_repeats);
    if (total.long_run_checks > 0) {
      std::printf("  long run (scene 1, %d more repeats): %d of %d name checks kept the name\n", options.long_run,
                  total.long_run_stable, total.long_run_checks);
    }
    std::printf("  after pushes of 1-2 cm / up to 10 deg: %d of %d names kept (pushed parts: %d of %d)\n",
                total.push_stable, total.push_checks, total.pushed_part_stable, total.pushed_part_checks);
    summary["persistence"] = {
        {"repeats_per_scene", options.repeats},
        {"still_name_checks", total.repeat_checks},
        {"still_names_kept", round3(fraction(total.repeat_stable, total.repeat_checks))},
        {"scenes_all_names_kept", total.scenes_all_stable},
        {"long_run_repeats", options.long_run},
        {"long_run_names_kept", round3(fraction(total.long_run_stable, total.long_run_checks))},
        {"push_name_checks", total.push_checks},
        {"push_names_kept", round3(fraction(total.push_stable, total.push_checks))},
        {"pushed_parts_names_kept", round3(fraction(total.pushed_part_stable, total.pushed_part_checks))}};
    std::printf("\nlatency per DetectObjects (%zu runs; frame capture not included; median / p95 ms):\n",
                total.latency_ms["total"].size());
    for (const char* stage : {"median_filter", "crop_plane", "normals", "features", "svm", "pose_wall",
                              "objrecransac_cpu", "icp_check_cpu", "total"}) {
      const auto& values = total.latency_ms[stage];
      std::printf("  %-18s %8.1f %8.1f\n", stage, percentile(values, 50), percentile(values, 95));
      summary["latency_ms"][stage] = {{"median", round3(percentile(values, 50))},
                                      {"p95", round3(percentile(values, 95))}};
    }
    if (!total.problems.empty()) {
      std::printf("\nproblems (%zu):\n", total.problems.size());
      for (std::size_t i = 0; i < total.problems.size() && i < 40; ++i) {
        std::printf("  %s\n", total.problems[i].c_str());
      }
      if (total.problems.size() > 40) {
        std::printf("  ... and %zu more\n", total.problems.size() - 40);
      }
    }
    summary["problems"] = total.problems;
    summary["seconds"] = round3(std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count());
    if (!options.json.empty()) {
      std::ofstream(options.json) << summary.dump(2) << "\n";
      std::printf("\nwrote %s\n", options.json.c_str());
    }
    if (!options.out.empty()) {
      std::printf("pictures in %s (green: within 5 mm / 5 deg, red: not, orange: false detection, yellow: missed)\n",
                  options.out.c_str());
    }
    if (options.min_found >= 0 && found < options.min_found) {
      std::printf("FAIL: %.4f of the visible parts found within tolerance, below the floor %.4f\n", found,
                  options.min_found);
      return kExitBelowFloor;
    }
    return kExitSuccess;
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return kExitError;
  }
}

struct DetectOptions {
  std::string scene;
  std::optional<std::uint64_t> seed;
  std::string out;
  int frames = 15;
};

/// DetectObjects once on a scene, as a plan would run it; prints what it found next to the
/// simulator's truth and draws it.
int detectScene(const DetectOptions& options) {
  try {
    perception::PerceptionConfig config;
    config.frames = options.frames;
    const auto pipeline = perception::loadPipeline(config);
    const sim::Scene scene = sim::loadScene(options.scene);
    sim::SimulationOptions sim_options;
    sim_options.placement_seed = options.seed;
    SimClock clock;
    auto simulation = sim::Simulation::create(scene, sim_options);
    simulation->attach(clock);
    sim::SimRgbdCamera camera(*simulation, options.seed.value_or(scene.seed));
    perception::PerceptionComponent component(camera, clock, pipeline, config);
    const perception::PipelineResult result = detectOnce(component, clock, options.frames);
    const std::vector<perception::TrackedObject> objects = seenObjects(component);
    const std::vector<PartTruth> truth = truthWithVisibility(*simulation, *result.filtered, *pipeline);
    const RoundMatch match = matchToTruth(objects, truth, *pipeline);
    std::printf("DetectObjects on %s: %zu object(s) in %.1f ms (%d frames; capture not included)\n",
                options.scene.c_str(), objects.size(), millis(result.times.total), options.frames);
    std::printf("  %-8s %-6s %24s %9s   %s\n", "name", "class", "position (m, world)", "yaw (deg)",
                "error against the simulator's truth");
    for (std::size_t d = 0; d < objects.size(); ++d) {
      const auto& object = objects[d];
      const Eigen::Vector3d p = object.pose.translation();
      const double yaw = world::rpyOf(object.pose.linear()).z() * 180.0 / M_PI;
      const int part = match.part_of_detection[d];
      char error[96] = "no such part (false detection)";
      if (part >= 0) {
        std::snprintf(error, sizeof error, "%s: %.1f mm, %.1f deg",
                      truth[static_cast<std::size_t>(part)].state.name.c_str(),
                      match.translation_error[static_cast<std::size_t>(part)] * 1000.0,
                      match.rotation_error[static_cast<std::size_t>(part)] * 180.0 / M_PI);
      }
      std::printf("  %-8s %-6s  (%6.3f, %6.3f, %6.3f) %9.1f   %s\n", object.name.c_str(), object.object_class.c_str(),
                  p.x(), p.y(), p.z(), yaw, error);
    }
    for (std::size_t t = 0; t < truth.size(); ++t) {
      if (match.detection_of_part[t] < 0) {
        std::printf("  missed %s (%s), %.0f %% of it in view\n", truth[t].state.name.c_str(),
                    truth[t].state.object_class.c_str(), truth[t].visible_fraction * 100.0);
      }
    }
    if (!options.out.empty()) {
      writePng(options.out, pictureOf(*result.filtered, objects, truth, match, *pipeline));
      std::printf("picture: %s (green: within 5 mm / 5 deg, red: not, orange: false detection, yellow: missed)\n",
                  options.out.c_str());
    }
    return kExitSuccess;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "costar perception detect: %s\n", e.what());
    return kExitError;
  }
}

}  // namespace

void addPerceptionCommands(CLI::App& app, int& exit_code) {
  CLI::App* perception = app.add_subcommand(
      "perception",
      "Set up and measure perception: the ArUco marker, training data, the SVM, and an evaluation against the "
      "simulator's ground truth");
  perception->require_subcommand(1);

  auto marker = std::make_shared<MarkerOptions>();
  marker->out = (dataRoot() / "sim" / "models" / "aruco_4x4_50_id0.png").string();
  CLI::App* marker_command = perception->add_subcommand(
      "marker",
      "Write the ArUco marker image (DICT_4X4_50) that marks the workspace centre, e.g. for printing or "
      "as the simulated table's texture");
  marker_command->add_option("--id", marker->id, "marker id")->capture_default_str();
  marker_command->add_option("--cell", marker->cell_pixels, "pixels per marker cell")->capture_default_str();
  marker_command->add_option("-o,--out", marker->out, "PNG to write")->capture_default_str();
  marker_command->callback([marker, &exit_code] { exit_code = writeMarker(*marker); });

  auto collect_options = std::make_shared<CollectOptions>();
  CLI::App* collect_command = perception->add_subcommand(
      "collect",
      "Collect SVM training data in the simulated workcell (the paper's Fig. 4): find the workspace centre from the "
      "ArUco marker, then for many random placements crop a box around it, keep the points above the table, split "
      "them into one example per object by Euclidean clustering, and add negative examples (the robot and gripper "
      "over the table, the table, clutter). Writes the workspace centre and the examples.");
  collect_command->add_option("-o,--out", collect_options->out, "folder for the examples (dataset.json + binary)")
      ->capture_default_str();
  collect_command->add_option("--workspace", collect_options->workspace_file,
                              "where to write the workspace centre (default: OUT/workspace.json; the pipeline "
                              "reads data/perception/workspace.json)");
  collect_command->add_option("--scenes-per-class", collect_options->scenes_per_class, "placements per object class")
      ->capture_default_str()
      ->check(CLI::Range(1, 1000));
  collect_command->add_option("--parts", collect_options->parts_per_scene, "parts per placement")
      ->capture_default_str()
      ->check(CLI::Range(1, 12));
  collect_command
      ->add_option("--arm-scenes", collect_options->arm_scenes,
                   "placements of the robot over the table (negative examples)")
      ->capture_default_str()
      ->check(CLI::Range(0, 1000));
  collect_command
      ->add_option("--clutter-scenes", collect_options->clutter_scenes,
                   "placements of clutter objects (negative examples)")
      ->capture_default_str()
      ->check(CLI::Range(0, 1000));
  collect_command->add_option("--frames", collect_options->frames, "frames per placement (median filter)")
      ->capture_default_str()
      ->check(CLI::Range(1, 60));
  collect_command->add_option("--seed", collect_options->seed, "seed of the placements and sensor noise")
      ->capture_default_str();
  collect_command->callback([collect_options, &exit_code] { exit_code = collect(*collect_options); });

  auto train_options = std::make_shared<TrainOptions>();
  CLI::App* train_command = perception->add_subcommand(
      "train",
      "Train the SVM (libsvm, RBF kernel) on collected examples, report the cross-validated accuracy per class, and "
      "write the model (default: data/perception/svm_model.json, which DetectObjects loads). Deterministic for a "
      "seed.");
  train_command->add_option("--dataset", train_options->dataset, "folder written by `costar perception collect`")
      ->capture_default_str();
  train_command->add_option("-o,--out", train_options->out, "model file (default: data/perception/svm_model.json)");
  train_command->add_option("--cost", train_options->svm.cost, "SVM soft-margin cost C")->capture_default_str();
  train_command->add_option("--gamma", train_options->svm.gamma, "RBF gamma on standardized features (0: 1/features)")
      ->capture_default_str();
  train_command->add_option("--folds", train_options->svm.folds, "cross-validation folds (0: none)")
      ->capture_default_str();
  train_command
      ->add_option("--max-per-label", train_options->svm.max_per_label,
                   "examples per label used (random subset; 0: all)")
      ->capture_default_str();
  train_command->add_option("--seed", train_options->svm.seed, "seed of the subset and the folds")
      ->capture_default_str();
  train_command->callback([train_options, &exit_code] { exit_code = train(*train_options); });

  auto eval_options = std::make_shared<EvalOptions>();
  CLI::App* eval_command = perception->add_subcommand(
      "eval",
      "Measure DetectObjects in random cluttered scenes (touching parts included) against the simulator's ground "
      "truth: per class precision, recall, translation and rotation error (symmetry-aware: the smallest over the "
      "class's symmetries; median and 95th percentile), identity persistence while parts stay still and after "
      "small pushes, and the latency of every stage. Exit code 1 when --min-found is not reached.");
  eval_command->add_option("--scenes", eval_options->scenes, "number of random scenes")
      ->capture_default_str()
      ->check(CLI::Range(1, 100000));
  eval_command->add_option("--seed", eval_options->seed, "seed of the scenes, pushes and sensor noise")
      ->capture_default_str();
  eval_command->add_option("--json", eval_options->json, "write the summary as JSON to this file");
  eval_command->add_option("--out", eval_options->out, "folder for a PNG per scene with the detections drawn");
  eval_command
      ->add_option("--repeats", eval_options->repeats, "DetectObjects runs per scene while the parts stay still")
      ->capture_default_str()
      ->check(CLI::Range(0, 10000));
  eval_command
      ->add_option("--long-run", eval_options->long_run,
                   "extra repeats on the first scene (e.g. 100 for the identity target)")
      ->capture_default_str()
      ->check(CLI::Range(0, 100000));
  eval_command
      ->add_option("--pushes", eval_options->pushes, "pushes per scene (one part moved 1-2 cm, turned <= 10 deg)")
      ->capture_default_str()
      ->check(CLI::Range(0, 1000));
  eval_command->add_option("--frames", eval_options->frames, "frames per DetectObjects (median filter's N)")
      ->capture_default_str()
      ->check(CLI::Range(1, 60));
  eval_command->add_option("--touching", eval_options->touching, "chance that a part is placed against another")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1.0));
  eval_command->add_option("--min-found", eval_options->min_found,
                           "fail (exit 1) when fewer of the visible parts are found within 5 mm and 5 deg");
  eval_command->callback([eval_options, &exit_code] { exit_code = evaluate(*eval_options); });

  auto detect_options = std::make_shared<DetectOptions>();
  CLI::App* detect_command = perception->add_subcommand(
      "detect",
      "Run DetectObjects once on a simulated scene, as a plan would: list the objects found (names, poses) with "
      "their error against the simulator's truth, and draw them over the camera image.");
  detect_command->add_option("scene", detect_options->scene, "scene file (e.g. sim/scenes/assembly.json)")
      ->required()
      ->check(CLI::ExistingFile);
  detect_command->add_option("--seed", detect_options->seed, "seed of the part placement and the sensor noise");
  detect_command->add_option("--out", detect_options->out, "write the picture to this PNG file");
  detect_command->add_option("--frames", detect_options->frames, "frames per DetectObjects (median filter's N)")
      ->capture_default_str()
      ->check(CLI::Range(1, 60));
  detect_command->callback([detect_options, &exit_code] { exit_code = detectScene(*detect_options); });
}

}  // namespace costar::cli
