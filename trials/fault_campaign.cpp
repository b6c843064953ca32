#include "trials/fault_campaign.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <random>
#include <stdexcept>

#include "arm/waypoints.h"
#include "bt/builder.h"
#include "bt/executor.h"
#include "bt/plan_xml.h"
#include "core/clock.h"
#include "core/files.h"
#include "core/json_file.h"
#include "core/parallel.h"
#include "core/paths.h"
#include "faults/injector.h"
#include "sim/simulation.h"
#include "workcell/workcell.h"

namespace costar::trials {

namespace {

double largestSpeed(const sim::Simulation& simulation) {
  double largest = 0.0;
  for (const double v : simulation.armVelocities()) {
    largest = std::max(largest, std::isfinite(v) ? std::abs(v) : 1e9);
  }
  return largest;
}

double percentile(std::vector<double> values, double p) {
  if (values.empty()) {
    return 0.0;
  }
  std::sort(values.begin(), values.end());
  const double position = p * static_cast<double>(values.size() - 1);
  const auto low = static_cast<std::size_t>(std::floor(position));
  const auto high = static_cast<std::size_t>(std::ceil(position));
  return values[low] + (values[high] - values[low]) * (position - low);
}

/// The spec with its moment: camera faults at a frame the plan captures, others at a time; a
/// spec that names its moment (KIND:TARGET@WHEN) keeps it.
std::string withMoment(const std::string& fault, const CampaignOptions& options, const CampaignTask& task,
                       std::uint64_t seed) {
  if (fault.find('@') != std::string::npos) {
    return fault;
  }
  if (fault.find(":camera") != std::string::npos) {
    std::mt19937_64 random(seed ^ 0x9e3779b97f4a7c15ULL);
    const int frames = std::max(1, options.frames_per_detection * task.detections);
    return fault + "@op=" + std::to_string(std::uniform_int_distribution<int>(1, frames)(random));
  }
  char window[32];
  std::snprintf(window, sizeof window, "%gs", std::min(options.window_s, task.window_s));
  return fault + "@random=" + window;
}

FaultTrial runOne(const CampaignOptions& options, const CampaignTask& task, const bt::Plan& plan,
                  const std::string& fault, const std::string& waypoints_before, int index) {
  FaultTrial trial;
  trial.index = index;
  trial.seed = options.seed + static_cast<std::uint64_t>(index);
  trial.task = task.name;
  trial.fault = withMoment(fault, options, task, trial.seed);
  const auto wall_start = std::chrono::steady_clock::now();
  try {
    auto injector = faults::Injector::fromText({trial.fault}, trial.seed);
    const auto cell = workcell::makeWorkcell(
        {.name = options.workcell,
         .scene = options.scene.empty() ? dataRoot() / "sim/scenes/assembly.json" : options.scene,
         .seed = trial.seed,
         .waypoints = options.waypoints,
         .memory_only = options.waypoints.empty(),
         .faults = injector});
    sim::Simulation* simulation = cell->simulation();
    auto& clock = dynamic_cast<SimClock&>(cell->clock());
    bt::Tree tree = bt::buildTree(plan, cell->nodes(), cell->clock());
    bt::Executor executor(tree, cell->clock(), {.time_limit = fromSeconds(options.time_limit_s)});
    executor.setBeforeTick([&cell] { cell->beforeTick(); });
    const TimePoint start = clock.now();
    const bt::RunResult run = executor.run();
    const TimePoint end = start + run.elapsed;
    trial.end_s = toSeconds(end);
    const faults::FaultRecord& record = injector->records().front();
    if (record.activated) {
      trial.due_s = toSeconds(*record.activated);
    }
    if (record.first_effect) {
      trial.effect_s = toSeconds(*record.first_effect);
      trial.latency_s = trial.end_s - trial.effect_s;
    }
    // The arm after the run, from the simulator's true state.
    for (TimePoint t = clock.now(); simulation != nullptr && clock.now() < end + fromSeconds(options.settle_s);) {
      t += std::chrono::milliseconds(10);
      clock.advanceTo(t);
      if (trial.rest_after_s < 0 && largestSpeed(*simulation) < options.rest_speed) {
        trial.rest_after_s = toSeconds(clock.now() - end);
      } else if (largestSpeed(*simulation) >= options.rest_speed) {
        trial.rest_after_s = -1;  // moving again
      }
    }
    trial.final_speed = simulation != nullptr ? largestSpeed(*simulation) : 0.0;
    if (!options.waypoints.empty()) {
      try {
        trial.waypoints_intact = readFile(options.waypoints) == waypoints_before;
        arm::WaypointStore(options.waypoints, /*persist=*/false).all();
      } catch (const std::exception&) {
        trial.waypoints_intact = false;
      }
    }
    trial.failure_path = run.failure_path;
    trial.reason = run.failure_reason;
    const bool timed_out = run.status != bt::Status::kSuccess && run.elapsed >= fromSeconds(options.time_limit_s);
    if (timed_out) {
      trial.outcome = "hang";
    } else if (run.status == bt::Status::kSuccess) {
      trial.outcome = !record.activated      ? "not-due"
                      : !record.first_effect ? "no-effect"
                      : record.spec.kind == faults::FaultKind::kThrow && record.spec.target != "arm-driver" &&
                              record.spec.target != "gripper-driver" && record.spec.target != "camera"
                          ? "recovered"
                          : "missed";
    } else if (!record.first_effect) {
      trial.outcome = "other-failure";
    } else if (trial.failure_path.empty() || trial.reason.empty()) {
      trial.outcome = "no-reason";
    } else if (trial.latency_s > options.deadline_s) {
      trial.outcome = "late";
    } else if (trial.final_speed >= options.rest_speed) {
      trial.outcome = "not-at-rest";
    } else if (!trial.waypoints_intact) {
      trial.outcome = "lost-data";
    } else {
      trial.outcome = "stopped";
    }
  } catch (const std::exception& e) {
    trial.outcome = "error";
    trial.reason = e.what();
  }
  trial.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  return trial;
}

}  // namespace

std::vector<CampaignTask> paperTasks() {
  return {{"pick_up_node", dataRoot() / "examples/ur5/pick_up_node.xml", 1, 5.5},
          {"move_nodes_right_to_left", dataRoot() / "examples/ur5/move_nodes_right_to_left.xml", 2},
          {"assemble_structure", dataRoot() / "examples/ur5/assemble_structure.xml", 3}};
}

std::vector<std::string> allFaults() {
  std::vector<std::string> faults;
  for (const char* kind : {"throw", "hang", "nan"}) {
    faults.push_back(std::string(kind) + ":arm-driver");
    faults.push_back(std::string(kind) + ":gripper-driver");
  }
  for (const char* kind : {"throw", "hang", "empty-frame", "nan-frame"}) {
    faults.push_back(std::string(kind) + ":camera");
  }
  for (const char* component : {"arm", "gripper", "perception", "smartmove", "predicator", "workcell"}) {
    for (const char* kind : {"throw", "hang", "die"}) {
      // The paper's plans call no operation of the predicator or the fixed frames: a throw
      // (from a start or poll) could never take effect there.
      if (std::string(kind) != "throw" ||
          (std::string(component) != "predicator" && std::string(component) != "workcell")) {
        faults.push_back(std::string(kind) + ":" + component);
      }
    }
  }
  return faults;
}

std::vector<std::string> testCellFaults() {
  std::vector<std::string> faults;
  for (const char* component : {"test_logger", "test_actions", "test_counter", "test_arm"}) {
    for (const char* kind : {"throw", "hang", "die"}) {
      faults.push_back(std::string(kind) + ":" + component);
    }
  }
  return faults;
}

void checkOptions(const CampaignOptions& options) {
  if (options.count < 1) {
    throw std::invalid_argument("-n: the number of runs must be at least 1, not " + std::to_string(options.count));
  }
  if (options.jobs < 1) {
    throw std::invalid_argument("--jobs: must be at least 1, not " + std::to_string(options.jobs));
  }
  if (options.tasks.empty()) {
    throw std::invalid_argument("no plan to run");
  }
  checkedDuration(options.window_s, "--window");
  checkedDuration(options.deadline_s, "deadline");
  checkedDuration(options.settle_s, "settle time");
  checkedDuration(options.time_limit_s, "time limit");
  const auto positive = [](double value, const char* what) {
    if (!(value > 0.0) || !std::isfinite(value)) {
      char text[160];
      std::snprintf(text, sizeof text, "%s: must be a finite number above 0, not %g", what, value);
      throw std::invalid_argument(text);
    }
  };
  positive(options.window_s, "--window");
  positive(options.time_limit_s, "time limit");
  positive(options.rest_speed, "rest speed");
  if (options.frames_per_detection < 1) {
    throw std::invalid_argument("frames per detection: must be at least 1, not " +
                                std::to_string(options.frames_per_detection));
  }
}

CampaignSummary runCampaign(const CampaignOptions& options,
                            const std::function<void(const FaultTrial&, int)>& progress) {
  checkOptions(options);
  const std::vector<std::string> faults = !options.faults.empty()      ? options.faults
                                          : options.workcell == "test" ? testCellFaults()
                                                                       : allFaults();
  for (const std::string& fault : faults) {
    faults::parseFault(
        fault.find('@') != std::string::npos ? fault : fault + "@t=0");  // @throws FaultSpecError, before any run
  }
  // An unknown cell is refused before any run too (each run would fail the same way).
  workcell::requireKnownWorkcell(options.workcell);
  std::vector<bt::Plan> plans;
  for (const CampaignTask& task : options.tasks) {
    plans.push_back(bt::loadPlan(task.plan));
  }
  std::string waypoints_before;
  if (!options.waypoints.empty()) {
    if (!std::filesystem::exists(options.waypoints)) {
      throw std::runtime_error("waypoint file '" + options.waypoints.string() + "' does not exist");
    }
    waypoints_before = readFile(options.waypoints);
  }
  CampaignSummary summary;
  summary.options = options;
  // Every task meets every fault: task cycles fastest, then the fault.
  summary.trials = runIndexed(
      static_cast<std::size_t>(options.count), options.jobs,
      [&](std::size_t index) {
        const std::size_t t = index % options.tasks.size();
        const std::size_t f = (index / options.tasks.size()) % faults.size();
        return runOne(options, options.tasks[t], plans[t], faults[f], waypoints_before, static_cast<int>(index));
      },
      [&](const FaultTrial& trial, std::size_t, int done) {
        if (progress) {
          progress(trial, done);
        }
      });
  return summary;
}

nlohmann::json FaultTrial::toJson() const {
  return {{"index", index},
          {"seed", seed},
          {"task", task},
          {"fault", fault},
          {"outcome", outcome},
          {"failure_path", failure_path},
          {"reason", reason},
          {"due_s", due_s},
          {"effect_s", effect_s},
          {"end_s", end_s},
          {"latency_s", latency_s},
          {"rest_after_s", rest_after_s},
          {"final_speed", final_speed},
          {"waypoints_intact", waypoints_intact},
          {"wall_s", wall_s}};
}

namespace {

const nlohmann::json& member(const nlohmann::json& json, const char* key) {
  const auto found = json.find(key);
  if (found == json.end()) {
    throw std::runtime_error(std::string("missing field '") + key + "'");
  }
  return *found;
}

[[noreturn]] void wrongType(const char* key, const std::string& what, const nlohmann::json& value) {
  throw std::runtime_error(std::string("field '") + key + "' must be " + what + ", not " +
                           value.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace).substr(0, 60));
}

double numberField(const nlohmann::json& json, const char* key) {
  const nlohmann::json& value = member(json, key);
  if (!value.is_number()) {
    wrongType(key, "a number", value);
  }
  return value.get<double>();
}

std::string textField(const nlohmann::json& json, const char* key) {
  const nlohmann::json& value = member(json, key);
  if (!value.is_string()) {
    wrongType(key, "a string", value);
  }
  return value.get<std::string>();
}

}  // namespace

