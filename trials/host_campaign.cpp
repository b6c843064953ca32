#include "trials/host_campaign.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <optional>
#include <random>
#include <set>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "bt/builder.h"
#include "bt/executor.h"
#include "bt/plan_xml.h"
#include "core/clock.h"
#include "core/files.h"
#include "core/paths.h"
#include "sim/simulation.h"
#include "workcell/workcell.h"

namespace costar::trials {
namespace {

using SteadyClock = std::chrono::steady_clock;

/// How long a host may take to start (it loads the perception pipeline) before the run is an error.
constexpr auto kHostStartLimit = std::chrono::seconds(60);

double largestSpeed(const sim::Simulation& simulation) {
  double largest = 0.0;
  for (const double v : simulation.armVelocities()) {
    largest = std::max(largest, std::isfinite(v) ? std::abs(v) : 1e9);
  }
  return largest;
}

double percentile(std::vector<double> values, double p) {
  if (values.empty()) {
    return -1.0;
  }
  std::sort(values.begin(), values.end());
  const auto at = static_cast<std::size_t>(std::ceil(p * static_cast<double>(values.size()))) - 1;
  return values[std::min(at, values.size() - 1)];
}

/// An operation that moves the arm: the arm's own, and SmartMove's (its motions run as the arm's).
bool isMotion(const std::string& id) {
  static const std::set<std::string, std::less<>> kMotions = {"Home",       "Move",         "MoveRelative", "SmartMove",
                                                              "SmartGrasp", "SmartRelease", "SmartPush"};
  return kMotions.contains(id);
}

/// An operation of the plan as a run in one process had it: its node's id and its span.
struct Span {
  std::string id;
  TimePoint start{};
  TimePoint end{};
};

/// Records the spans of the tree's leaves.
class SpanRecorder final : public bt::TreeObserver {
 public:
  void onTransition(TimePoint time, const bt::TreeNode& node, bt::Status from, bt::Status to) override {
    if (!node.children().empty()) {
      return;
    }
    if (to == bt::Status::kRunning) {
      started_[&node] = time;
    } else if ((to == bt::Status::kSuccess || to == bt::Status::kFailure) && from != to) {
      const auto it = started_.find(&node);
      spans.push_back({node.id(), it == started_.end() ? time : it->second, time});
      if (it != started_.end()) {
        started_.erase(it);
      }
    }
  }
  std::vector<Span> spans;

