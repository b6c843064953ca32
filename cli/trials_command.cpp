#include "cli/trials_command.h"

#include <cstdint>
#include <cstdio>
#include <functional>
#include <iostream>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "bt/plan.h"
#include "cli/inject_option.h"
#include "cli/number_options.h"
#include "cli/output_options.h"
#include "cli/stop_signals.h"
#include "core/files.h"
#include "core/json_file.h"
#include "trials/disturbance.h"
#include "trials/judge.h"
#include "trials/trials.h"

namespace costar::cli {

namespace {

struct Options {
  trials::TrialOptions trials;
  std::string json;
  std::string plot;
  double require = 0.0;
  std::string shard;                      // "I/N"
  std::vector<std::string> merge_inputs;  // `costar trials merge`
};

/// "I/N" with 0 <= I < N into the options. @throws std::invalid_argument.
void parseShard(const std::string& text, trials::TrialOptions& options) {
  const auto slash = text.find('/');
  try {
    std::size_t used_index = 0;
    std::size_t used_count = 0;
    if (slash == std::string::npos) {
      throw std::invalid_argument("no '/'");
    }
    options.shard_index = std::stoi(text.substr(0, slash), &used_index);
    options.shard_count = std::stoi(text.substr(slash + 1), &used_count);
    if (used_index != slash || used_count != text.size() - slash - 1) {
      throw std::invalid_argument("trailing characters");
    }
  } catch (const std::exception&) {
    throw std::invalid_argument("--shard: '" + text + "' is not I/N (e.g. 0/4: the first of 4 slices)");
  }
  if (options.shard_count < 1 || options.shard_index < 0 || options.shard_index >= options.shard_count) {
    throw std::invalid_argument("--shard: '" + text + "': needs 0 <= I < N (slices are numbered from 0)");
  }
}

/// Prints the summary, writes the JSON and the plot where asked; the exit code (`code` unless an
/// output could not be written, or the success rate is below --require).
int report(const trials::Summary& summary, const Options& options, int code = 0) {
  std::printf("\n%s", summary.text().c_str());
  const double rate = summary.trials.empty() ? 0.0 : static_cast<double>(summary.successes()) / summary.trials.size();
  if (code == 0 && rate + 1e-12 < options.require) {
    code = 1;
  }
  // Each output on its own: the JSON is written even when the plot cannot be.
  const auto write = [&code](const std::string& file, const std::function<void()>& writer) {
    try {
      writer();
      std::printf("wrote %s\n", file.c_str());
    } catch (const std::exception& e) {
      std::cerr << "error: " << e.what() << "\n";
      code = 2;
    }
  };
  if (!options.json.empty()) {
    write(options.json, [&] { trials::writeJson(summary, options.json); });
  }
  if (!options.plot.empty()) {
    std::vector<std::filesystem::path> written;
    write(options.plot, [&] { written = trials::writePlot(summary, options.plot); });
    for (std::size_t i = 1; i < written.size(); ++i) {
      std::printf("wrote %s\n", written[i].c_str());  // a polishing trial's force and coverage pictures
    }
  }
  return code;
}

/// Checks that the outputs can be written at the end, before anything runs, and that none of
/// them is a file the trials read.
void checkOutputs(const Options& options) {
  NamedFiles inputs{{options.trials.plan, "the plan"},
                    {options.trials.scene, "the --scene file"},
                    {options.trials.waypoints, "the --waypoints file"}};
  for (const std::string& file : options.merge_inputs) {
    inputs.emplace_back(file, "a result file to merge");
  }
  if (!options.json.empty()) {
    checkOutputFile(options.json, "--json");
    refuseWritingAnInput(options.json, "--json", inputs);
  }
  if (!options.plot.empty()) {
    checkOutputFile(options.plot, "--plot");
    refuseWritingAnInput(options.plot, "--plot", inputs);
  }
  if (!options.json.empty() && !options.plot.empty() && sameFile(options.json, options.plot)) {
    throw std::invalid_argument("--json and --plot name the same file '" + options.json + "'");
  }
  if (!options.trials.trace_dir.empty()) {  // the first trial's file in it: each trial writes one
    const std::uint64_t first = options.trials.seed + static_cast<std::uint64_t>(options.trials.shard_index);
    checkOutputFile(options.trials.trace_dir / ("trial_" + std::to_string(first) + ".jsonl"), "--trace");
  }
}

int merge(const Options& options) {
  std::vector<trials::Summary> shards;
  try {
    checkOutputs(options);
    for (const std::string& file : options.merge_inputs) {
      try {
        shards.push_back(trials::Summary::fromJson(core::readJsonFile(file)));
      } catch (const std::exception& e) {
        throw std::runtime_error(file + ": " + e.what());
      }
    }
    const trials::Summary merged = trials::mergeShards(shards);
    const std::string scene = merged.options.scene.empty() ? "(the workcell's)" : merged.options.scene.string();
    std::printf("costar trials merge: %zu result file(s), %zu trials of %s on scene %s, judge '%s'\n", shards.size(),
                merged.trials.size(), merged.options.plan.c_str(), scene.c_str(), merged.options.judge.c_str());
    return report(merged, options);
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  }
}

int run(Options options) {
  if (options.trials.plan.empty() || options.trials.judge.empty()) {
    std::cerr << "error: costar trials needs a plan and --judge (or: costar trials merge RESULTS.json...)\n";
    return 2;
  }
  // Everything that can be checked is checked before the first trial: no result is lost to a
  // bad option or an output that cannot be written at the end.
  std::filesystem::path scene;
  try {
    if (!options.shard.empty()) {
      parseShard(options.shard, options.trials);
    }
    trials::checkOptions(options.trials);
    checkOutputs(options);
    scene = trials::effectiveScene(options.trials);  // the workcell's when none is given, as costar run
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  }
  std::printf("costar trials: %d trial(s) of %s on scene %s, judge '%s', seeds %llu.., %d at a time\n",
              options.trials.count, options.trials.plan.c_str(), scene.c_str(), options.trials.judge.c_str(),
              static_cast<unsigned long long>(options.trials.seed), options.trials.jobs);
  if ((options.trials.camera_move_m > 0 || options.trials.camera_turn_deg > 0) && !options.trials.calibrate) {
    // A hostile tester's --camera-move 0.05 failed every trial at DetectObjects, unexplained.
    std::printf("note: --camera-move without --calibrate: the cell believes the camera is where it was drawn, as a "
                "cell whose camera was knocked (add --calibrate to calibrate it first in each trial)\n");
  }
  if (options.trials.shard_count > 1) {
    std::printf("shard %d/%d: trials %d, %d, ... of them\n", options.trials.shard_index, options.trials.shard_count,
                options.trials.shard_index, options.trials.shard_index + options.trials.shard_count);
  }
  std::fflush(stdout);
  trials::Summary summary;
  bool trace_failed = false;
  const StopSignals signals;  // SIGINT, SIGTERM: stop launching, cancel the running trials, keep the rest
  try {
    const int total = (options.trials.count - options.trials.shard_index + options.trials.shard_count - 1) /
                      options.trials.shard_count;  // this shard's trials
    summary = trials::runTrials(
        options.trials,
        [total, &trace_failed](const trials::TrialResult& result, int done) {
          if (result.success) {
            std::printf("[%4d/%d] trial %d (seed %llu): SUCCESS in %.1f s simulated (%.1f s wall)%s%s\n", done, total,
                        result.index, static_cast<unsigned long long>(result.seed), result.cycle_time_s, result.wall_s,
                        result.reason.empty() ? "" : ": ", result.reason.c_str());
          } else {
            std::printf("[%4d/%d] trial %d (seed %llu): FAILURE at %s: %s\n", done, total, result.index,
                        static_cast<unsigned long long>(result.seed), result.failure_path.c_str(),
                        result.reason.c_str());
          }
          for (const std::string& event : result.disturbances) {
            std::printf("         disturbed: %s\n", event.c_str());
          }
          std::fflush(stdout);
          if (!result.trace_error.empty()) {
            std::cerr << "error: trial " << result.index << "'s trace: " << result.trace_error << "\n";
            trace_failed = true;
          }
        },
        &StopSignals::stopRequested());
  } catch (const bt::PlanError& error) {
    for (const auto& diagnostic : error.diagnostics()) {
      std::cerr << "error: " << diagnostic.str() << "\n";
    }
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  }
  if (summary.interrupted) {
    const int signal = StopSignals::received();
    std::cerr << "costar trials: stopped by " << StopSignals::name(signal) << ": " << summary.trials.size() << " of "
              << summary.planned << " trials finished";
    if (!summary.cancelled.empty()) {
      std::cerr << ", " << summary.cancelled.size() << " stopped midway (not counted; their traces end there)";
    }
    std::cerr << "; the results written are of the finished trials, marked \"interrupted\": true\n";
    const int code = report(summary, options, StopSignals::exitCode(signal));
    return code == 2 ? 2 : StopSignals::exitCode(signal);
  }
  return report(summary, options, trace_failed ? 2 : 0);
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
  command->add_option("plan", options->trials.plan, "plan file (required unless merging)")->check(CLI::ExistingFile);
  command->add_option("--judge", options->trials.judge, "how success is judged (see below; required)");
  command->add_option("-w,--workcell", options->trials.workcell, "simulated workcell the trials run in")
      ->capture_default_str();
  command->add_option("--scene", options->trials.scene, "scene file (default: the workcell's)")
      ->check(CLI::ExistingFile);
  command->add_option("-n,--n", options->trials.count, "number of trials")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  command->add_option("--seed", options->trials.seed, "seed of the first trial (trial i: seed + i)")
      ->check(wholeNumber())
      ->capture_default_str();
  command->add_option("-j,--jobs", options->trials.jobs, "trials run at once")
      ->check(CLI::Range(1, 64))
      ->capture_default_str();
  command->add_option("--waypoints", options->trials.waypoints, "waypoint file the plan uses (read only)")
      ->check(CLI::ExistingFile);
  command->add_option("--time-limit", options->trials.time_limit_s, "simulated seconds allowed per trial")
      ->check(numberIn(0.0, trials::kMaxTimeLimitSeconds, true, " s"))
      ->capture_default_str();
  command->add_option_function<std::string>(
      "--camera-move",
      [options](const std::string& text) {
        const auto [distance, angle] = parseCameraMove(text);
        options->trials.camera_move_m = distance;
        options->trials.camera_turn_deg = angle;
      },
      "the camera moved from its drawn mounting in each trial: DISTANCE_M,ANGLE_DEG, direction from the trial's seed");
  command->add_flag("--calibrate", options->trials.calibrate,
                    "run Calibrate in each trial's cell before the plan (as a technician would after set-up)");
  addInjectOption(command, options->trials.inject);
  command
      ->add_option("--remote", options->trials.remote,
                   "JSON file {components, domain, partition, interface}: the components served by `costar host` "
                   "in lockstep with each trial's simulation (gripper, perception; trials then run one at a time)")
      ->check(CLI::ExistingFile);
  command
      ->add_option("--disturb", options->trials.disturb,
                   "disturb the simulated world in each trial (repeatable): " + trials::disturbanceGrammar())
      ->check(CLI::Validator(
          [](std::string& text) -> std::string {
            try {
              trials::parseDisturbance(text);
            } catch (const std::invalid_argument& e) {
              return e.what();
            }
            return {};
          },
          "KIND[@grasp=N]"));
  command->add_option("--json", options->json, "write the summary and every trial as JSON")->check(aFileName());
  command
      ->add_option("--trace", options->trials.trace_dir,
                   "write every trial's status transitions to DIR/trial_SEED.jsonl (JSON lines, as costar run "
                   "--trace: the reasons of failures a retry recovered too)")
      ->check(CLI::ExistingDirectory)
      ->check(aFileName());
  command
      ->add_option("--plot", options->plot,
                   "write a PNG: success rate, failures, cycle times (and, in a scene with a workpiece, "
                   "PLOT_force.png and PLOT_coverage.png of the first trial: the pad's force, the area worked)")
      ->check(aFileName());
  command->add_option("--require", options->require, "exit 1 when the success rate is below this (0..1)")
      ->check(numberIn(0.0, 1.0, false, ""));
  command->add_option("--shard", options->shard,
                      "run only slice I of N (0 <= I < N): trials I, I+N, I+2N, ..., each with its own seed as in "
                      "one run; combine the --json files with `costar trials merge`");

  CLI::App* merge_command = command->add_subcommand(
      "merge", "Combine the --json results of shards (costar trials --shard I/N) into one summary and plot");
  merge_command->add_option("results", options->merge_inputs, "JSON files written by `costar trials --json`")
      ->required()
      ->check(CLI::ExistingFile);
  merge_command->add_option("--json", options->json, "write the merged summary as JSON")->check(aFileName());
  merge_command->add_option("--plot", options->plot, "write a PNG: success rate, failures, cycle times")
      ->check(aFileName());
  merge_command->add_option("--require", options->require, "exit 1 when the success rate is below this (0..1)")
      ->check(numberIn(0.0, 1.0, false, ""));
  merge_command->callback([options, &exit_code] { exit_code = merge(*options); });
  command->footer(
      "Judges:" + judges +
      "\nMany machines: run `costar trials PLAN --judge J -n 10000 --shard $I/100 --json r$I.json` as jobs I = 0..99 "
      "(a Slurm array, GNU parallel, Kubernetes indexed jobs), then `costar trials merge r*.json --plot trials.png`."
      "\nExit code: 0, or 1 when the success rate is below --require; 2 for an invalid plan or option (checked "
      "before the first trial) or an output (--json, --plot, a --trace file) that could not be written; 130 "
      "(SIGINT, Ctrl-C) or 143 (SIGTERM) when stopped: no trial starts after the signal, the running ones are "
      "cancelled, and --json and --plot are written for the trials that finished, marked \"interrupted\": true.");
  command->callback([options, merge_command, &exit_code] {
    if (!merge_command->parsed()) {
      exit_code = run(*options);
    }
  });
}

}  // namespace costar::cli