FaultTrial FaultTrial::fromJson(const nlohmann::json& json) {
  if (!json.is_object()) {
    throw std::runtime_error("must be a JSON object {\"index\": ..., ...}, not " + std::string(json.type_name()));
  }
  FaultTrial trial;
  const nlohmann::json& index = member(json, "index");
  if (!index.is_number_integer() || index.get<long long>() < 0 || index.get<long long>() > 1000000000) {
    wrongType("index", "a whole number from 0", index);
  }
  trial.index = index.get<int>();
  const nlohmann::json& seed = member(json, "seed");
  if (!seed.is_number_unsigned()) {
    wrongType("seed", "a whole number from 0", seed);
  }
  trial.seed = seed.get<std::uint64_t>();
  trial.task = textField(json, "task");
  trial.fault = textField(json, "fault");
  trial.outcome = textField(json, "outcome");
  trial.failure_path = textField(json, "failure_path");
  trial.reason = textField(json, "reason");
  trial.due_s = numberField(json, "due_s");
  trial.effect_s = numberField(json, "effect_s");
  trial.end_s = numberField(json, "end_s");
  trial.latency_s = numberField(json, "latency_s");
  trial.rest_after_s = numberField(json, "rest_after_s");
  trial.final_speed = numberField(json, "final_speed");
  const nlohmann::json& intact = member(json, "waypoints_intact");
  if (!intact.is_boolean()) {
    wrongType("waypoints_intact", "true or false", intact);
  }
  trial.waypoints_intact = intact.get<bool>();
  trial.wall_s = numberField(json, "wall_s");
  return trial;
}

