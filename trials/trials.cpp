#include "trials/trials.h"

#include <unistd.h>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <fstream>
#include <regex>
#include <stdexcept>

#include "bt/builder.h"
#include "bt/executor.h"
#include "bt/plan_xml.h"
#include "bt/trace.h"
#include "core/files.h"
#include "core/json_file.h"
#include "core/parallel.h"
#include "core/paths.h"
#include "faults/injector.h"
#include "sim/simulation.h"
#include "trials/disturbance.h"
#include "trials/judge.h"
#include "trials/tool_plot.h"
#include "workcell/sim_cell_description.h"
#include "workcell/workcell.h"

namespace costar::trials {

namespace {

/// The process's resident set size in kB (Linux /proc/self/status), 0 when unknown.
long residentKilobytes() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("VmRSS:", 0) == 0) {
      return std::strtol(line.c_str() + 6, nullptr, 10);
    }
  }
  return 0;
}

std::vector<DisturbanceSpec> parseDisturbances(const std::vector<std::string>& texts) {
  std::vector<DisturbanceSpec> specs;
  for (const std::string& text : texts) {
    specs.push_back(parseDisturbance(text));
  }
  return specs;
}

/// The workcell of trial `index` (seed options.seed + index), fresh.
std::unique_ptr<workcell::Workcell> trialWorkcell(const TrialOptions& options, int index) {
  const std::uint64_t seed = options.seed + static_cast<std::uint64_t>(index);
  workcell::WorkcellOptions cell_options{.name = options.workcell,
                                         .scene = options.scene,
                                         .seed = seed,
                                         .waypoints = options.waypoints,
                                         .memory_only = true,
                                         .faults = nullptr,
                                         .remote = options.remote};
  // The faults asked for, and those the trial's disturbances need (drawn from the same seed as
  // the Disturber that runOne makes).
  std::vector<std::string> inject = options.inject;
  const Disturber disturber(parseDisturbances(options.disturb), seed);
  for (const std::string& fault : disturber.faultSpecs()) {
    inject.push_back(fault);
  }
  // Parts a disturbance adds: one spare of every class per addition, parked off the table.
  for (int i = 0; i < disturber.additions(); ++i) {
    for (const world::ObjectClass& object_class : world::loadObjectClasses(dataRoot() / "data" / "objects")) {
      cell_options.spare_parts.push_back(object_class.name);
    }
  }
  if (!inject.empty()) {
    cell_options.faults = faults::Injector::fromText(inject, seed);
  }
  if (options.camera_move_m > 0 || options.camera_turn_deg > 0) {
    cell_options.camera_move =
        workcell::WorkcellOptions::CameraMove{options.camera_move_m, options.camera_turn_deg, {}};
  }
  return workcell::makeWorkcell(cell_options);
}