 private:
  std::map<const bt::TreeNode*, TimePoint> started_;
};

workcell::WorkcellOptions cellOptions(const HostCampaignOptions& options, std::uint64_t seed) {
  return {.name = options.workcell, .seed = seed, .waypoints = options.waypoints, .memory_only = true};
}

/// The moment to kill the host in run `seed` of `phase`, from a run of the same seed in one
/// process; nullopt when the plan has no such operation.
std::optional<std::pair<TimePoint, std::string>> drawMoment(const HostCampaignOptions& options, const bt::Plan& plan,
                                                            const std::string& phase, std::uint64_t seed) {
  const auto cell = workcell::makeWorkcell(cellOptions(options, seed));
  bt::Tree tree = bt::buildTree(plan, cell->nodes(), cell->clock());
  SpanRecorder recorder;
  tree.addObserver(&recorder);
  bt::Executor executor(tree, cell->clock(), {.time_limit = fromSeconds(options.time_limit_s)});
  executor.setBeforeTick([&cell] { cell->beforeTick(); });
  executor.run();
  TimePoint last_end{};
  for (const Span& span : recorder.spans) {
    last_end = std::max(last_end, span.end);
  }
  std::vector<Span> chosen;
  for (const Span& span : recorder.spans) {
    const bool take = phase == "detect" ? span.id == "DetectObjects" && span.end > span.start
                      : phase == "move" ? isMotion(span.id) && span.end > span.start
                                        : span.end < last_end;  // between: an operation's end, not the plan's
    if (take) {
      chosen.push_back(span);
    }
  }
  if (chosen.empty()) {
    return std::nullopt;
  }
  std::mt19937_64 random(seed * 0x9E3779B97F4A7C15ULL + std::hash<std::string>{}(phase));
  const Span& span = chosen[std::uniform_int_distribution<std::size_t>(0, chosen.size() - 1)(random)];
  if (phase == "between") {
    return std::pair{span.end, span.id};
  }
  const double from = toSeconds(span.start);
  const double to = toSeconds(span.end);
  return std::pair{TimePoint(fromSeconds(std::uniform_real_distribution<double>(from, to)(random))), span.id};
}

/// A host process serving the components, started and ready; killed (SIGKILL) when destroyed.
class Host {
 public:
  Host(const HostCampaignOptions& options, const std::string& partition, const std::filesystem::path& log) {
    std::vector<std::string> args = options.host_command;
    args.insert(args.end(), options.components.begin(), options.components.end());
    args.insert(args.end(),
                {"-w", options.workcell, "--domain", std::to_string(options.domain), "--partition", partition});
    pid_ = ::fork();
    if (pid_ < 0) {
      throw std::runtime_error("cannot start the host: fork failed");
    }
    if (pid_ == 0) {
      const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      if (fd >= 0) {
        ::dup2(fd, STDERR_FILENO);
        ::dup2(fd, STDOUT_FILENO);
      }
      std::vector<char*> argv;
      for (auto& arg : args) {
        argv.push_back(arg.data());
      }
      argv.push_back(nullptr);
      ::execv(argv[0], argv.data());
      ::_exit(127);
    }
    const auto deadline = SteadyClock::now() + kHostStartLimit;
    for (;;) {
      std::ifstream in(log);
      const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
      if (text.find("costar host: serving") != std::string::npos) {
        return;
      }
      int status = 0;
      if (::waitpid(pid_, &status, WNOHANG) == pid_) {
        pid_ = -1;
        throw std::runtime_error("the host ended before it served: " + text);
      }
      if (SteadyClock::now() > deadline) {
        throw std::runtime_error("the host did not start within 60 s: " + text);
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
  }
  Host(const Host&) = delete;
  Host& operator=(const Host&) = delete;
  ~Host() { kill(); }
  /// SIGKILL, at once; the process is reaped later.
  void kill() {
    if (pid_ > 0) {
      ::kill(pid_, SIGKILL);
      ::waitpid(pid_, nullptr, 0);
      pid_ = -1;
    }
  }
  void killNow() {
    if (pid_ > 0) {
      ::kill(pid_, SIGKILL);
    }
  }

 private:
  pid_t pid_ = -1;
};

HostKillRun runOne(const HostCampaignOptions& options, const bt::Plan& plan, const std::string& plan_text,
                   const std::string& waypoints_text, int index) {
  HostKillRun run;
  run.index = index;
  run.seed = options.seed + static_cast<std::uint64_t>(index);
  run.phase = options.phases[static_cast<std::size_t>(index) % options.phases.size()];
  const auto wall_start = SteadyClock::now();
  const std::filesystem::path folder =
      std::filesystem::temp_directory_path() /
      ("costar-host-campaign-" + std::to_string(::getpid()) + "-" + std::to_string(index));
  std::filesystem::create_directories(folder);
  try {
    const auto moment = drawMoment(options, plan, run.phase, run.seed);
    if (!moment) {
      throw std::runtime_error("the plan has no operation for phase '" + run.phase + "'");
    }
    run.kill_at_s = toSeconds(moment->first);
    run.node = moment->second;
    const std::string partition = "host-campaign-" + std::to_string(::getpid()) + "-" + std::to_string(index);
    nlohmann::json remote = {{"domain", options.domain}, {"partition", partition}, {"components", options.components}};
    const std::filesystem::path remote_file = folder / "remote.json";
    std::ofstream(remote_file) << remote.dump();
    Host host(options, partition, folder / "host.log");
    workcell::WorkcellOptions cell_options = cellOptions(options, run.seed);
    cell_options.remote = remote_file;
    const auto cell = workcell::makeWorkcell(cell_options);
    sim::Simulation* simulation = cell->simulation();
    auto& clock = dynamic_cast<SimClock&>(cell->clock());
    std::optional<SteadyClock::time_point> killed;
    const TimePoint kill_at = moment->first;
    clock.addStepListener([&](TimePoint, TimePoint to) {
      if (!killed && to >= kill_at) {
        host.killNow();
        killed = SteadyClock::now();
      }
    });
    bt::Tree tree = bt::buildTree(plan, cell->nodes(), cell->clock());
    bt::Executor executor(tree, cell->clock(), {.time_limit = fromSeconds(options.time_limit_s)});
    executor.setBeforeTick([&cell] { cell->beforeTick(); });
    const TimePoint start = clock.now();
    const bt::RunResult result = executor.run();
    const auto ended = SteadyClock::now();
    const TimePoint end = start + result.elapsed;
    if (killed) {
      run.noticed_s = std::chrono::duration<double>(ended - *killed).count();
    }
    for (TimePoint t = clock.now(); simulation != nullptr && clock.now() < end + fromSeconds(options.settle_s);) {
      t += std::chrono::milliseconds(10);
      clock.advanceTo(t);
    }
    run.final_speed = simulation != nullptr ? largestSpeed(*simulation) : 0.0;
    host.kill();
    run.files_intact = readFile(options.plan) == plan_text &&
                       (options.waypoints.empty() || readFile(options.waypoints) == waypoints_text);
    run.failure_path = result.failure_path;
    run.reason = result.failure_reason;
    const bool names_component =
        std::any_of(options.components.begin(), options.components.end(),
                    [&](const std::string& name) { return run.reason.find("'" + name + "'") != std::string::npos; });
    if (!killed) {
      run.outcome = "not-killed";
    } else if (result.status == bt::Status::kSuccess) {
      run.outcome = "success";
    } else if (result.elapsed >= fromSeconds(options.time_limit_s)) {
      run.outcome = "hang";
    } else if (!names_component) {
      run.outcome = "no-reason";
    } else if (run.noticed_s > options.deadline_s) {
      run.outcome = "late";
    } else if (run.final_speed >= options.rest_speed) {
      run.outcome = "not-at-rest";
    } else if (!run.files_intact) {
      run.outcome = "lost-data";
    } else {
      run.outcome = "stopped";
    }
  } catch (const std::exception& error) {
    run.outcome = "error";
    run.reason = error.what();
  }
  std::error_code ignored;
  std::filesystem::remove_all(folder, ignored);
  run.wall_s = std::chrono::duration<double>(SteadyClock::now() - wall_start).count();
  return run;
}

}  // namespace

nlohmann::json HostKillRun::toJson() const {
  return {{"index", index},
          {"seed", seed},
          {"phase", phase},
          {"node", node},
          {"kill_at_s", kill_at_s},
          {"outcome", outcome},
          {"failure_path", failure_path},
          {"reason", reason},
          {"noticed_s", noticed_s},
          {"final_speed", final_speed},
          {"files_intact", files_intact},
          {"wall_s", wall_s}};
}

nlohmann::json HostCampaignSummary::toJson() const {
  nlohmann::json list = nlohmann::json::array();
  for (const HostKillRun& run : runs) {
    list.push_back(run.toJson());
  }
  return {{"workcell", options.workcell},     {"plan", options.plan.string()},    {"seed", options.seed},
          {"components", options.components}, {"deadline_s", options.deadline_s}, {"runs", list}};
}

std::string HostCampaignSummary::text() const {
  std::ostringstream out;
  for (const std::string& phase : options.phases) {
    std::map<std::string, int> outcomes;
    std::vector<double> noticed;
    int total = 0;
    for (const HostKillRun& run : runs) {
      if (run.phase != phase) {
        continue;
      }
      ++total;
      ++outcomes[run.outcome];
      if (run.noticed_s >= 0) {
        noticed.push_back(run.noticed_s);
      }
    }
    char line[256];
    std::snprintf(line, sizeof line,
                  "%-8s %d / %d stopped; FAILURE %.3f s after the kill (median), %.3f (p99), %.3f (max)", phase.c_str(),
                  outcomes["stopped"], total, percentile(noticed, 0.5), percentile(noticed, 0.99),
                  percentile(noticed, 1.0));
    out << line;
    for (const auto& [outcome, count] : outcomes) {
      if (outcome != "stopped") {
        out << "; " << outcome << " " << count;
      }
    }
    out << "\n";
  }
  return out.str();
}

HostCampaignSummary runHostCampaign(const HostCampaignOptions& given,
                                    const std::function<void(const HostKillRun&, int done)>& progress) {
  HostCampaignOptions options = given;
  if (options.plan.empty()) {
    options.plan = dataRoot() / "examples/ur5/assemble_structure.xml";
  }
  if (options.count < 1) {
    throw std::invalid_argument("the number of runs must be at least 1, not " + std::to_string(options.count));
  }
  if (options.host_command.empty()) {
    throw std::invalid_argument("no host command");
  }
  if (options.phases.empty()) {
    throw std::invalid_argument("no phase");
  }
  for (const std::string& phase : options.phases) {
    if (phase != "detect" && phase != "move" && phase != "between") {
      throw std::invalid_argument("unknown phase '" + phase + "' (known: detect, move, between)");
    }
  }
  const bt::Plan plan = bt::loadPlan(options.plan);
  const std::string plan_text = readFile(options.plan);
  const std::string waypoints_text = options.waypoints.empty() ? std::string() : readFile(options.waypoints);
  HostCampaignSummary summary;
  summary.options = options;
  for (int i = 0; i < options.count; ++i) {
    summary.runs.push_back(runOne(options, plan, plan_text, waypoints_text, i));
    if (progress) {
      progress(summary.runs.back(), i + 1);
    }
  }
  return summary;
}

}  // namespace costar::trials
