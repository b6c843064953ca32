// fault_campaign: the paper's UR5 plans with injected faults, judged from outside
// (faults/campaign.h). Run from the repository root:
//   nice -n 10 build/faults/fault_campaign -n 1000 -j 2 --json faults.json
// Exit code: 0 when every fault that took effect stopped the task in time, else 1.

#include <CLI/CLI.hpp>
#include <cstdio>
#include <cstdlib>
#include <fstream>

#include "faults/campaign.h"

int main(int argc, char** argv) {
  costar::faults::CampaignOptions options;
  options.count = 1000;
  std::string json;
  CLI::App app("Runs the paper's three plans with one injected fault each and judges every run");
  app.add_option("-n,--n", options.count, "runs (faults)")->check(CLI::Range(1, 1000000))->capture_default_str();
  app.add_option("--seed", options.seed, "seed of the first run (run i: seed + i)")->capture_default_str();
  app.add_option("-j,--jobs", options.jobs, "runs at once")->check(CLI::Range(1, 64))->capture_default_str();
  app.add_option("--window", options.window_s, "timed faults: moment in [0, WINDOW) simulated s")
      ->capture_default_str();
  app.add_option("-w,--workcell", options.workcell,
                 "a simulated workcell (ur5-sim, iiwa-sim, iiwa-3f-sim: `costar workcells`), or test (components only)")
      ->capture_default_str();
  std::vector<std::string> plans;
  app.add_option("--plan", plans, "plan(s) to run in place of the paper's three tasks");
  app.add_option("--fault", options.faults, "KIND:TARGET to cycle through, or KIND:TARGET@WHEN (default: all)");
  app.add_option("--waypoints", options.waypoints, "the cell's waypoint file (checked unchanged)")
      ->check(CLI::ExistingFile);
  app.add_option("--json", json, "write every run as JSON");
  std::string jsonl;
  app.add_option("--jsonl", jsonl, "append each run as a JSON line as it ends (survives an interrupted campaign)");
  std::string summarize;
  app.add_option("--summarize", summarize, "print the table of a --jsonl file (an interrupted campaign) and exit")
      ->check(CLI::ExistingFile);
  CLI11_PARSE(app, argc, argv);
  if (!summarize.empty()) {
    costar::faults::CampaignSummary summary;
    std::ifstream in(summarize);
    for (std::string line; std::getline(in, line);) {
      const auto j = nlohmann::json::parse(line);
      costar::faults::FaultTrial t;
      t.index = j.at("index");
      t.seed = j.at("seed");
      t.task = j.at("task");
      t.fault = j.at("fault");
      t.outcome = j.at("outcome");
      t.failure_path = j.at("failure_path");
      t.reason = j.at("reason");
      t.due_s = j.at("due_s");
      t.effect_s = j.at("effect_s");
      t.end_s = j.at("end_s");
      t.latency_s = j.at("latency_s");
      t.rest_after_s = j.at("rest_after_s");
      t.final_speed = j.at("final_speed");
      t.waypoints_intact = j.at("waypoints_intact");
      t.wall_s = j.at("wall_s");
      summary.trials.push_back(std::move(t));
    }
    std::printf("%zu runs from %s\n%s", summary.trials.size(), summarize.c_str(), summary.text().c_str());
    return 0;
  }
  if (!plans.empty()) {
    options.tasks.clear();
    for (const std::string& plan : plans) {
      options.tasks.push_back({std::filesystem::path(plan).stem().string(), plan, 1});
    }
  }
  // Whatever the cell would keep goes to a scratch state directory, never the user's.
  if (std::getenv("XDG_STATE_HOME") == nullptr) {
    ::setenv("XDG_STATE_HOME", "/tmp/costar-fault-campaign-state", 1);
  }
  std::ofstream lines;
  if (!jsonl.empty()) {
    lines.open(jsonl, std::ios::app);
  }
  try {
    const auto summary = costar::faults::runCampaign(options, [&](const auto& trial, int done) {
      if (lines.is_open()) {
        costar::faults::CampaignSummary one;
        one.trials = {trial};
        lines << one.toJson()["trials"][0].dump() << std::endl;
      }
      std::printf("[%4d/%d] %-26s %-34s %-13s %6.3f s  %s%s%s\n", done, options.count, trial.task.c_str(),
                  trial.fault.c_str(), trial.outcome.c_str(), trial.latency_s, trial.failure_path.c_str(),
                  trial.reason.empty() ? "" : ": ", trial.reason.c_str());
      std::fflush(stdout);
    });
    std::printf("\n%s", summary.text().c_str());
    if (!json.empty()) {
      std::ofstream(json) << summary.toJson().dump(1) << "\n";
    }
    for (const auto& trial : summary.trials) {
      const bool excused =
          trial.outcome == "not-due" || trial.outcome == "no-effect" || trial.outcome == "recovered" || trial.met();
      if (!excused) {
        return 1;
      }
    }
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  }
}