/// Runs trial `index` in `built` (its fresh workcell, built by trialWorkcell) or in one it builds.
/// Once `*stop` is set it starts nothing and stops its run at the next tick.
TrialResult runOne(const TrialOptions& options, const bt::Plan& plan, const Judge& judge, int index,
                   const std::atomic<bool>* stop, std::unique_ptr<workcell::Workcell> built = nullptr) {
  TrialResult result;
  result.index = index;
  result.seed = options.seed + static_cast<std::uint64_t>(index);
  const auto stopping = [stop] { return stop != nullptr && stop->load(); };
  if (stopping()) {
    result.started = false;
    return result;
  }
  const auto wall_start = std::chrono::steady_clock::now();
  Disturber disturber(parseDisturbances(options.disturb), result.seed);
  try {
    const auto cell = built ? std::move(built) : trialWorkcell(options, index);
    sim::Simulation& simulation = *cell->simulation();
    if (options.calibrate) {
      const std::vector<sim::PartState> before = simulation.parts();
      const component::OperationResult calibrated =
          workcell::runOperation(*cell, "Calibrate", {}, std::chrono::seconds(120));
      double moved = 0.0;
      const std::vector<sim::PartState> after = simulation.parts();
      for (std::size_t i = 0; i < before.size() && i < after.size(); ++i) {
        moved = std::max(moved, (after[i].pose.translation() - before[i].pose.translation()).norm());
      }
      result.calibrate_moved_part_m = moved;
      if (calibrated.state != component::OperationState::kSuccess) {
        result.failure_path = "Calibrate";
        result.reason = calibrated.reason;
        result.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
        return result;
      }
    }
    if (stopping()) {  // the cell took a while to build: the stop came meanwhile
      result.started = false;
      return result;
    }
    const std::vector<sim::PartState> initial = simulation.parts();
    bt::Tree tree = bt::buildTree(plan, cell->nodes(), cell->clock());
    // The trace is written as the trial goes, each tick's transitions at the next tick.
    std::optional<bt::JsonLinesFileTrace> trace;
    if (!options.trace_dir.empty()) {
      trace.emplace(options.trace_dir / ("trial_" + std::to_string(result.seed) + ".jsonl"));
      tree.addObserver(&*trace);
    }
    bt::Executor executor(tree, cell->clock(), {.time_limit = checkedDuration(options.time_limit_s, "--time-limit")});
    executor.setBeforeTick([&cell, &disturber, &simulation, &trace, &executor, &stopping] {
      if (stopping()) {
        executor.requestStop();  // halts the tree: its operations are cancelled, the arm stops
      }
      if (trace) {
        trace->flush();
      }
      disturber.watch(simulation);
      cell->beforeTick();
    });
    const bt::RunResult run = executor.run();
    if (trace) {
      trace->close();
      result.trace_error = trace->error();
    }
    result.disturbances = disturber.events();
    result.cycle_time_s = toSeconds(run.elapsed);
    if (run.stopped) {
      result.interrupted = true;
    } else if (run.status != bt::Status::kSuccess) {
      result.failure_path = run.failure_path;
      result.reason = run.failure_reason;
    } else {
      simulation.stepTo(simulation.time() + checkedDuration(options.settle_s, "settle time"));
      const Verdict verdict = judge(simulation, initial);
      result.success = verdict.success;
      result.reason = verdict.reason;
      if (!verdict.success) {
        result.failure_path = "judge";
      }
    }
    if (const std::optional<sim::SeparationRecord> record = simulation.separationRecord()) {
      SeparationFigures figures;
      figures.min_separation_fast_m = record->min_separation_fast;
      figures.min_margin_fast_m = record->min_margin_fast;
      figures.violation_steps = record->violation_steps;
      figures.contact_steps = record->contact_steps;
      figures.max_contact_n = record->max_contact_force;
      figures.stopped_contact_steps = record->stopped_contact_steps;
      figures.stops = record->stops;
      figures.stopped_s = record->stopped_seconds;
      figures.collaborative_s = record->collaborative_seconds;
      figures.hand_contact_steps = record->hand_contact_steps;
      figures.max_hand_contact_n = record->max_hand_contact_force;
      result.separation = figures;
      if ((figures.violation_steps > 0 || figures.contact_steps > 0) && !result.interrupted) {
        result.success = false;
        result.failure_path = "safety";
        char text[160];
        std::snprintf(text, sizeof text,
                      "the arm moved faster than 0.25 m/s within the protective distance for %llu steps and touched "
                      "the person for %llu",
                      static_cast<unsigned long long>(figures.violation_steps),
                      static_cast<unsigned long long>(figures.contact_steps));
        result.reason = text;
      }
    }
    if (const sim::SimPowerTool* tool = simulation.powerTool();
        tool != nullptr && tool->coverage() && index == options.shard_index) {
      auto tool_trace = std::make_shared<ToolTrace>();
      tool_trace->seed = result.seed;
      tool_trace->log = tool->log();
      tool_trace->coverage = tool->coverage();
      tool_trace->disturbances = result.disturbances;
      result.tool = std::move(tool_trace);
    }
  } catch (const std::exception& e) {
    result.failure_path = "error";
    result.reason = e.what();
  }
  result.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
#if defined(__GLIBC__)
  // The trial's workcell is gone: hand the pages glibc keeps for reuse back to the system, so that
  // a long run's resident memory is what is in use, not what fragmentation left behind.
  malloc_trim(0);
#endif
  result.rss_kb = residentKilobytes();
  return result;
}

