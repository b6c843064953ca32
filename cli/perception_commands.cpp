#include "cli/perception_commands.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <string>

#include "cli/number_options.h"
#include "cli/output_options.h"
#include "core/files.h"
#include "core/image.h"
#include "core/paths.h"
#include "perception/aruco_marker.h"
#include "perception/features.h"
#include "perception/pipeline.h"
#include "perception/svm_classifier.h"
#include "perception/training_data.h"
#include "trials/perception_collect.h"
#include "trials/perception_eval.h"
#include "workcell/sim_cell_description.h"
#include "world/pose.h"

namespace costar::cli {

namespace {

namespace fs = std::filesystem;

constexpr int kExitSuccess = 0;
constexpr int kExitBelowFloor = 1;
constexpr int kExitError = 2;

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
// collect (trials/perception_collect.h)

int collect(const trials::CollectOptions& options) {
  try {
    const trials::CollectResult result = trials::collectTrainingData(options, [&options](const auto& progress) {
      if (!progress.scene.empty()) {
        std::printf("  [%3d/%3d] %-34s %2d example(s), %5d voxels\n", progress.done, progress.total,
                    progress.scene.c_str(), progress.examples, progress.voxels);
      } else if (progress.step == 1) {
        std::printf(
            "collect: 1. finding the workspace centre (ArUco marker DICT_4X4_50 id 0, 10 cm) on a clear table\n");
      } else if (progress.step == 2) {
        std::printf("collect: 2. positive examples: %d scenes per class, %d parts each, well apart\n",
                    options.scenes_per_class, options.parts_per_scene);
      } else if (progress.step == 3) {
        std::printf("collect: 3. negative examples: %s's robot and gripper over the table (%d), clutter (%d), table\n",
                    options.workcell.c_str(), options.arm_scenes, options.clutter_scenes);
      } else {
        std::printf(
            "collect: 4. mixed scenes (%d): parts touching and stacked, the robot over them, labelled point by point "
            "from the simulator's truth\n",
            options.mixed_scenes);
      }
      std::fflush(stdout);
    });
    const world::Pose& centre = result.table_center;
    const Eigen::Vector3d rpy = world::rpyOf(centre.linear()) * 180.0 / M_PI;
    std::printf("table_center at (%.4f, %.4f, %.4f) m, roll/pitch/yaw (%.2f, %.2f, %.2f) deg: wrote %s\n",
                centre.translation().x(), centre.translation().y(), centre.translation().z(), rpy.x(), rpy.y(), rpy.z(),
                result.workspace_file.string().c_str());
    std::printf("collect: wrote %s (%ld examples of %d features) in %.0f s\n", result.dataset.string().c_str(),
                result.rows, perception::kFeatureCount, result.seconds);
    for (const auto& [label, name] : result.names) {
      std::printf("   %-10s (label %d): %6ld voxels\n", name.c_str(), label, result.voxels.at(label));
    }
    std::printf("next: costar perception train -w %s --dataset %s\n", options.workcell.c_str(),
                result.dataset.string().c_str());
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
  std::string workcell;
  perception::SvmTrainingOptions svm;
};

/// Where a trained model goes: --out, else the cell's perception_model, else the default model.
fs::path modelFile(const TrainOptions& options) {
  if (!options.out.empty()) {
    return options.out;
  }
  if (options.workcell.empty()) {
    return perception::PipelineFiles::under().svm_file;
  }
  const workcell::SimCellDescription cell = workcell::loadSimCellDescription(workcell::simCellFile(options.workcell));
  if (cell.perception_model.empty()) {
    throw std::runtime_error("workcell description '" + cell.file.string() +
                             "': perception_model: absent; name the file the cell's model goes to (e.g. "
                             "\"data/perception/svm/" +
                             cell.name + ".json\") or pass --out");
  }
  return cell.perception_model;
}

int train(const TrainOptions& options) {
  try {
    const fs::path out = modelFile(options);
    checkOutputFile(out, "--out");  // before the training's minutes
    const perception::TrainingSet dataset = perception::loadTrainingSet(options.dataset);
    std::printf("train: %zu examples from %s\n", dataset.labels.size(), options.dataset.c_str());
    perception::SvmTrainingReport report;
    const auto classifier = perception::SvmClassifier::train(dataset.features, dataset.labels, dataset.names,
                                                             options.svm, &report, [](const std::string& step) {
                                                               std::printf("train: %s ...\n", step.c_str());
                                                               std::fflush(stdout);
                                                             });
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
    if (report.held_out_accuracy > 0.0) {
      std::printf("held-out accuracy (examples not trained on, classified by the final model):\n");
      for (const auto& [label, entry] : report.labels) {
        std::printf("   %-10s %5d  %6.2f %%\n", entry.name.c_str(), entry.held_out, 100.0 * entry.heldOutAccuracy());
      }
      std::printf("   %-10s        %6.2f %%\n", "overall", 100.0 * report.held_out_accuracy);
    }
    std::printf("train: wrote %s\n", out.string().c_str());
    return kExitSuccess;
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return kExitError;
  }
}

// ---------------------------------------------------------------------------------------------
// eval and detect (trials/perception_eval.h)

struct EvalOptions {
  trials::PerceptionEvalOptions eval;
  std::string json;
  double min_found = -1.0;
};

int evaluate(const EvalOptions& options) {
  try {
    const trials::PerceptionEvalOptions& eval = options.eval;
    // Refused now rather than after the evaluation's minutes.
    if (!options.json.empty()) {
      checkOutputFile(options.json, "--json");
    }
    std::printf(
        "eval on %s: %d random cluttered scene(s), seed %llu, %d frames per DetectObjects, %d repeat(s), %d "
        "push(es)\n",
        eval.workcell.c_str(), eval.scenes, static_cast<unsigned long long>(eval.seed), eval.frames, eval.repeats,
        eval.pushes);
    const trials::PerceptionEvalSummary summary =
        trials::evaluatePerception(eval, [&eval](const trials::SceneReport& scene) {
          std::printf(
              "  scene %2d/%d: %d parts (%d placed touching), first look %d/%d within 5 mm and 5 deg, "
              "identities %d/%d stable over %d repeats, %d/%d pushes kept every name, %.0f ms\n",
              scene.scene, eval.scenes, scene.parts, scene.touching_parts, scene.accurate_first_look, scene.parts,
              scene.names_kept, scene.name_checks, scene.repeats, scene.pushes_all_names_kept, eval.pushes,
              scene.last_detection_ms);
          std::fflush(stdout);
        });
    std::fputs(summary.text().c_str(), stdout);
    if (!options.json.empty()) {
      writeOutputFile(options.json,
                      summary.toJson().dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n");
      std::printf("\nwrote %s\n", options.json.c_str());
    }
    if (!eval.pictures.empty()) {
      std::printf(
          "pictures in %s (green: within 5 mm / 5 deg, red: not, orange: false detection, yellow: missed);\n"
          "each scene's file beside its picture (scene_NNN.json, scene_NNN_push_K.json): "
          "`costar-robot perception detect FILE` runs it again; with `--look scene_NNN_look.json` as the first look "
          "saw it (the camera's noise, the arm over the parts)\n",
          eval.pictures.string().c_str());
    }
    const double found = summary.scores.foundWithinTolerance();
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
  std::string workcell = "ur5-sim";
  std::optional<std::uint64_t> seed;
  std::string look;
  std::string out;
  int frames = 15;
};

/// DetectObjects once on a scene, as a plan would run it; prints what it found next to the
/// simulator's truth and draws it.
int detectScene(const DetectOptions& options) {
  try {
    if (!options.out.empty()) {
      checkOutputFile(options.out, "--out");
    }
    std::optional<trials::SceneLook> look;
    if (!options.look.empty()) {
      look = trials::loadSceneLook(options.look);
    }
    const trials::SceneDetection found =
        trials::detectInScene(options.scene, options.seed, options.frames, options.workcell, look);
    const trials::Match& match = found.match;
    std::printf("DetectObjects on %s: %zu object(s) in %.1f ms (%d frames; capture not included)\n",
                options.scene.c_str(), found.detected.size(), found.milliseconds, options.frames);
    std::printf("  %-8s %-6s %24s %9s   %s\n", "name", "class", "position (m, world)", "yaw (deg)",
                "error against the simulator's truth");
    for (std::size_t d = 0; d < found.detected.size(); ++d) {
      const trials::DetectedPart& object = found.detected[d];
      const Eigen::Vector3d p = object.pose.translation();
      const double yaw = world::rpyOf(object.pose.linear()).z() * 180.0 / M_PI;
      const int part = match.part_of_detection[d];
      char error[96] = "no such part (false detection)";
      if (part >= 0) {
        const auto index = static_cast<std::size_t>(part);
        std::snprintf(error, sizeof error, "%s: %.1f mm, %.1f deg", found.truth[index].name.c_str(),
                      match.translation_error[index] * 1000.0, match.rotation_error[index] * 180.0 / M_PI);
      }
      std::printf("  %-8s %-6s  (%6.3f, %6.3f, %6.3f) %9.1f   %s\n", object.name.c_str(), object.object_class.c_str(),
                  p.x(), p.y(), p.z(), yaw, error);
    }
    for (std::size_t t = 0; t < found.truth.size(); ++t) {
      if (match.detection_of_part[t] < 0) {
        std::printf("  missed %s (%s), %.0f %% of it in view\n", found.truth[t].name.c_str(),
                    found.truth[t].object_class.c_str(), found.truth[t].visible_fraction * 100.0);
      }
    }
    if (!options.out.empty()) {
      writePng(options.out, found.picture);
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
  // Checked here: OpenCV's assertion text answered --id -1, and --cell 100000 asked for a
  // 64-gigapixel image (a hostile tester's findings).
  marker_command->add_option("--id", marker->id, "marker id (DICT_4X4_50 has ids 0 to 49)")
      ->capture_default_str()
      ->check(CLI::Range(0, 49));
  marker_command->add_option("--cell", marker->cell_pixels, "pixels per marker cell")
      ->capture_default_str()
      ->check(CLI::Range(1, 500));
  marker_command->add_option("-o,--out", marker->out, "PNG to write")->capture_default_str()->check(aFileName());
  marker_command->callback([marker, &exit_code] { exit_code = writeMarker(*marker); });

  auto collect_options = std::make_shared<trials::CollectOptions>();
  CLI::App* collect_command = perception->add_subcommand(
      "collect",
      "Collect SVM training data in the simulated workcell (the paper's Fig. 4): find the workspace centre from the "
      "ArUco marker, then for many random placements crop a box around it, keep the points above the table, split "
      "them into one example per object by Euclidean clustering, and add negative examples (the robot and gripper "
      "over the table, the table, clutter). Writes the workspace centre and the examples.");
  collect_command->add_option("-o,--out", collect_options->out, "folder for the examples (dataset.json + binary)")
      ->capture_default_str()
      ->check(aFileName());
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
  collect_command
      ->add_option("--mixed-scenes", collect_options->mixed_scenes,
                   "placements of parts touching and stacked with the robot over them, labelled point by point from "
                   "the simulator's truth")
      ->capture_default_str()
      ->check(CLI::Range(0, 1000));
  collect_command
      ->add_option("-w,--workcell", collect_options->workcell,
                   "simulated workcell whose robot, gripper and camera are posed (workcells/NAME.json)")
      ->capture_default_str();
  collect_command->add_option("--frames", collect_options->frames, "frames per placement (median filter)")
      ->capture_default_str()
      ->check(CLI::Range(1, 60));
  collect_command->add_option("--seed", collect_options->seed, "seed of the placements and sensor noise")
      ->check(wholeNumber())
      ->capture_default_str();
  collect_command->callback([collect_options, &exit_code] { exit_code = collect(*collect_options); });

  auto train_options = std::make_shared<TrainOptions>();
  CLI::App* train_command = perception->add_subcommand(
      "train",
      "Train the SVM (libsvm, RBF kernel) on collected examples, report the cross-validated accuracy per class, and "
      "write the model (with -w: the cell's, which DetectObjects in that cell loads). Deterministic for a seed.");
  train_command->add_option("--dataset", train_options->dataset, "folder written by `costar perception collect`")
      ->capture_default_str();
  train_command
      ->add_option("-o,--out", train_options->out,
                   "model file (default: the cell's perception_model with -w, else "
                   "data/perception/svm/ur5-sim.json)")
      ->check(aFileName());
  train_command->add_option("-w,--workcell", train_options->workcell,
                            "write the model the cell names (workcells/NAME.json's perception_model)");
  train_command->add_option("--cost", train_options->svm.cost, "SVM soft-margin cost C")
      ->check(numberIn(0.0, 1e9, true))
      ->capture_default_str();
  train_command->add_option("--gamma", train_options->svm.gamma, "RBF gamma on standardized features (0: 1/features)")
      ->check(numberIn(0.0, 1e9))
      ->capture_default_str();
  train_command->add_option("--folds", train_options->svm.folds, "cross-validation folds (0: none)")
      ->check(CLI::Validator(
          [](const std::string& text) -> std::string {
            const std::optional<double> folds = parseNumber(text);
            return folds && *folds == std::floor(*folds) && (*folds == 0 || (*folds >= 2 && *folds <= 100))
                       ? std::string()
                       : "must be 0 (none) or a whole number from 2 to 100, not " + typed(text);
          },
          "0|2..100"))
      ->capture_default_str();
  train_command
      ->add_option("--max-per-label", train_options->svm.max_per_label,
                   "examples per label used (random subset; 0: all)")
      ->capture_default_str();
  train_command
      ->add_option("--held-out", train_options->svm.held_out_per_label,
                   "examples per label not trained on that the model classifies afterwards (0: none)")
      ->capture_default_str()
      ->check(CLI::Range(0, 10000000));
  train_command->add_option("--seed", train_options->svm.seed, "seed of the subset and the folds")
      ->check(wholeNumber<unsigned>())
      ->capture_default_str();
  train_command->callback([train_options, &exit_code] { exit_code = train(*train_options); });

  // retrain: collect, then train, for one cell.
  auto retrain_collect = std::make_shared<trials::CollectOptions>();
  auto retrain_train = std::make_shared<TrainOptions>();
  CLI::App* retrain_command = perception->add_subcommand(
      "retrain",
      "Collect training data in a simulated cell with its own robot and gripper, then train and write the cell's "
      "model (workcells/NAME.json's perception_model): `collect -w NAME` and `train -w NAME` in one command, with "
      "their defaults.");
  retrain_command->add_option("-w,--workcell", retrain_collect->workcell, "simulated workcell")->required();
  retrain_command->add_option("--dataset", retrain_collect->out,
                              "folder for the examples (default: perception_dataset_NAME)");
  retrain_command->add_option("--seed", retrain_collect->seed, "seed of the placements and sensor noise")
      ->check(wholeNumber())
      ->capture_default_str();
  retrain_command->callback([retrain_collect, retrain_train, &exit_code] {
    if (retrain_collect->out == trials::CollectOptions{}.out) {
      retrain_collect->out = "perception_dataset_" + retrain_collect->workcell;
    }
    retrain_collect->workspace_file = retrain_collect->out / "workspace.json";
    retrain_train->workcell = retrain_collect->workcell;
    retrain_train->dataset = retrain_collect->out.string();
    try {
      checkOutputFile(modelFile(*retrain_train), "the cell's perception_model");  // before the minutes
    } catch (const std::exception& e) {
      std::cerr << "error: " << e.what() << "\n";
      exit_code = kExitError;
      return;
    }
    exit_code = collect(*retrain_collect);
    if (exit_code == kExitSuccess) {
      exit_code = train(*retrain_train);
    }
  });

  auto eval_options = std::make_shared<EvalOptions>();
  CLI::App* eval_command = perception->add_subcommand(
      "eval",
      "Measure DetectObjects in random cluttered scenes (touching parts included) against the simulator's ground "
      "truth: per class precision, recall, translation and rotation error (symmetry-aware: the smallest over the "
      "class's symmetries; median and 95th percentile), identity persistence while parts stay still and after "
      "small pushes, and the latency of every stage. Exit code 1 when --min-found is not reached.");
  eval_command->add_option("--scenes", eval_options->eval.scenes, "number of random scenes")
      ->capture_default_str()
      ->check(CLI::Range(1, 100000));
  eval_command->add_option("--seed", eval_options->eval.seed, "seed of the scenes, pushes and sensor noise")
      ->check(wholeNumber())
      ->capture_default_str();
  eval_command->add_option("--json", eval_options->json, "write the summary as JSON to this file")->check(aFileName());
  eval_command
      ->add_option("--out", eval_options->eval.pictures,
                   "folder for a PNG per scene with the detections drawn, and each scene's file (and each "
                   "push's) to run again with `perception detect`")
      ->check(aFileName());
  eval_command
      ->add_option("--repeats", eval_options->eval.repeats, "DetectObjects runs per scene while the parts stay still")
      ->capture_default_str()
      ->check(CLI::Range(0, 10000));
  eval_command
      ->add_option("--long-run", eval_options->eval.long_run,
                   "extra repeats on the first scene (e.g. 100 for the identity target)")
      ->capture_default_str()
      ->check(CLI::Range(0, 100000));
  eval_command
      ->add_option("--pushes", eval_options->eval.pushes, "pushes per scene (one part moved 1-2 cm, turned <= 10 deg)")
      ->capture_default_str()
      ->check(CLI::Range(0, 1000));
  eval_command->add_option("--frames", eval_options->eval.frames, "frames per DetectObjects (median filter's N)")
      ->capture_default_str()
      ->check(CLI::Range(1, 60));
  eval_command->add_option("--touching", eval_options->eval.touching, "chance that a part is placed against another")
      ->capture_default_str()
      ->check(numberIn(0.0, 1.0));
  eval_command->add_option("--stacked", eval_options->eval.stacked, "links put across nodes per scene")
      ->capture_default_str()
      ->check(CLI::Range(0, 6));
  eval_command
      ->add_option("--arm-over", eval_options->eval.arm_over,
                   "chance that a scene has the cell's arm posed over the parts (hiding some; none may be detected on "
                   "it)")
      ->capture_default_str()
      ->check(numberIn(0.0, 1.0));
  eval_command
      ->add_option("-w,--workcell", eval_options->eval.workcell,
                   "simulated workcell: its robot, gripper, camera and perception model (workcells/NAME.json)")
      ->capture_default_str();
  eval_command
      ->add_option(
          "--model", eval_options->eval.model,
          "SVM model file to use instead of the cell's perception_model (to compare models on the same scenes)")
      ->check(CLI::ExistingFile);
  eval_command
      ->add_option("--min-found", eval_options->min_found,
                   "fail (exit 1) when fewer of the visible parts are found within 5 mm and 5 deg (0..1)")
      ->check(numberIn(0.0, 1.0));
  eval_command->callback([eval_options, &exit_code] { exit_code = evaluate(*eval_options); });

  auto detect_options = std::make_shared<DetectOptions>();
  CLI::App* detect_command = perception->add_subcommand(
      "detect",
      "Run DetectObjects once on a simulated scene, as a plan would: list the objects found (names, poses) with "
      "their error against the simulator's truth, and draw them over the camera image.");
  detect_command->add_option("scene", detect_options->scene, "scene file (e.g. sim/scenes/assembly.json)")
      ->required()
      ->check(CLI::ExistingFile);
  detect_command->add_option("--seed", detect_options->seed, "seed of the part placement and the sensor noise")
      ->check(wholeNumber());
  detect_command->add_option("--out", detect_options->out, "write the picture to this PNG file")->check(aFileName());
  detect_command
      ->add_option("--look", detect_options->look,
                   "scene_NNN_look.json that perception eval wrote beside the scene: the camera's noise and "
                   "the arm over the parts as its first look had them")
      ->check(CLI::ExistingFile);
  detect_command
      ->add_option("-w,--workcell", detect_options->workcell,
                   "simulated workcell: its robot, gripper, camera and perception model (workcells/NAME.json)")
      ->capture_default_str();
  detect_command->add_option("--frames", detect_options->frames, "frames per DetectObjects (median filter's N)")
      ->capture_default_str()
      ->check(CLI::Range(1, 60));
  detect_command->callback([detect_options, &exit_code] { exit_code = detectScene(*detect_options); });
}

}  // namespace costar::cli
