#include "faults/campaign.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <map>
#include <random>
#include <sstream>
#include <stdexcept>

#include "arm/waypoints.h"
#include "bt/builder.h"
#include "bt/executor.h"
#include "bt/plan_xml.h"
#include "core/parallel.h"
#include "core/paths.h"
#include "faults/injector.h"
#include "sim/simulation.h"
#include "workcell/workcell.h"

namespace costar::faults {

namespace {

std::string readAll(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

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
    auto injector = Injector::fromText({trial.fault}, trial.seed);
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
    const FaultRecord& record = injector->records().front();
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
      trial.waypoints_intact = readAll(options.waypoints) == waypoints_before;
      try {
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
                      : record.spec.kind == FaultKind::kThrow && record.spec.target != "arm-driver" &&
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

CampaignSummary runCampaign(const CampaignOptions& options,
                            const std::function<void(const FaultTrial&, int)>& progress) {
  const std::vector<std::string> faults = !options.faults.empty()      ? options.faults
                                          : options.workcell == "test" ? testCellFaults()
                                                                       : allFaults();
  for (const std::string& fault : faults) {
    parseFault(fault.find('@') != std::string::npos ? fault
                                                    : fault + "@t=0");  // @throws FaultSpecError, before any run
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
    waypoints_before = readAll(options.waypoints);
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

nlohmann::json CampaignSummary::toJson() const {
  nlohmann::json list = nlohmann::json::array();
  for (const FaultTrial& t : trials) {
    list.push_back({{"index", t.index},
                    {"seed", t.seed},
                    {"task", t.task},
                    {"fault", t.fault},
                    {"outcome", t.outcome},
                    {"failure_path", t.failure_path},
                    {"reason", t.reason},
                    {"due_s", t.due_s},
                    {"effect_s", t.effect_s},
                    {"end_s", t.end_s},
                    {"latency_s", t.latency_s},
                    {"rest_after_s", t.rest_after_s},
                    {"final_speed", t.final_speed},
                    {"waypoints_intact", t.waypoints_intact},
                    {"wall_s", t.wall_s}});
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

}  // namespace costar::faults