/// The fingerprint of the plan file and the files it includes, in order.
std::string planFingerprint(const bt::Plan& plan) {
  std::string text = readFile(plan.file.path);
  for (const bt::PlanFile& included : plan.included) {
    text += "\n" + readFile(included.path);
  }
  return fingerprint(text);
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

std::string shown(double value) {
  char text[64];
  std::snprintf(text, sizeof text, "%g", value);
  return text;
}

}  // namespace

void checkOptions(const TrialOptions& options) {
  if (options.workcell == "test" || options.workcell == "none") {
    throw std::invalid_argument("costar trials judges a simulated world, and the '" + options.workcell +
                                "' workcell has none (simulated cells: " + workcell::knownWorkcellNames(true) + ")");
  }
  if (options.count < 1) {
    throw std::invalid_argument("the number of trials must be at least 1, not " + std::to_string(options.count));
  }
  if (options.jobs < 1) {
    throw std::invalid_argument("the number of trials run at once must be at least 1, not " +
                                std::to_string(options.jobs));
  }
  if (!options.remote.empty() && options.jobs != 1) {
    throw std::invalid_argument("--jobs " + std::to_string(options.jobs) + " with --remote: a host serves one run at " +
                                "a time, so trials with remote components run one at a time (--jobs 1)");
  }
  if (options.shard_count < 1 || options.shard_index < 0 || options.shard_index >= options.shard_count) {
    throw std::invalid_argument("shard " + std::to_string(options.shard_index) + "/" +
                                std::to_string(options.shard_count) + ": needs 0 <= I < N");
  }
  if (options.shard_index >= options.count) {
    // A hostile tester's --shard 5/10 -n 2 ran no trial and exited 0.
    throw std::invalid_argument("--shard: slice " + std::to_string(options.shard_index) + " of " +
                                std::to_string(options.count) + " trial(s) has none (slice I runs trials I, I+N, ...)");
  }
  // nan compares false with everything: the conditions are written so that it fails them.
  if (!(options.time_limit_s > 0.0 && options.time_limit_s <= kMaxTimeLimitSeconds)) {
    throw std::invalid_argument("the time limit must be a number of simulated seconds above 0 and at most " +
                                shown(kMaxTimeLimitSeconds) + ", not " + shown(options.time_limit_s));
  }
  if (!(options.settle_s >= 0.0 && options.settle_s <= kMaxTimeLimitSeconds)) {
    throw std::invalid_argument("the settle time must be a number of simulated seconds from 0 to " +
                                shown(kMaxTimeLimitSeconds) + ", not " + shown(options.settle_s));
  }
  if (!(options.camera_move_m >= 0.0 && options.camera_move_m <= 0.5) ||
      !(options.camera_turn_deg >= 0.0 && options.camera_turn_deg <= 45.0)) {
    throw std::invalid_argument("--camera-move: must be DISTANCE_M,ANGLE_DEG from 0 to 0.5 m and 45 degrees, not " +
                                shown(options.camera_move_m) + "," + shown(options.camera_turn_deg));
  }
}

std::filesystem::path effectiveScene(const TrialOptions& options) {
  if (!options.scene.empty()) {
    return options.scene;
  }
  return workcell::loadSimCellDescription(workcell::simCellFile(options.workcell)).scene;
}