CampaignSummary readJsonLines(const std::filesystem::path& file, std::vector<std::string>& notes) {
  const std::string text = readFile(file);
  CampaignSummary summary;
  std::size_t start = 0;
  for (int line = 1; start < text.size(); ++line) {
    const std::size_t end = std::min(text.find('\n', start), text.size());
    const std::string_view content(text.data() + start, end - start);
    const bool last_cut_short = end == text.size();  // no newline after it
    start = end + 1;
    if (content.find_first_not_of(" \t\r") == std::string_view::npos) {
      continue;
    }
    const std::string where = file.string() + ":" + std::to_string(line) + ": ";
    nlohmann::json json;
    try {
      json = core::parseJson(content);
    } catch (const core::JsonSyntaxError& e) {
      if (last_cut_short) {
        notes.push_back(where + "the last line is cut short (the campaign was stopped while writing it): left out");
        break;
      }
      throw std::runtime_error(where + "not a JSON object: " + e.what());
    } catch (const std::exception& e) {
      throw std::runtime_error(where + e.what());
    }
    try {
      summary.trials.push_back(FaultTrial::fromJson(json));
    } catch (const std::exception& e) {
      throw std::runtime_error(where + e.what());
    }
  }
  return summary;
}

nlohmann::json CampaignSummary::toJson() const {
  nlohmann::json list = nlohmann::json::array();
  for (const FaultTrial& t : trials) {
    list.push_back(t.toJson());
  }
  return {{"count", trials.size()},
          {"seed", options.seed},
          {"window_s", options.window_s},
          {"deadline_s", options.deadline_s},
          {"rest_speed", options.rest_speed},
          {"settle_s", options.settle_s},
          {"trials", list}};
}

