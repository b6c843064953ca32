#include "cli/trials_command.h"

#include <cstdio>
#include <fstream>
#include <iostream>
#include <thread>

#include "bt/plan.h"
#include "trials/judge.h"
#include "trials/trials.h"

namespace costar::cli {

namespace {

struct Options {
  trials::TrialOptions trials;
  std::string json;
  std::string plot;
  double require = 0.0;
};

int run(Options options) {
  if (options.trials.scene.empty()) {
    options.trials.scene = "sim/scenes/assembly.json";
  }
  std::printf("costar trials: %d trial(s) of %s on scene %s, judge '%s', seeds %llu.., %d at a time\n",
              options.trials.count, options.trials.plan.c_str(), options.trials.scene.c_str(),
              options.trials.judge.c_str(), static_cast<unsigned long long>(options.trials.seed), options.trials.jobs);
  std::fflush(stdout);
  trials::Summary summary;
  try {
    summary = trials::runTrials(options.trials, [&options](const trials::TrialResult& result, int done) {
      if (result.success) {
        std::printf("[%4d/%d] trial %d (seed %llu): SUCCESS in %.1f s simulated (%.1f s wall)\n", done,
                    options.trials.count, result.index, static_cast<unsigned long long>(result.seed),
                    result.cycle_time_s, result.wall_s);
      } else {
        std::printf("[%4d/%d] trial %d (seed %llu): FAILURE at %s: %s\n", done, options.trials.count, result.index,
                    static_cast<unsigned long long>(result.seed), result.failure_path.c_str(), result.reason.c_str());
      }
      std::fflush(stdout);
    });
  } catch (const bt::PlanError& error) {
    for (const auto& diagnostic : error.diagnostics()) {
      std::cerr << "error: " << diagnostic.str() << "\n";
    }
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  }
  std::printf("\n%s", summary.text().c_str());
  if (!options.json.empty()) {
    std::ofstream(options.json) << summary.toJson().dump(2) << "\n";
    std::printf("wrote %s\n", options.json.c_str());
  }
  if (!options.plot.empty()) {
    trials::writePlot(summary, options.plot);
    std::printf("wrote %s\n", options.plot.c_str());
  }
  const double rate = summary.trials.empty() ? 0.0 : static_cast<double>(summary.successes()) / summary.trials.size();
  return rate + 1e-12 >= options.require ? 0 : 1;
}

}  // namespace

void addTrialsCommand(CLI::App& app, int& exit_code) {
  auto options = std::make_shared<Options>();
  options->trials.jobs = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  std::string judges;
  for (const auto& info : trials::judges()) {
    judges += "\n  " + info.name + ": " + info.description;
  }
  CLI::App* command = app.add_subcommand(
      "trials", "Rerun a plan as N randomized trials in the simulated cell, judged from its true state");
  command->add_option("plan", options->trials.plan, "plan file")->required()->check(CLI::ExistingFile);
  command->add_option("--judge", options->trials.judge, "how success is judged (see below)")->required();
  command->add_option("--scene", options->trials.scene, "scene file (default sim/scenes/assembly.json)")
      ->check(CLI::ExistingFile);
  command->add_option("-n,--n", options->trials.count, "number of trials")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  command->add_option("--seed", options->trials.seed, "seed of the first trial (trial i: seed + i)")
      ->capture_default_str();
  command->add_option("-j,--jobs", options->trials.jobs, "trials run at once")
      ->check(CLI::Range(1, 64))
      ->capture_default_str();
  command->add_option("--waypoints", options->trials.waypoints, "waypoint file the plan uses (read only)")
      ->check(CLI::ExistingFile);
  command->add_option("--time-limit", options->trials.time_limit_s, "simulated seconds allowed per trial")
      ->capture_default_str();
  command->add_option_function<std::string>(
      "--camera-move",
      [options](const std::string& text) {
        const auto comma = text.find(',');
        try {
          options->trials.camera_move_m = std::stod(text.substr(0, comma));
          options->trials.camera_turn_deg = comma == std::string::npos ? 0.0 : std::stod(text.substr(comma + 1));
        } catch (const std::exception&) {
          throw CLI::ValidationError("--camera-move", "'" + text + "' should be DISTANCE_M,ANGLE_DEG (e.g. 0.05,5)");
        }
        if (options->trials.camera_move_m < 0 || options->trials.camera_move_m > 0.5 ||
            options->trials.camera_turn_deg < 0 || options->trials.camera_turn_deg > 45) {
          throw CLI::ValidationError("--camera-move", "at most 0.5 m and 45 degrees");
        }
      },
      "the camera moved from its drawn mounting in each trial: DISTANCE_M,ANGLE_DEG, direction from the trial's seed");
  command->add_flag("--calibrate", options->trials.calibrate,
                    "run Calibrate in each trial's cell before the plan (as a technician would after set-up)");
  command->add_option("--json", options->json, "write the summary and every trial as JSON");
  command->add_option("--plot", options->plot, "write a PNG: success rate, failures, cycle times");
  command->add_option("--require", options->require, "exit 1 when the success rate is below this (0..1)")
      ->check(CLI::Range(0.0, 1.0));
  command->footer("Judges:" + judges +
                  "\nExit code: 0, or 1 when the success rate is below --require; 2 for an invalid plan or option.");
  command->callback([options, &exit_code] { exit_code = run(*options); });
}

}  // namespace costar::cli
