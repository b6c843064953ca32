// fault_campaign: the paper's UR5 plans with injected faults, judged from outside
// (trials/fault_campaign.h). Run from the repository root:
//   nice -n 10 build/trials/fault_campaign -n 1000 -j 2 --json faults.json
// Exit code: 0 when every fault that took effect stopped the task in time, 1 when one did not,
// 2 for a bad option or file, or an output that could not be written.

#include <CLI/CLI.hpp>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <optional>

#include "cli/number_options.h"
#include "core/clock.h"
#include "core/files.h"
#include "trials/fault_campaign.h"
#include "workcell/workcell.h"

namespace {

int summarize(const std::string& file) {
  try {
    std::vector<std::string> notes;
    const costar::trials::CampaignSummary summary = costar::trials::readJsonLines(file, notes);
    for (const std::string& note : notes) {
      std::fprintf(stderr, "note: %s\n", note.c_str());
    }
    std::printf("%zu runs from %s\n%s", summary.trials.size(), file.c_str(), summary.text().c_str());
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  }
}

}  // namespace

int main(int argc, char** argv) {
  // A standard output nobody reads any more (| head) makes writes fail instead of ending the
  // campaign before --json is written.
  std::signal(SIGPIPE, SIG_IGN);
  costar::trials::CampaignOptions options;
  options.count = 1000;
  std::string json;
  CLI::App app("Runs the paper's three plans with one injected fault each and judges every run");
  app.add_option("-n,--n", options.count, "runs (faults)")->check(CLI::Range(1, 1000000))->capture_default_str();
  app.add_option("--seed", options.seed, "seed of the first run (run i: seed + i)")
      ->check(costar::cli::wholeNumber())
      ->capture_default_str();
  app.add_option("-j,--jobs", options.jobs, "runs at once")->check(CLI::Range(1, 64))->capture_default_str();
  app.add_option("--window", options.window_s, "timed faults: moment in [0, WINDOW) simulated s")
      ->check(costar::cli::numberIn(0.0, costar::kMaxDurationSeconds, true, " s"))
      ->capture_default_str();
  app.add_option("-w,--workcell", options.workcell,
                 "a simulated workcell (" + costar::workcell::knownWorkcellNames(true) +
                     ": `costar workcells`), or test (components only)")
      ->capture_default_str();
  std::vector<std::string> plans;
  app.add_option("--plan", plans, "plan(s) to run in place of the paper's three tasks");
  app.add_option("--fault", options.faults, "KIND:TARGET to cycle through, or KIND:TARGET@WHEN (default: all)");
  app.add_option("--waypoints", options.waypoints, "the cell's waypoint file (checked unchanged)")
      ->check(CLI::ExistingFile);
  app.add_option("--json", json, "write every run as JSON");
  std::string jsonl;
  app.add_option("--jsonl", jsonl, "append each run as a JSON line as it ends (survives an interrupted campaign)");
  std::string summarize_file;
  app.add_option("--summarize", summarize_file, "print the table of a --jsonl file (an interrupted campaign) and exit")
      ->check(CLI::ExistingFile);
  app.footer(
      "Exit code: 0 every fault that took effect stopped the task in time, 1 one did not, 2 a bad option or file, or "
      "an output that could not be written.");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& error) {
    const int code = app.exit(error);  // prints the problem (or the help)
    return code == 0 ? 0 : 2;
  }
  if (!summarize_file.empty()) {
    return summarize(summarize_file);
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
  // The outputs are checked before the first run: no campaign is lost to a path that cannot be
  // written at the end.
  std::optional<costar::AppendingFile> lines;
  try {
    if (!json.empty()) {
      costar::checkOutputFile(json, "--json");
    }
    if (!jsonl.empty()) {
      lines.emplace(jsonl, costar::AppendingFile::Mode::kAppend);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  }
  bool lines_failed = false;
  try {
    const auto summary = costar::trials::runCampaign(options, [&](const auto& trial, int done) {
      if (lines && !lines_failed) {
        try {
          lines->append(trial.toJson().dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n");
        } catch (const std::exception& e) {
          // The campaign goes on (its --json may still be written); the error is said at once
          // and in the exit code.
          std::fprintf(stderr, "error: %s; --jsonl holds the runs before this one\n", e.what());
          lines_failed = true;
        }
      }
      std::printf("[%4d/%d] %-26s %-34s %-13s %6.3f s  %s%s%s\n", done, options.count, trial.task.c_str(),
                  trial.fault.c_str(), trial.outcome.c_str(), trial.latency_s, trial.failure_path.c_str(),
                  trial.reason.empty() ? "" : ": ", trial.reason.c_str());
      std::fflush(stdout);
    });
    std::printf("\n%s", summary.text().c_str());
    int code = 0;
    for (const auto& trial : summary.trials) {
      const bool excused =
          trial.outcome == "not-due" || trial.outcome == "no-effect" || trial.outcome == "recovered" || trial.met();
      if (!excused) {
        code = 1;
      }
    }
    if (lines && !lines_failed) {
      try {
        lines->close();
      } catch (const std::exception& e) {
        std::fprintf(stderr, "error: %s\n", e.what());
        lines_failed = true;
      }
    }
    if (!json.empty()) {
      try {
        costar::writeOutputFile(json,
                                summary.toJson().dump(1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n");
        std::printf("wrote %s\n", json.c_str());
      } catch (const std::exception& e) {
        std::fprintf(stderr, "error: %s\n", e.what());
        code = 2;
      }
    }
    return lines_failed ? 2 : code;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  }
}