std::string CampaignSummary::text() const {
  // Rows: every kind (all targets), then every KIND:TARGET.
  struct Row {
    int runs = 0;
    int took_effect = 0;
    int met = 0;
    std::map<std::string, int> outcomes;
    std::vector<double> latencies;
    std::vector<double> rests;
  };
  std::map<std::string, Row> rows;
  const auto add = [&rows](const std::string& key, const FaultTrial& t) {
    Row& row = rows[key];
    ++row.runs;
    ++row.outcomes[t.outcome];
    if (t.effect_s >= 0) {
      ++row.took_effect;
    }
    if (t.met()) {
      ++row.met;
    }
    if (t.latency_s >= 0 && t.outcome != "hang" && t.outcome != "missed") {
      row.latencies.push_back(t.latency_s);
    }
    if (t.rest_after_s >= 0) {
      row.rests.push_back(t.rest_after_s);
    }
  };
  for (const FaultTrial& t : trials) {
    const std::string spec = t.fault.substr(0, t.fault.find('@'));
    add("all", t);
    add("kind " + spec.substr(0, spec.find(':')), t);
    add(spec, t);
  }
  std::string out;
  char line[320];
  std::snprintf(line, sizeof line, "%-28s %5s %6s %6s %9s %9s %9s  %s\n", "fault", "runs", "effect", "met", "max s",
                "p99 s", "rest max", "outcomes");
  out += line;
  for (const auto& [key, row] : rows) {
    std::string outcomes;
    for (const auto& [outcome, n] : row.outcomes) {
      outcomes += (outcomes.empty() ? "" : ", ") + outcome + " " + std::to_string(n);
    }
    std::snprintf(line, sizeof line, "%-28s %5d %6d %6d %9.3f %9.3f %9.3f  %s\n", key.c_str(), row.runs,
                  row.took_effect, row.met, percentile(row.latencies, 1.0), percentile(row.latencies, 0.99),
                  percentile(row.rests, 1.0), outcomes.c_str());
    out += line;
  }
  return out;
}

}  // namespace costar::trials
