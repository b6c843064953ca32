#include "cli/calibrate_command.h"

#include <cstdio>
#include <iostream>
#include <memory>
#include <sstream>

#include "calibration/hand_eye.h"
#include "cli/number_options.h"
#include "cli/output_options.h"
#include "core/files.h"
#include "sim/simulation.h"
#include "trials/calibration_eval.h"
#include "workcell/sim_cell_description.h"
#include "workcell/workcell.h"

namespace costar::cli {

namespace {

struct CalibrateOptions {
  std::string scene;
  std::uint64_t seed = 1;
  bool seed_given = false;
  std::string workcell = "ur5-sim";
  std::string camera_move;  // "DIST,DEG"
  std::string calibration;
  int views = 0;
  std::string method = "daniilidis";
  bool no_refine = false;
  double speed = 0.0;
  std::string json;
  bool truth = false;
};

workcell::WorkcellOptions cellOptions(const CalibrateOptions& options) {
  workcell::WorkcellOptions cell;
  cell.name = options.workcell;
  cell.scene = options.scene;
  if (options.seed_given) {
    cell.seed = options.seed;
  }
  if (!options.camera_move.empty()) {
    const auto [distance, angle] = parseCameraMove(options.camera_move);
    cell.camera_move = workcell::WorkcellOptions::CameraMove{distance, angle, {}};
  }
  cell.calibration = options.calibration;
  return cell;
}

/// The result as --json holds it. @throws std::runtime_error "cannot write 'FILE': ERROR".
void writeResult(const std::string& file, const nlohmann::json& result) {
  writeOutputFile(file, result.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n");
  std::printf("wrote %s\n", file.c_str());
}

int calibrate(const CalibrateOptions& options, bool marker) {
  std::unique_ptr<workcell::Workcell> cell;
  try {
    // The files written at the end are checked before the arm moves.
    if (!options.json.empty()) {
      checkOutputFile(options.json, "--json");
    }
    if (!options.calibration.empty()) {
      checkOutputFile(options.calibration, "--calibration");
    }
    cell = workcell::makeWorkcell(cellOptions(options));
  } catch (const CLI::ValidationError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  }
  component::ParamMap params;
  if (options.views > 0) {
    params.emplace("views", component::Value(static_cast<long long>(options.views)));
  }
  if (options.speed > 0) {
    params.emplace("speed", component::Value(options.speed));
  }
  if (marker) {
    params.emplace("method", component::Value(options.method));
    params.emplace("refine", component::Value(!options.no_refine));
  }
  const std::string operation = marker ? "CalibrateMarker" : "Calibrate";
  std::printf("costar calibrate: %s on %s (the arm shows the gripper's marker to the camera)\n", operation.c_str(),
              cell->description().c_str());
  std::fflush(stdout);
  component::OperationResult result;
  try {
    result = workcell::runOperation(*cell, operation, params, std::chrono::seconds(300));
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  }
  nlohmann::json out = result.data;
  if (options.truth && cell->simulation() != nullptr && result.state == component::OperationState::kSuccess) {
    // Simulation only: the error against the simulator's true camera pose.
    const world::Pose truth = cell->simulation()->rgbdPose();
    const auto& t = result.data.at("camera").at("xyz");
    const auto& r = result.data.at("camera").at("rpy_deg");
    const world::Pose found = world::poseFromXyzRpy(t[0], t[1], t[2], r[0].get<double>() * M_PI / 180,
                                                    r[1].get<double>() * M_PI / 180, r[2].get<double>() * M_PI / 180);
    out["error_against_truth"] = {{"mm", (found.translation() - truth.translation()).norm() * 1000},
                                  {"deg", world::rotationAngle(found, truth) * 180 / M_PI}};
  }
  const auto shown = [](const nlohmann::json& json) {
    return json.dump(2, ' ', false, nlohmann::json::error_handler_t::replace);
  };
  int code = result.state == component::OperationState::kSuccess ? 0 : 1;
  if (result.state == component::OperationState::kSuccess) {
    std::printf("SUCCESS: %s\n", shown(out).c_str());
    // The calibration is in use in this process, which ends here: unsaved, it is lost.
    if (out.contains("warning")) {
      std::cerr << "error: the calibration was not saved: " << out["warning"].get<std::string>() << "\n";
      code = 2;
    }
  } else {
    std::printf("FAILURE: %s\n%s\n", result.reason.c_str(), out.is_null() ? "" : shown(out).c_str());
  }
  if (!options.json.empty()) {
    try {
      writeResult(options.json,
                  {{"state", component::toString(result.state)}, {"reason", result.reason}, {"data", out}});
    } catch (const std::exception& e) {
      std::cerr << "error: " << e.what() << "\n";
      code = 2;
    }
  }
  return code;
}

/// --methods "daniilidis,tsai": each a hand-eye method. @throws std::invalid_argument naming
/// the option, the method and the known ones.
std::vector<std::string> parseMethods(const std::string& text) {
  std::vector<std::string> methods;
  if (text.empty()) {
    return methods;
  }
  std::stringstream list(text);
  for (std::string method; std::getline(list, method, ',');) {
    try {
      calibration::methodFromName(method);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(std::string("--methods: ") + e.what() +
                                  " (a comma-separated list, e.g. daniilidis,tsai)");
    }
    methods.push_back(method);
  }
  if (text.back() == ',') {
    throw std::invalid_argument("--methods: '" + typed(text) + "' ends with a comma (e.g. daniilidis,tsai)");
  }
  return methods;
}

struct EvalOptions {
  trials::CalibrationEvalOptions eval;
  std::string camera_move = "0.05,5";
  std::string methods;
  bool no_refine = false;
  std::string json;
};

int evaluate(EvalOptions options) {
  // Only the simulated cells have a true camera pose to compare with.
  std::string known;
  bool simulated = false;
  for (const auto& [name, label] : workcell::simCells()) {
    simulated = simulated || name == options.eval.workcell;
    known += (known.empty() ? "" : ", ") + name;
  }
  if (!simulated) {
    std::cerr << "error: unknown workcell '" << options.eval.workcell
              << "' for calibrate eval (simulated cells: " << known << ")\n";
    return 2;
  }
  try {
    const auto [distance, angle] = parseCameraMove(options.camera_move);
    options.eval.camera_move_m = distance;
    options.eval.camera_turn_deg = angle;
    options.eval.methods = parseMethods(options.methods);
    if (!options.json.empty()) {
      checkOutputFile(options.json, "--json");
    }
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  }
  options.eval.refine = !options.no_refine;
  std::printf("costar calibrate eval: %s, %d set-up(s), seeds %llu.., camera moved %.3f m and turned %.1f deg\n",
              options.eval.workcell.c_str(), options.eval.setups, static_cast<unsigned long long>(options.eval.seed),
              options.eval.camera_move_m, options.eval.camera_turn_deg);
  std::fflush(stdout);
  const trials::CalibrationEvalSummary summary =
      trials::evaluateCalibration(options.eval, [](const trials::CalibrationSample& s) {
        if (s.camera_ok) {
          std::printf(
              "set-up %d %-10s camera %.2f mm %.3f deg (drawn pose was %.1f mm %.2f deg off), marker %.2f mm "
              "%.3f deg, simulated %.1f + %.1f s, parts moved by Calibrate %.1f mm\n",
              s.setup, s.method.empty() ? "cell" : s.method.c_str(), s.camera_mm, s.camera_deg, s.camera_before_mm,
              s.camera_before_deg, s.marker_mm, s.marker_deg, s.marker_simulated_s, s.camera_simulated_s,
              s.parts_moved_mm);
          if (s.parts > 0) {
            std::printf("  DetectObjects: %d/%d parts within 5 mm and 5 deg before Calibrate, %d/%d after\n",
                        s.parts_accurate_before, s.parts, s.parts_accurate_after, s.parts);
          }
        } else {
          std::printf("set-up %d %-10s FAILED: %s\n", s.setup, s.method.empty() ? "cell" : s.method.c_str(),
                      s.reason.c_str());
        }
        std::fflush(stdout);
      });
  std::printf("\n%s", summary.text().c_str());
  if (!options.json.empty()) {
    try {
      writeResult(options.json, summary.toJson());
    } catch (const std::exception& e) {
      std::cerr << "error: " << e.what() << "\n";
      return 2;
    }
  }
  return 0;
}

void addCellOptions(CLI::App* command, CalibrateOptions& options) {
  command
      ->add_option("-w,--workcell", options.workcell,
                   "simulated workcell (workcells/NAME.json: " + workcell::knownWorkcellNames(true) + ")")
      ->capture_default_str();
  command->add_option("--scene", options.scene, "scene file (default sim/scenes/assembly.json)")
      ->check(CLI::ExistingFile);
  command->add_option("--seed", options.seed, "seed of the cell (placement, noise, the camera's move)")
      ->check(wholeNumber())
      ->each([&options](const std::string&) { options.seed_given = true; });
  command->add_option("--camera-move", options.camera_move,
                      "simulation: the camera moved from its drawn mounting, DISTANCE_M,ANGLE_DEG in a seeded random "
                      "direction (e.g. 0.05,5)");
  command->add_option("--calibration", options.calibration,
                      "calibration file to read and write (default: the cell's, beside its waypoints)");
  command->add_option("--views", options.views, "views of the marker to take")->check(CLI::Range(1, 40));
  command->add_option("--speed", options.speed, "fraction of the arm's top speed")->check(numberIn(0.05, 1.0));
  command->add_option("--json", options.json, "write the result as JSON")->check(aFileName());
  command->add_flag("--truth", options.truth, "simulation: also print the error against the true camera pose");
}

}  // namespace

void addCalibrateCommand(CLI::App& app, int& exit_code) {
  auto options = std::make_shared<CalibrateOptions>();
  CLI::App* command = app.add_subcommand(
      "calibrate",
      "Calibrate the camera: the arm shows the marker on its gripper to the camera from poses it chooses, and the "
      "camera's pose is saved with the cell (the editor's Calibrate button)");
  addCellOptions(command, *options);
  command->footer(
      "Exit code: 0 calibrated, 1 the calibration failed (the previous one is kept), 2 bad options.\n"
      "Once after fixing the marker to the gripper: costar calibrate marker. See docs/CALIBRATION.md.");

  auto marker_options = std::make_shared<CalibrateOptions>();
  CLI::App* marker = command->add_subcommand(
      "marker", "Once, after fixing the marker to the gripper: find where it is on the flange (hand-eye calibration)");
  addCellOptions(marker, *marker_options);
  marker
      ->add_option("--method", marker_options->method,
                   "hand-eye method: daniilidis (the paper's), tsai, park, horaud, andreff, shah, li")
      ->capture_default_str()
      ->check(CLI::IsMember({"daniilidis", "tsai", "park", "horaud", "andreff", "shah", "li"}));
  marker->add_flag("--no-refine", marker_options->no_refine,
                   "keep the method's own solution (no reprojection refinement)");
  marker->callback([marker_options, &exit_code] { exit_code = calibrate(*marker_options, true); });

  auto eval_options = std::make_shared<EvalOptions>();
  CLI::App* eval = command->add_subcommand(
      "eval", "Simulation: calibrate N seeded set-ups with the camera moved, and compare with its true pose");
  eval->add_option("-w,--workcell", eval_options->eval.workcell,
                   "simulated workcell (workcells/NAME.json: " + workcell::knownWorkcellNames(true) + ")")
      ->capture_default_str();
  eval->add_option("--scene", eval_options->eval.scene, "scene file (default sim/scenes/assembly.json)")
      ->check(CLI::ExistingFile);
  eval->add_option("--setups", eval_options->eval.setups, "number of set-ups")
      ->capture_default_str()
      ->check(CLI::Range(1, 1000));
  eval->add_option("--seed", eval_options->eval.seed, "seed of the first set-up")
      ->check(wholeNumber())
      ->capture_default_str();
  eval->add_option("--camera-move", eval_options->camera_move, "DISTANCE_M,ANGLE_DEG")->capture_default_str();
  eval->add_option("--methods", eval_options->methods,
                   "comma-separated hand-eye methods to run the marker calibration with in each set-up (default: "
                   "none, Calibrate with the cell's marker calibration)");
  eval->add_flag("--no-refine", eval_options->no_refine, "the methods' own solutions, unrefined");
  eval->add_flag("--perception", eval_options->eval.perception,
                 "also run DetectObjects before and after Calibrate and score the parts against the truth");
  eval->add_option("--marker-views", eval_options->eval.marker_views,
                   "views of the marker calibration (default: the cell's)")
      ->check(CLI::Range(6, 40));
  eval->add_option("--views", eval_options->eval.camera_views, "views of Calibrate (default: the cell's)")
      ->check(CLI::Range(3, 20));
  eval->add_option("--json", eval_options->json, "write every sample as JSON")->check(aFileName());
  eval->callback([eval_options, &exit_code] { exit_code = evaluate(*eval_options); });

  command->callback([options, command, &exit_code] {
    if (command->get_subcommands().empty()) {
      exit_code = calibrate(*options, false);
    }
  });
}

}  // namespace costar::cli