void writeJson(const Summary& summary, const std::filesystem::path& file) {
  writeOutputFile(file, summary.toJson().dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n");
}

Summary runTrials(const TrialOptions& options, const std::function<void(const TrialResult&, int)>& progress,
                  const std::atomic<bool>* stop) {
  checkOptions(options);
  const Judge judge = trials::judge(options.judge);
  parseDisturbances(options.disturb);  // a bad one is an error before any trial
  const bt::Plan plan = bt::loadPlan(options.plan);
  Summary summary;
  summary.options = options;
  summary.fingerprints["plan"] = planFingerprint(plan);
  summary.fingerprints["scene"] = fingerprint(readFile(effectiveScene(options)));
  if (!options.waypoints.empty()) {
    summary.fingerprints["waypoints"] = fingerprint(readFile(options.waypoints));
  }
  // This shard's trials: every shard_count-th index, so that slices take about as long.
  std::vector<int> indices;
  for (int index = options.shard_index; index < options.count; index += options.shard_count) {
    indices.push_back(index);
  }
  summary.planned = static_cast<int>(indices.size());
  // Validate once, before any trial, against the workcell the trials use (the faults too):
  // the first trial's, which that trial then runs in (a workcell load saved per run; nothing
  // has ticked in it: validation only reads the node models).
  std::unique_ptr<workcell::Workcell> first_cell =
      trialWorkcell(options, indices.empty() ? options.shard_index : indices.front());
  if (auto diagnostics = bt::validatePlan(plan, first_cell->nodes()); !diagnostics.empty()) {
    throw bt::PlanError(std::move(diagnostics));
  }
  // Slot 0 runs on this thread, in first_cell: a workcell shares the perception pipeline of the
  // thread that built it (workcell/sim_workcell.cpp), so it must run on that thread.
  std::vector<TrialResult> results = runIndexed(
      indices.size(), options.jobs,
      [&](std::size_t slot) {
        return runOne(options, plan, judge, indices[slot], stop, slot == 0 ? std::move(first_cell) : nullptr);
      },
      [&](const TrialResult& result, std::size_t, int done) {
        if (progress && result.started && !result.interrupted) {
          progress(result, done);
        }
      });
  // A stopped batch keeps the trials that finished; those stopped midway or never started are
  // not results.
  for (TrialResult& result : results) {
    if (result.interrupted) {
      summary.cancelled.push_back(result.index);
    }
    if (result.started && !result.interrupted) {
      summary.trials.push_back(std::move(result));
    }
  }
  summary.interrupted = stop != nullptr && stop->load();
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

std::vector<std::pair<int, long>> Summary::residentMemory() const {
  std::vector<std::pair<int, long>> samples;
  for (std::size_t i = 0; i < trials.size(); ++i) {
    if (trials[i].rss_kb > 0 && ((i + 1) % 100 == 0 || i + 1 == trials.size())) {
      samples.emplace_back(static_cast<int>(i + 1), trials[i].rss_kb);
    }
  }
  return samples;
}

double Summary::residentGrowthPercent() const {
  if (trials.size() <= 100 || trials[99].rss_kb <= 0 || trials.back().rss_kb <= 0) {
    return 0.0;
  }
  return 100.0 * static_cast<double>(trials.back().rss_kb - trials[99].rss_kb) / static_cast<double>(trials[99].rss_kb);
}

nlohmann::json Summary::toJson() const {
  nlohmann::json json;
  json["plan"] = options.plan.string();
  json["workcell"] = options.workcell;
  json["scene"] = options.scene.string();
  json["judge"] = options.judge;
  json["trials"] = trials.size();
  json["seed"] = options.seed;
  json["count"] = options.count;
  json["shard"] = {{"index", options.shard_index}, {"count", options.shard_count}};
  json["time_limit_s"] = options.time_limit_s;
  // Every option that affects outcomes, so that shards run differently are not merged.
  json["settle_s"] = options.settle_s;
  json["waypoints"] = options.waypoints.string();
  json["inject"] = options.inject;
  json["camera_move"] = {{"distance_m", options.camera_move_m}, {"angle_deg", options.camera_turn_deg}};
  json["calibrate"] = options.calibrate;
  json["fingerprints"] = fingerprints;
  if (interrupted) {
    json["interrupted"] = true;
    json["planned"] = planned;
    json["cancelled"] = cancelled;
  }
  json["successes"] = successes();
  json["success_rate"] = trials.empty() ? 0.0 : static_cast<double>(successes()) / trials.size();
  json["cycle_time_s"] = cycleTimes();
  nlohmann::json failures = nlohmann::json::array();
  for (const auto& [reason, count] : failureHistogram()) {
    failures.push_back({{"reason", reason}, {"count", count}});
  }
  json["failures"] = failures;
  if (!options.disturb.empty()) {
    json["disturb"] = options.disturb;
  }
  nlohmann::json memory = nlohmann::json::array();
  for (const auto& [count, kb] : residentMemory()) {
    memory.push_back({{"trials", count}, {"rss_kb", kb}});
  }
  json["resident_memory"] = memory;
  json["resident_growth_from_trial_100_percent"] = residentGrowthPercent();
  nlohmann::json list = nlohmann::json::array();
  for (const TrialResult& trial : trials) {
    nlohmann::json item = {{"index", trial.index},     {"seed", trial.seed},
                           {"success", trial.success}, {"cycle_time_s", trial.cycle_time_s},
                           {"wall_s", trial.wall_s},   {"rss_kb", trial.rss_kb}};
    if (!trial.disturbances.empty()) {
      item["disturbances"] = trial.disturbances;
    }
    if (trial.calibrate_moved_part_m) {
      item["calibrate_moved_part_mm"] = std::round(*trial.calibrate_moved_part_m * 1e4) / 10.0;
    }
    if (trial.separation) {
      const SeparationFigures& f = *trial.separation;
      item["separation"] = {{"min_separation_fast_m", f.min_separation_fast_m},
                            {"min_margin_fast_m", f.min_margin_fast_m},
                            {"violation_steps", f.violation_steps},
                            {"contact_steps", f.contact_steps},
                            {"max_contact_n", f.max_contact_n},
                            {"stopped_contact_steps", f.stopped_contact_steps},
                            {"stops", f.stops},
                            {"stopped_s", f.stopped_s},
                            {"collaborative_s", f.collaborative_s},
                            {"hand_contact_steps", f.hand_contact_steps},
                            {"max_hand_contact_n", f.max_hand_contact_n}};
    }
    if (!trial.success) {
      item["failure_path"] = trial.failure_path;
      item["reason"] = trial.reason;
    } else if (!trial.reason.empty()) {
      item["judged"] = trial.reason;
    }
    list.push_back(std::move(item));
  }
  json["results"] = list;
  return json;
}

namespace {

/// `json[key]` as T, or an error naming the field.
template <typename T>
T field(const nlohmann::json& json, const std::string& key, const std::string& where) {
  const auto found = json.find(key);
  if (found == json.end()) {
    throw std::runtime_error(where + ": missing field '" + key + "'");
  }
  try {
    return found->get<T>();
  } catch (const nlohmann::json::exception&) {
    throw std::runtime_error(where + ": field '" + key + "' has the wrong type (" + found->type_name() + ")");
  }
}

}  // namespace

Summary Summary::fromJson(const nlohmann::json& json) {
  if (!json.is_object()) {
    throw std::runtime_error("trial results: expected a JSON object, not " + std::string(json.type_name()));
  }
  Summary summary;
  const std::string where = "trial results";
  summary.options.plan = field<std::string>(json, "plan", where);
  summary.options.workcell = json.value("workcell", summary.options.workcell);
  summary.options.scene = field<std::string>(json, "scene", where);
  summary.options.judge = field<std::string>(json, "judge", where);
  summary.options.seed = field<std::uint64_t>(json, "seed", where);
  summary.options.count = json.contains("count") ? field<int>(json, "count", where) : field<int>(json, "trials", where);
  if (json.contains("time_limit_s")) {
    summary.options.time_limit_s = field<double>(json, "time_limit_s", where);
  }
  if (json.contains("settle_s")) {
    summary.options.settle_s = field<double>(json, "settle_s", where);
  }
  if (json.contains("waypoints")) {
    summary.options.waypoints = field<std::string>(json, "waypoints", where);
  }
  if (json.contains("inject")) {
    summary.options.inject = field<std::vector<std::string>>(json, "inject", where);
  }
  if (json.contains("camera_move")) {
    summary.options.camera_move_m = field<double>(json.at("camera_move"), "distance_m", where + ", camera_move");
    summary.options.camera_turn_deg = field<double>(json.at("camera_move"), "angle_deg", where + ", camera_move");
  }
  if (json.contains("calibrate")) {
    summary.options.calibrate = field<bool>(json, "calibrate", where);
  }
  if (json.contains("fingerprints")) {
    summary.fingerprints = field<std::map<std::string, std::string>>(json, "fingerprints", where);
  }
  if (json.contains("interrupted")) {
    summary.interrupted = field<bool>(json, "interrupted", where);
    summary.planned = json.contains("planned") ? field<int>(json, "planned", where) : 0;
    if (json.contains("cancelled")) {
      summary.cancelled = field<std::vector<int>>(json, "cancelled", where);
    }
  }
  if (json.contains("disturb")) {
    summary.options.disturb = field<std::vector<std::string>>(json, "disturb", where);
  }
  if (json.contains("shard")) {
    summary.options.shard_index = field<int>(json.at("shard"), "index", where + ", shard");
    summary.options.shard_count = field<int>(json.at("shard"), "count", where + ", shard");
  }
  const auto& results = json.find("results");
  if (results == json.end() || !results->is_array()) {
    throw std::runtime_error(where + ": missing array 'results'");
  }
  for (std::size_t i = 0; i < results->size(); ++i) {
    const nlohmann::json& item = (*results)[i];
    const std::string at = where + ", results[" + std::to_string(i) + "]";
    if (!item.is_object()) {
      throw std::runtime_error(at + ": expected an object");
    }
    TrialResult trial;
    trial.index = field<int>(item, "index", at);
    trial.seed = field<std::uint64_t>(item, "seed", at);
    trial.success = field<bool>(item, "success", at);
    trial.cycle_time_s = field<double>(item, "cycle_time_s", at);
    trial.wall_s = item.value("wall_s", 0.0);
    trial.rss_kb = item.value("rss_kb", 0L);
    if (item.contains("disturbances")) {
      trial.disturbances = field<std::vector<std::string>>(item, "disturbances", at);
    }
    if (item.contains("calibrate_moved_part_mm") && item["calibrate_moved_part_mm"].is_number()) {
      trial.calibrate_moved_part_m = item["calibrate_moved_part_mm"].get<double>() / 1000.0;
    }
    if (item.contains("separation")) {
      const nlohmann::json& f = item.at("separation");
      const std::string in = at + ", separation";
      SeparationFigures figures;
      figures.min_separation_fast_m = field<double>(f, "min_separation_fast_m", in);
      figures.min_margin_fast_m = field<double>(f, "min_margin_fast_m", in);
      figures.violation_steps = field<std::uint64_t>(f, "violation_steps", in);
      figures.contact_steps = field<std::uint64_t>(f, "contact_steps", in);
      figures.max_contact_n = field<double>(f, "max_contact_n", in);
      figures.stopped_contact_steps = field<std::uint64_t>(f, "stopped_contact_steps", in);
      figures.stops = field<int>(f, "stops", in);
      figures.stopped_s = field<double>(f, "stopped_s", in);
      // Written since the hand-over's figures were recorded; older files lack them.
      if (f.contains("collaborative_s")) {
        figures.collaborative_s = field<double>(f, "collaborative_s", in);
        figures.hand_contact_steps = field<std::uint64_t>(f, "hand_contact_steps", in);
        figures.max_hand_contact_n = field<double>(f, "max_hand_contact_n", in);
      }
      trial.separation = figures;
    }
    if (!trial.success) {
      trial.failure_path = field<std::string>(item, "failure_path", at);
      trial.reason = field<std::string>(item, "reason", at);
    } else if (item.contains("judged")) {
      trial.reason = field<std::string>(item, "judged", at);
    }
    summary.trials.push_back(std::move(trial));
  }
  return summary;
}

Summary mergeShards(const std::vector<Summary>& shards) {
  if (shards.empty()) {
    throw std::runtime_error("no trial results to merge");
  }
  const TrialOptions& first = shards.front().options;
  Summary merged;
  merged.options = first;
  merged.options.shard_index = 0;
  merged.options.shard_count = 1;
  merged.fingerprints = shards.front().fingerprints;
  merged.trials.resize(static_cast<std::size_t>(first.count));
  std::vector<bool> seen(static_cast<std::size_t>(first.count), false);
  for (std::size_t s = 0; s < shards.size(); ++s) {
    const TrialOptions& options = shards[s].options;
    if (shards[s].interrupted) {
      throw std::runtime_error("results " + std::to_string(s + 1) + " are of an interrupted run (" +
                               std::to_string(shards[s].trials.size()) + " of " + std::to_string(shards[s].planned) +
                               " trials finished): run that shard again");
    }
    const auto differs = [&](const std::string& what, const std::string& a, const std::string& b) {
      if (a != b) {
        throw std::runtime_error("results " + std::to_string(s + 1) + " are of another batch: " + what + " '" + b +
                                 "', not '" + a + "' as in results 1");
      }
    };
    const auto list = [](const std::vector<std::string>& items) { return nlohmann::json(items).dump(); };
    differs("plan", first.plan.string(), options.plan.string());
    differs("workcell", first.workcell, options.workcell);
    differs("scene", first.scene.string(), options.scene.string());
    differs("judge", first.judge, options.judge);
    differs("first seed", std::to_string(first.seed), std::to_string(options.seed));
    differs("trial count", std::to_string(first.count), std::to_string(options.count));
    differs("--time-limit", shown(first.time_limit_s), shown(options.time_limit_s));
    differs("settle time", shown(first.settle_s), shown(options.settle_s));
    differs("--waypoints", first.waypoints.string(), options.waypoints.string());
    differs("--inject", list(first.inject), list(options.inject));
    differs("--disturb", list(first.disturb), list(options.disturb));
    differs("--camera-move", shown(first.camera_move_m) + "," + shown(first.camera_turn_deg),
            shown(options.camera_move_m) + "," + shown(options.camera_turn_deg));
    differs("--calibrate", first.calibrate ? "on" : "off", options.calibrate ? "on" : "off");
    for (const char* file : {"plan", "scene", "waypoints"}) {
      const auto value = [file](const Summary& summary) {
        const auto found = summary.fingerprints.find(file);
        return found == summary.fingerprints.end() ? std::string("(none)") : found->second;
      };
      differs(std::string("the ") + file + " file's contents (fingerprint)", value(shards.front()), value(shards[s]));
    }
    for (const TrialResult& trial : shards[s].trials) {
      if (trial.index < 0 || trial.index >= first.count) {
        throw std::runtime_error("results " + std::to_string(s + 1) + ": trial " + std::to_string(trial.index) +
                                 " is outside 0.." + std::to_string(first.count - 1));
      }
      if (seen[static_cast<std::size_t>(trial.index)]) {
        throw std::runtime_error("trial " + std::to_string(trial.index) + " appears twice (results " +
                                 std::to_string(s + 1) + ")");
      }
      seen[static_cast<std::size_t>(trial.index)] = true;
      merged.trials[static_cast<std::size_t>(trial.index)] = trial;
    }
  }
  std::string missing;
  int missing_count = 0;
  for (std::size_t i = 0; i < seen.size(); ++i) {
    if (!seen[i] && ++missing_count <= 10) {
      missing += (missing.empty() ? "" : ", ") + std::to_string(i);
    }
  }
  if (missing_count > 0) {
    throw std::runtime_error(std::to_string(missing_count) + " of " + std::to_string(first.count) +
                             " trials are missing (a shard not merged?): " + missing +
                             (missing_count > 10 ? ", ..." : ""));
  }
  return merged;
}

std::string Summary::text() const {
  char line[256];
  std::string out;
  if (options.shard_count > 1) {
    std::snprintf(line, sizeof line, "shard %d/%d (trials %d, %d, ... of %d): ", options.shard_index,
                  options.shard_count, options.shard_index, options.shard_index + options.shard_count, options.count);
    out += line;
  }
  if (interrupted) {
    std::snprintf(line, sizeof line, "INTERRUPTED: %zu of %d trials finished (%zu stopped midway, not counted)\n",
                  trials.size(), planned, cancelled.size());
    out += line;
  }
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
  if (!options.disturb.empty()) {
    std::string kinds;
    for (const std::string& d : options.disturb) {
      kinds += (kinds.empty() ? "" : ", ") + d;
    }
    // A trial counts as disturbed when one of its disturbances was applied.
    const auto applied = [](const std::string& event) { return event.find(": no") == std::string::npos; };
    const auto disturbed = std::count_if(trials.begin(), trials.end(), [&](const TrialResult& trial) {
      return std::any_of(trial.disturbances.begin(), trial.disturbances.end(), applied);
    });
    std::snprintf(line, sizeof line, "disturbed (%s): %zu of %zu trials\n", kinds.c_str(),
                  static_cast<std::size_t>(disturbed), trials.size());
    out += line;
  }
  std::size_t with_person = 0;
  std::uint64_t violations = 0;
  std::uint64_t contacts = 0;
  std::uint64_t stopped_contacts = 0;
  double margin = 1e9;
  double collaborative_s = 0.0;
  std::uint64_t hand_contacts = 0;
  double hand_force = 0.0;
  for (const TrialResult& trial : trials) {
    if (trial.separation) {
      ++with_person;
      collaborative_s += trial.separation->collaborative_s;
      hand_contacts += trial.separation->hand_contact_steps;
      hand_force = std::max(hand_force, trial.separation->max_hand_contact_n);
      violations += trial.separation->violation_steps;
      contacts += trial.separation->contact_steps;
      stopped_contacts += trial.separation->stopped_contact_steps;
      margin = std::min(margin, trial.separation->min_margin_fast_m);
    }
  }
  if (with_person > 0) {
    std::snprintf(line, sizeof line,
                  "a person in %zu trials: %llu steps within the protective distance while fast, %llu touching the "
                  "person while moving (%llu with the arm stopped); ",
                  with_person, static_cast<unsigned long long>(violations), static_cast<unsigned long long>(contacts),
                  static_cast<unsigned long long>(stopped_contacts));
    out += line;
    if (margin < 1e9) {
      std::snprintf(line, sizeof line, "smallest margin over it %.3f m\n", margin);
      out += line;
    } else {
      out += "the arm never moved faster than 0.25 m/s\n";
    }
    if (collaborative_s > 0.0) {
      std::snprintf(line, sizeof line,
                    "collaborative mode %.0f s in all: %llu steps touching the person's hand while moving, at most "
                    "%.1f N\n",
                    collaborative_s, static_cast<unsigned long long>(hand_contacts), hand_force);
      out += line;
    }
  }
  if (const auto memory = residentMemory(); memory.size() > 1) {
    out += "resident memory (MB) after trials:";
    for (const auto& [count, kb] : memory) {
      std::snprintf(line, sizeof line, " %d: %.1f;", count, kb / 1024.0);
      out += line;
    }
    std::snprintf(line, sizeof line, " growth from trial 100: %+.2f %%\n", residentGrowthPercent());
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
