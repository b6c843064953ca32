#include "trials/trials.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <mutex>
#include <regex>
#include <stdexcept>
#include <thread>

#include "bt/builder.h"
#include "bt/executor.h"
#include "bt/plan_xml.h"
#include "sim/simulation.h"
#include "trials/judge.h"
#include "workcell/workcell.h"

namespace costar::trials {

namespace {

TrialResult runOne(const TrialOptions& options, const bt::Plan& plan, const Judge& judge, int index) {
  TrialResult result;
  result.index = index;
  result.seed = options.seed + static_cast<std::uint64_t>(index);
  const auto wall_start = std::chrono::steady_clock::now();
  try {
    workcell::WorkcellOptions cell_options{.name = "ur5-sim",
                                           .scene = options.scene,
                                           .seed = result.seed,
                                           .waypoints = options.waypoints,
                                           .memory_only = true};
    if (options.camera_move_m > 0 || options.camera_turn_deg > 0) {
      cell_options.camera_move = workcell::WorkcellOptions::CameraMove{options.camera_move_m, options.camera_turn_deg, {}};
    }
    const auto cell = workcell::makeWorkcell(cell_options);
    sim::Simulation& simulation = *cell->simulation();
    if (options.calibrate) {
      const component::OperationResult calibrated =
          workcell::runOperation(*cell, "Calibrate", {}, std::chrono::seconds(120));
      if (calibrated.state != component::OperationState::kSuccess) {
        result.failure_path = "Calibrate";
        result.reason = calibrated.reason;
        result.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
        return result;
      }
    }
    const std::vector<sim::PartState> initial = simulation.parts();
    bt::Tree tree = bt::buildTree(plan, cell->nodes(), cell->clock());
    bt::Executor executor(tree, cell->clock(), {.time_limit = fromSeconds(options.time_limit_s)});
    executor.setBeforeTick([&cell] { cell->beforeTick(); });
    const bt::RunResult run = executor.run();
    result.cycle_time_s = toSeconds(run.elapsed);
    if (run.status != bt::Status::kSuccess) {
      result.failure_path = run.failure_path;
      result.reason = run.failure_reason;
    } else {
      simulation.stepTo(simulation.time() + fromSeconds(options.settle_s));
      const Verdict verdict = judge(simulation, initial);
      result.success = verdict.success;
      if (!verdict.success) {
        result.failure_path = "judge";
        result.reason = verdict.reason;
      }
    }
  } catch (const std::exception& e) {
    result.failure_path = "error";
    result.reason = e.what();
  }
  result.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  return result;
}

double percentile(std::vector<double> values, double p) {
  if (values.empty()) {
    return 0.0;
  }
  std::sort(values.begin(), values.end());
  const double position = p * (values.size() - 1);
  const auto low = static_cast<std::size_t>(std::floor(position));
  const auto high = static_cast<std::size_t>(std::ceil(position));
  return values[low] + (values[high] - values[low]) * (position - low);
}

}  // namespace

Summary runTrials(const TrialOptions& options, const std::function<void(const TrialResult&, int)>& progress) {
  const Judge judge = trials::judge(options.judge);
  const bt::Plan plan = bt::loadPlan(options.plan);
  {
    // Validate once, before any trial, against the workcell the trials use.
    const auto cell = workcell::makeWorkcell({.name = "ur5-sim",
                                              .scene = options.scene,
                                              .seed = options.seed,
                                              .waypoints = options.waypoints,
                                              .memory_only = true});
    if (auto diagnostics = bt::validatePlan(plan, cell->nodes()); !diagnostics.empty()) {
      throw bt::PlanError(std::move(diagnostics));
    }
  }
  Summary summary;
  summary.options = options;
  summary.trials.resize(static_cast<std::size_t>(options.count));
  std::atomic<int> next{0};
  int done = 0;
  std::mutex mutex;
  const auto worker = [&] {
    for (int index = next++; index < options.count; index = next++) {
      TrialResult result = runOne(options, plan, judge, index);
      std::lock_guard lock(mutex);
      summary.trials[static_cast<std::size_t>(index)] = result;
      ++done;
      if (progress) {
        progress(result, done);
      }
    }
  };
  std::vector<std::thread> threads;
  for (int j = 1; j < std::max(1, options.jobs); ++j) {
    threads.emplace_back(worker);
  }
  worker();
  for (auto& thread : threads) {
    thread.join();
  }
  return summary;
}

int Summary::successes() const {
  return static_cast<int>(std::count_if(trials.begin(), trials.end(), [](const TrialResult& t) { return t.success; }));
}

std::vector<std::pair<std::string, int>> Summary::failureHistogram() const {
  static const std::regex kNumber(R"(-?\d+(\.\d+)?)");
  std::map<std::string, int> counts;
  for (const TrialResult& trial : trials) {
    if (!trial.success) {
      ++counts[std::regex_replace(trial.failure_path + ": " + trial.reason, kNumber, "#")];
    }
  }
  std::vector<std::pair<std::string, int>> histogram(counts.begin(), counts.end());
  std::stable_sort(histogram.begin(), histogram.end(),
                   [](const auto& a, const auto& b) { return a.second > b.second; });
  return histogram;
}

std::map<std::string, double> Summary::cycleTimes() const {
  std::vector<double> times;
  for (const TrialResult& trial : trials) {
    if (trial.success) {
      times.push_back(trial.cycle_time_s);
    }
  }
  double mean = 0.0;
  for (const double t : times) {
    mean += t / static_cast<double>(times.size());
  }
  return {{"min", percentile(times, 0.0)},
          {"median", percentile(times, 0.5)},
          {"p95", percentile(times, 0.95)},
          {"max", percentile(times, 1.0)},
          {"mean", mean}};
}

nlohmann::json Summary::toJson() const {
  nlohmann::json json;
  json["plan"] = options.plan.string();
  json["scene"] = options.scene.string();
  json["judge"] = options.judge;
  json["trials"] = trials.size();
  json["seed"] = options.seed;
  json["successes"] = successes();
  json["success_rate"] = trials.empty() ? 0.0 : static_cast<double>(successes()) / trials.size();
  json["cycle_time_s"] = cycleTimes();
  nlohmann::json failures = nlohmann::json::array();
  for (const auto& [reason, count] : failureHistogram()) {
    failures.push_back({{"reason", reason}, {"count", count}});
  }
  json["failures"] = failures;
  nlohmann::json list = nlohmann::json::array();
  for (const TrialResult& trial : trials) {
    nlohmann::json item = {{"index", trial.index},
                           {"seed", trial.seed},
                           {"success", trial.success},
                           {"cycle_time_s", trial.cycle_time_s},
                           {"wall_s", trial.wall_s}};
    if (!trial.success) {
      item["failure_path"] = trial.failure_path;
      item["reason"] = trial.reason;
    }
    list.push_back(std::move(item));
  }
  json["results"] = list;
  return json;
}

std::string Summary::text() const {
  char line[256];
  std::string out;
  std::snprintf(line, sizeof line, "%d of %zu trials succeeded (%.1f %%)\n", successes(), trials.size(),
                trials.empty() ? 0.0 : 100.0 * successes() / trials.size());
  out += line;
  const auto times = cycleTimes();
  if (successes() > 0) {
    std::snprintf(line, sizeof line,
                  "cycle time (simulated s): median %.1f, 95th percentile %.1f, min %.1f, max %.1f\n",
                  times.at("median"), times.at("p95"), times.at("min"), times.at("max"));
    out += line;
  }
  const auto histogram = failureHistogram();
  if (!histogram.empty()) {
    out += "failures:\n";
    for (const auto& [reason, count] : histogram) {
      std::snprintf(line, sizeof line, "  %4d  ", count);
      out += line + reason + "\n";
    }
  }
  return out;
}

}  // namespace costar::trials
