#include "server/engine.h"

#include <time.h>

#include <algorithm>
#include <cmath>
#include <set>

#include "arm/arm_component.h"
#include "bt/builder.h"
#include "bt/executor.h"
#include "component/nodes.h"
#include "server/guard.h"
#include "sim/simulation.h"
#include "smartmove/grasps.h"
#include "workcell/workcell.h"

namespace costar::server {

using nlohmann::json;

namespace {

double rounded(double value, double scale = 1e5) { return std::round(value * scale) / scale; }

json poseJson(const world::Pose& pose) {
  const Eigen::Vector3d& p = pose.translation();
  const Eigen::Quaterniond q(pose.linear());
  // three.js order: x, y, z, w.
  return {{"p", {rounded(p.x()), rounded(p.y()), rounded(p.z())}},
          {"q", {rounded(q.x()), rounded(q.y()), rounded(q.z()), rounded(q.w())}}};
}

const std::span<const std::string> kNoArgs{};

/// CPU time of the calling thread, seconds.
double threadCpuSeconds() {
  timespec now{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &now);
  return static_cast<double>(now.tv_sec) + 1e-9 * static_cast<double>(now.tv_nsec);
}

}  // namespace

// One run (a plan or a single operation) as the browser sees it.
struct Engine::RunState {
  struct Node {
    bt::Status current = bt::Status::kIdle;
    std::string last = "IDLE";  // last status other than IDLE; HALTED when stopped while RUNNING
    std::string reason;
    std::string origin;
    json data;  // an operation's result data (SmartMove candidates, ...)
    bool dirty = false;
  };
  std::int64_t id = 0;
  bool operation = false;
  std::string plan_name;
  int version = 0;
  std::string label;  // the main tree's ID, or the operation's node type
  std::string xml;
  std::vector<RunNode> nodes;
  std::vector<Node> statuses;
  std::vector<std::uint32_t> dirty;
  bool active = true;
  bool stopped = false;
  std::string result;
  std::string failure_path;
  std::string failure_reason;
  double started_at = 0;
  double clock_seconds = 0;
  double wall_seconds = 0;
  double cpu_seconds = 0;  // the engine thread's CPU time during the run
  TimePoint start_time{};
  std::uint64_t transitions = 0;
  bool truncated = false;
};

class Engine::Observer final : public bt::TreeObserver {
 public:
  explicit Observer(Engine& engine) : engine_(engine) {}
  void onTransition(TimePoint time, const bt::TreeNode& node, bt::Status from, bt::Status to) override {
    engine_.onTransition(time, node, from, to);
  }

 private:
  Engine& engine_;
};

struct Engine::LogCommand {
  enum class Kind { kBegin, kTransitions, kEnd } kind = Kind::kBegin;
  RunRecord record;
  std::vector<RunNode> nodes;
  std::vector<TransitionRecord> transitions;
};

Engine::Engine(workcell::Workcell& cell, Store* store, EngineOptions options)
    : cell_(cell), store_(store), options_(std::move(options)) {
  const double pace = options_.pace;
  pacer_.setFactor(pace > 0 ? pace : 1.0);
  if (store_ != nullptr) {
    next_run_id_ = store_->maxRunId() + 1;
  }

  // The palette: every node type with its ports; operation parameters add where their
  // choices come from and their range.
  json nodes = json::array();
  bool detect = false;
  bool calibrate = false;
  for (const bt::NodeSpec* spec : cell_.nodes().all()) {
    const component::Component* provider = cell_.components().provider(spec->id);
    const component::OperationSpec* operation =
        provider != nullptr ? provider->description().operation(spec->id) : nullptr;
    json ports = json::array();
    for (const auto& port : spec->ports) {
      json item = {{"name", port.name}, {"type", port.type_name}, {"description", port.description}};
      if (port.default_value) {
        item["default"] = *port.default_value;
      }
      if (!port.choices.empty()) {
        item["choices"] = port.choices;
      }
      if (const component::ParamSpec* param = operation != nullptr ? operation->param(port.name) : nullptr) {
        if (!param->choices_from.empty()) {
          item["choices_from"] = param->choices_from;
        }
        if (param->min) {
          item["min"] = *param->min;
        }
        if (param->max) {
          item["max"] = *param->max;
        }
      }
      ports.push_back(std::move(item));
    }
    json node = {{"id", spec->id},
                 {"kind", bt::toString(spec->kind)},
                 {"category", bt::toString(spec->category)},
                 {"description", spec->description},
                 {"asynchronous", spec->asynchronous},
                 {"ports", std::move(ports)}};
    if (provider != nullptr) {
      node["component"] = provider->description().name;
    }
    nodes.push_back(std::move(node));
    detect = detect || spec->id == "DetectObjects";
    calibrate = calibrate || spec->id == "Calibrate" || spec->id == "HandEyeCalibration";
  }
  nodes_json_ = nodes.dump();
  info_ = {{"workcell", cell_.name()},
           {"description", cell_.description()},
           {"simulated_clock", cell_.clock().simulated()},
           {"simulator", cell_.simulation() != nullptr},
           {"features",
            {{"detect", detect},
             {"calibrate", calibrate},
             {"pointcloud", cell_.simulation() != nullptr},
             {"detect_node", detect ? "DetectObjects" : ""},
             {"calibrate_node", cell_.nodes().find("Calibrate") != nullptr ? "Calibrate" : "HandEyeCalibration"}}},
           {"version", "0.1.0"}};
  takeSnapshot();
}

Engine::~Engine() { shutdown(); }

void Engine::startThread() {
  {
    const std::lock_guard lock(task_mutex_);
    if (started_) {
      return;
    }
    started_ = true;
  }
  // An exception that escapes a loop is logged and the loop goes on (guard.h).
  log_thread_ = std::thread([this] {
    while (!guarded("run log writer", [this] { logWriterLoop(); })) {
    }
  });
  thread_ = std::thread([this] {
    while (!guarded("engine thread", [this] { loop(); })) {
    }
  });
}

void Engine::shutdown() {
  {
    const std::lock_guard lock(task_mutex_);
    if (!started_ || stopping_) {
      return;
    }
    stopping_ = true;
    stop_requested_ = true;
  }
  task_cv_.notify_all();
  if (thread_.joinable()) {
    thread_.join();
  }
  {
    const std::lock_guard lock(log_mutex_);
    log_stopping_ = true;
  }
  log_cv_.notify_all();
  if (log_thread_.joinable()) {
    log_thread_.join();
  }
}

template <typename F>
auto Engine::call(F task) -> decltype(task()) {
  using Result = decltype(task());
  // The task owns what it uses (captured by value): it may run after the caller gave up.
  auto packaged = std::make_shared<std::packaged_task<Result()>>(std::move(task));
  std::future<Result> future = packaged->get_future();
  {
    const std::lock_guard lock(task_mutex_);
    if (!started_ || stopping_) {
      throw BackendBusy("the engine is not running (the server is stopping)");
    }
    tasks_.emplace_back([packaged] { (*packaged)(); });
  }
  task_cv_.notify_all();
  if (future.wait_for(options_.call_timeout) != std::future_status::ready) {
    throw BackendBusy("the engine did not answer within " + std::to_string(toSeconds(options_.call_timeout)) +
                      " s (busy with a long computation); try again");
  }
  try {
    return future.get();
  } catch (const std::future_error&) {
    throw BackendBusy("the engine stopped before answering");
  }
}

void Engine::runTasks() {
  while (true) {
    std::function<void()> task;
    {
      const std::lock_guard lock(task_mutex_);
      if (tasks_.empty()) {
        return;
      }
      task = std::move(tasks_.front());
      tasks_.pop_front();
    }
    task();  // exceptions are carried by the packaged_task's future
  }
}

void Engine::waitWall(std::chrono::steady_clock::duration duration) {
  const auto deadline = std::chrono::steady_clock::now() + duration;
  while (!stopping_) {
    {
      std::unique_lock lock(task_mutex_);
      task_cv_.wait_until(lock, deadline, [this] { return !tasks_.empty() || stopping_.load(); });
    }
    runTasks();
    if (std::chrono::steady_clock::now() >= deadline) {
      return;
    }
  }
}

void Engine::loop() {
  while (!stopping_) {
    runTasks();
    if (pending_tree_) {
      executePending();
      continue;
    }
    try {
      hook(false);
      Clock& clock = cell_.clock();
      clock.sleepUntil(clock.now() + options_.tick_period);
    } catch (const std::exception& error) {
      // A component that fails while idle must not take the server down: note it, go on.
      {
        const std::lock_guard lock(mutex_);
        last_error_ = error.what();
      }
      waitWall(std::chrono::milliseconds(100));
    }
  }
  runTasks();
}

void Engine::hook(bool running) {
  runTasks();
  if (const double pace = pace_request_.exchange(-1); pace >= 0) {
    {
      const std::lock_guard lock(mutex_);
      options_.pace = pace;
    }
    pacer_.setFactor(running && pace <= 0 ? 0.0 : (pace > 0 ? pace : 1.0));
  }
  cell_.beforeTick();
  const auto now = std::chrono::steady_clock::now();
  if (now >= next_snapshot_) {
    takeSnapshot();
    // A steady rate: the next one is due a period after this one was due, unless that is past.
    const auto period = std::chrono::duration_cast<std::chrono::steady_clock::duration>(
        std::chrono::duration<double>(1.0 / std::max(1.0, options_.stream_hz)));
    next_snapshot_ = next_snapshot_ + period > now ? next_snapshot_ + period : now + period;
  }
  {
    const std::lock_guard lock(mutex_);
    ++stats_.ticks;
  }
  if (cell_.clock().simulated()) {
    const auto delay = pacer_.delay(cell_.clock().now(), std::chrono::steady_clock::now());
    if (delay > std::chrono::steady_clock::duration::zero()) {
      waitWall(delay);
      const std::lock_guard lock(mutex_);
      stats_.paced_wait_seconds += std::chrono::duration<double>(delay).count();
    }
  }
}

void Engine::executePending() {
  std::shared_ptr<RunState> run = std::move(pending_run_);
  bt::Tree tree = std::move(*pending_tree_);
  pending_tree_.reset();
  pending_run_.reset();

  observer_ = std::make_unique<Observer>(*this);
  tree.addObserver(observer_.get());
  bt::ExecutorOptions executor_options;
  executor_options.tick_period = options_.tick_period;
  bt::Executor executor(tree, cell_.clock(), executor_options);
  if (start_paused_) {
    executor.pause();
    paused_ = true;
  }
  executor.setBeforeTick([this, &executor] {
    hook(true);
    if (stop_requested_.exchange(false)) {
      executor.requestStop();
    }
    if (const int pause = pause_requested_.exchange(0); pause > 0) {
      executor.pause();
    } else if (pause < 0) {
      executor.resume();
    }
    if (const int steps = steps_requested_.exchange(0); steps > 0) {
      executor.pause();
      for (int i = 0; i < steps; ++i) {
        executor.step();
      }
    }
    paused_ = executor.paused();
  });
  pacer_.setFactor(options_.pace);

  bt::RunResult result;
  const double cpu_start = threadCpuSeconds();
  const auto wall_start = std::chrono::steady_clock::now();
  try {
    result = executor.run();
  } catch (const std::exception& error) {
    try {
      tree.halt();
    } catch (const std::exception&) {
    }
    result.status = bt::Status::kFailure;
    result.failure_path = tree.mainTreeId();
    result.failure_reason = std::string("the engine failed: ") + error.what();
  }
  tree.removeObserver(observer_.get());
  observer_.reset();
  pacer_.setFactor(options_.pace > 0 ? options_.pace : 1.0);

  RunRecord record;
  {
    const std::lock_guard lock(mutex_);
    run->active = false;
    run->stopped = result.stopped;
    run->result = result.stopped ? "STOPPED" : bt::toString(result.status);
    run->failure_path = result.failure_path;
    run->failure_reason = result.failure_reason;
    run->clock_seconds = toSeconds(result.elapsed);
    run->cpu_seconds = threadCpuSeconds() - cpu_start;
    run->wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
    if (!run->dirty.empty()) {
      events_.push_back(statusesJson(*run, true).dump(-1, ' ', false, json::error_handler_t::replace));
    }
    json ended = runJson(*run, false);
    events_.push_back(
        json{{"type", "run_ended"}, {"run", std::move(ended)}}.dump(-1, ' ', false, json::error_handler_t::replace));
    finished_.push_front(run);
    while (finished_.size() > options_.remembered_runs) {
      finished_.pop_back();
    }
    record.id = run->id;
    record.result = run->result;
    record.ended_at = unixNow();
    record.clock_seconds = run->clock_seconds;
    record.failure_path = run->failure_path;
    record.failure_reason = run->failure_reason;
    record.transitions = run->transitions;
    record.truncated = run->truncated;
  }
  active_run_ = 0;
  paused_ = false;
  stop_requested_ = false;
  pause_requested_ = 0;
  steps_requested_ = 0;
  if (!run->operation && store_ != nullptr) {
    LogCommand end;
    end.kind = LogCommand::Kind::kEnd;
    end.record = std::move(record);
    pushLog(std::move(end));
  }
  cell_.beforeTick();
  takeSnapshot();
}

void Engine::onTransition(TimePoint time, const bt::TreeNode& node, bt::Status from, bt::Status to) {
  RunState* run = current_.get();  // set before the run starts; only this thread replaces it
  if (run == nullptr || node.uid() >= run->statuses.size()) {
    return;
  }
  json data;
  if (bt::isCompleted(to)) {
    if (const auto* operation = dynamic_cast<const component::OperationNode*>(&node)) {
      const json& result_data = operation->lastResult().data;
      if (!result_data.is_null() && !result_data.empty()) {
        data = result_data;
      }
    }
  }
  TransitionRecord record;
  record.t = toSeconds(time - run->start_time);
  record.uid = node.uid();
  record.from = bt::toString(from);
  record.to = bt::toString(to);
  if (to == bt::Status::kFailure) {
    record.reason = std::string(node.failureReason());
    record.origin = node.failureOrigin().path();
  }
  bool keep = false;
  {
    const std::lock_guard lock(mutex_);
    RunState::Node& state = run->statuses[node.uid()];
    state.current = to;
    if (to == bt::Status::kIdle) {
      if (from == bt::Status::kRunning) {
        state.last = "HALTED";
      }
    } else {
      state.last = bt::toString(to);
    }
    if (to == bt::Status::kRunning) {
      state.reason.clear();
      state.origin.clear();
    } else if (to == bt::Status::kFailure) {
      state.reason = record.reason;
      state.origin = record.origin;
    }
    if (!data.is_null()) {
      state.data = data;
    }
    if (!state.dirty) {
      state.dirty = true;
      run->dirty.push_back(node.uid());
    }
    record.seq = ++run->transitions;
    keep = !run->operation && store_ != nullptr && record.seq <= options_.max_logged_transitions;
    if (!run->operation && record.seq > options_.max_logged_transitions) {
      run->truncated = true;
    }
  }
  if (keep) {
    if (!data.is_null()) {
      record.data = data.dump(-1, ' ', false, json::error_handler_t::replace);
    }
    const std::lock_guard lock(log_mutex_);
    log_pending_run_ = run->id;
    log_pending_.push_back(std::move(record));
  }
}

json Engine::statusesJson(RunState& run, bool dirty_only) {
  json nodes = json::array();
  const auto add = [&](std::uint32_t uid) {
    const RunState::Node& state = run.statuses[uid];
    json item = {{"uid", uid}, {"status", bt::toString(state.current)}, {"last", state.last}};
    if (!state.reason.empty()) {
      item["reason"] = state.reason;
      item["origin"] = state.origin;
    }
    if (!state.data.is_null()) {
      item["data"] = state.data;
    }
    nodes.push_back(std::move(item));
  };
  if (dirty_only) {
    for (const std::uint32_t uid : run.dirty) {
      run.statuses[uid].dirty = false;
      add(uid);
    }
    run.dirty.clear();
  } else {
    for (std::uint32_t uid = 0; uid < run.statuses.size(); ++uid) {
      if (run.statuses[uid].last != "IDLE" || run.statuses[uid].current != bt::Status::kIdle) {
        add(uid);
      }
    }
  }
  return {{"type", "statuses"}, {"run", run.id}, {"nodes", std::move(nodes)}};
}

json Engine::runJson(const RunState& run, bool with_nodes) const {
  json out = {{"id", run.id},
              {"kind", run.operation ? "operation" : "plan"},
              {"plan", run.plan_name},
              {"version", run.version},
              {"label", run.label},
              {"active", run.active},
              {"started_at", run.started_at},
              {"result", run.result},
              {"clock_seconds", run.clock_seconds},
              {"wall_seconds", run.wall_seconds},
              {"cpu_seconds", run.cpu_seconds},
              {"transitions", run.transitions}};
  if (!run.failure_reason.empty()) {
    out["failure_path"] = run.failure_path;
    out["failure_reason"] = run.failure_reason;
  }
  if (run.stopped) {
    out["stopped"] = true;
  }
  if (with_nodes) {
    json nodes = json::array();
    for (const RunNode& node : run.nodes) {
      nodes.push_back(
          {{"uid", node.uid}, {"parent", node.parent}, {"id", node.id}, {"name", node.name}, {"path", node.path}});
    }
    out["nodes"] = std::move(nodes);
  }
  return out;
}

// --- Backend ---------------------------------------------------------------------------------

json Engine::info() {
  json out = info_;
  const std::lock_guard lock(mutex_);
  out["pace"] = options_.pace;
  out["active_run"] = active_run_.load();
  if (!last_error_.empty()) {
    out["last_error"] = last_error_;
  }
  out["stats"] = {{"ticks", stats_.ticks},
                  {"snapshots", stats_.snapshots},
                  {"snapshot_seconds", stats_.snapshot_seconds},
                  {"paced_wait_seconds", stats_.paced_wait_seconds},
                  {"runs", stats_.runs}};
  return out;
}

json Engine::choices() {
  return call([this] {
    const world::WorldState& world = cell_.components().world();
    std::set<std::string> waypoints;
    std::set<std::string> frames = {"world"};
    std::set<std::string> classes;
    std::set<std::string> arm_sources;
    std::set<std::string> declared;
    for (const auto& component : cell_.components().components()) {
      const auto& description = component->description();
      if (std::find(description.implements.begin(), description.implements.end(), "Arm") !=
          description.implements.end()) {
        arm_sources.insert(description.name);
      }
      for (const auto& symbol : description.symbols) {
        declared.insert(symbol.name);
      }
    }
    for (const world::Symbol* symbol : world.symbols()) {
      if (symbol->frame() != nullptr) {
        frames.insert(symbol->name);
      }
      if (arm_sources.contains(symbol->source) && !declared.contains(symbol->name)) {
        waypoints.insert(symbol->name);
      }
    }
    for (const world::Predicate* predicate : world.predicates("is_a")) {
      if (predicate->args.size() == 2) {
        classes.insert(predicate->args[1]);
      }
    }
    if (sim::Simulation* simulation = cell_.simulation()) {
      for (const auto& object_class : simulation->objectClasses()) {
        classes.insert(object_class.name);
      }
    }
    json predicates = json::array();
    for (const auto& [name, decl] : cell_.components().predicates()) {
      predicates.push_back({{"name", name}, {"arity", decl.arity}, {"description", decl.description}});
    }
    json grasps = json::object();
    try {
      if (!options_.grasp_defaults.empty() && std::filesystem::exists(options_.grasp_defaults)) {
        const smartmove::GraspLibrary library(options_.grasp_defaults, options_.grasp_taught);
        for (const std::string& object_class : classes) {
          json names = json::array();
          for (const auto& grasp : library.forClass(object_class)) {
            names.push_back(grasp.name);
          }
          grasps[object_class] = std::move(names);
        }
      }
    } catch (const std::exception&) {
      // An unreadable grasp file: SmartMove reports it when it runs; offer no list.
    }
    return json{{"waypoint", waypoints},
                {"frame", frames},
                {"object_class", classes},
                {"predicate", std::move(predicates)},
                {"grasp", std::move(grasps)}};
  });
}

std::vector<bt::Diagnostic> Engine::validate(const bt::Plan& plan) {
  return call([this, copy = std::make_shared<const bt::Plan>(plan)] { return bt::validatePlan(*copy, cell_.nodes()); });
}

StartResult Engine::start(RunRequest run_request) {
  return call([this, shared = std::make_shared<RunRequest>(std::move(run_request))]() -> StartResult {
    RunRequest& request = *shared;
    StartResult out;
    if (active_run_ != 0 || pending_tree_) {
      out.status = 409;
      out.error = "run " + std::to_string(active_run_.load()) + " is active: stop it or wait for it to end";
      return out;
    }
    const bt::PlanTree* main = nullptr;
    try {
      main = request.plan.findTree(request.plan.mainTreeId());
    } catch (const bt::PlanError& error) {
      out.status = 422;
      out.diagnostics = error.diagnostics();
      return out;
    }
    if (request.operation && main != nullptr) {
      const bt::NodeSpec* spec = cell_.nodes().find(main->root.id);
      if (spec != nullptr && spec->kind != bt::NodeKind::kAction && spec->kind != bt::NodeKind::kCondition) {
        out.status = 422;
        out.error = "an operation is one action or condition, not a " + std::string(bt::toString(spec->kind));
        return out;
      }
    }
    try {
      if (auto diagnostics = bt::validatePlan(request.plan, cell_.nodes()); !diagnostics.empty()) {
        out.status = 422;
        out.diagnostics = std::move(diagnostics);
        return out;
      }
      pending_tree_.emplace(bt::buildTree(request.plan, cell_.nodes(), cell_.clock()));
    } catch (const bt::PlanError& error) {
      out.status = 422;
      out.diagnostics = error.diagnostics();
      return out;
    } catch (const std::exception& error) {
      out.status = 422;
      out.error = error.what();
      return out;
    }
    auto run = std::make_shared<RunState>();
    run->operation = request.operation;
    run->plan_name = request.plan_name;
    run->version = request.version;
    run->label = request.operation ? (main != nullptr ? main->root.id : "") : pending_tree_->mainTreeId();
    run->xml = request.xml;
    for (const bt::TreeNode* node : pending_tree_->nodes()) {
      run->nodes.push_back({node->uid(),
                            node->parent() != nullptr ? static_cast<std::int64_t>(node->parent()->uid()) : -1,
                            node->id(), node->name(), node->path()});
    }
    run->statuses.resize(run->nodes.size());
    run->start_time = cell_.clock().now();
    run->started_at = unixNow();
    stop_requested_ = false;
    pause_requested_ = 0;
    steps_requested_ = 0;
    start_paused_ = request.start_paused;
    paused_ = request.start_paused;
    {
      const std::lock_guard lock(mutex_);
      run->id = next_run_id_++;
      current_ = run;
      ++stats_.runs;
      events_.push_back(json{{"type", "run_started"}, {"run", runJson(*run, true)}}.dump(
          -1, ' ', false, json::error_handler_t::replace));
    }
    active_run_ = run->id;
    if (!run->operation && store_ != nullptr) {
      LogCommand begin;
      begin.kind = LogCommand::Kind::kBegin;
      begin.record.id = run->id;
      begin.record.plan = run->plan_name;
      begin.record.version = run->version;
      begin.record.xml = run->xml;
      begin.record.started_at = run->started_at;
      begin.nodes = run->nodes;
      pushLog(std::move(begin));
    }
    pending_run_ = run;
    out.run_id = run->id;
    return out;
  });
}

bool Engine::control(RunControl control) {
  if (active_run_ == 0) {
    return false;
  }
  switch (control) {
    case RunControl::kStop:
      stop_requested_ = true;
      break;
    case RunControl::kPause:
      pause_requested_ = 1;
      break;
    case RunControl::kResume:
      pause_requested_ = -1;
      break;
    case RunControl::kStep:
      ++steps_requested_;
      break;
  }
  task_cv_.notify_all();
  return true;
}

json Engine::state() {
  const std::lock_guard lock(mutex_);
  return json::parse(state_json_);
}

std::optional<json> Engine::runStatus(std::optional<std::int64_t> id) {
  const std::lock_guard lock(mutex_);
  std::shared_ptr<RunState> run;
  if (!id) {
    run = current_;
  } else if (current_ && current_->id == *id) {
    run = current_;
  } else {
    for (const auto& finished : finished_) {
      if (finished->id == *id) {
        run = finished;
        break;
      }
    }
  }
  if (!run) {
    return std::nullopt;
  }
  json out = runJson(*run, true);
  out["statuses"] = statusesJson(*run, false)["nodes"];
  return out;
}

std::optional<json> Engine::groundTruth() {
  return call([this]() -> std::optional<json> {
    sim::Simulation* simulation = cell_.simulation();
    if (simulation == nullptr) {
      return std::nullopt;
    }
    json parts = json::array();
    for (const sim::PartState& part : simulation->parts()) {
      json item = poseJson(part.pose);
      item["name"] = part.name;
      item["class"] = part.object_class;
      parts.push_back(std::move(item));
    }
    const sim::FingerState fingers = simulation->fingers();
    return json{{"TEST_ONLY", "the simulator's true state; never used by plans"},
                {"t", toSeconds(simulation->time())},
                {"parts", std::move(parts)},
                {"tcp", poseJson(simulation->tcpPose())},
                {"finger_opening", fingers.opening},
                {"arm_table_contact_steps", simulation->armTableContactSteps()}};
  });
}

std::optional<json> Engine::pointCloud(std::size_t max_points) {
  return call([this, max_points]() -> std::optional<json> {
    sim::Simulation* simulation = cell_.simulation();
    if (simulation == nullptr) {
      return std::nullopt;
    }
    static std::uint64_t noise_seed = 1;
    const camera::RgbdFrame frame = simulation->captureRgbd(noise_seed++);
    const std::size_t valid = frame.validCount();
    const std::size_t stride =
        std::max<std::size_t>(1, (valid + max_points - 1) / std::max<std::size_t>(1, max_points));
    json points = json::array();
    json colors = json::array();
    std::size_t seen = 0;
    for (int v = 0; v < frame.intrinsics.height; ++v) {
      for (int u = 0; u < frame.intrinsics.width; ++u) {
        if (!frame.valid(u, v) || (seen++ % stride) != 0) {
          continue;
        }
        const Eigen::Vector3d p = frame.camera_pose * frame.point(u, v).cast<double>();
        points.push_back(rounded(p.x(), 1e4));
        points.push_back(rounded(p.y(), 1e4));
        points.push_back(rounded(p.z(), 1e4));
        if (frame.rgb.width == frame.intrinsics.width && frame.rgb.height == frame.intrinsics.height) {
          const std::uint8_t* rgb = frame.rgb.at(u, v);
          colors.push_back(rgb[0]);
          colors.push_back(rgb[1]);
          colors.push_back(rgb[2]);
        }
      }
    }
    return json{{"frame", "world"},
                {"camera", poseJson(frame.camera_pose)},
                {"t", toSeconds(frame.stamp)},
                {"points", std::move(points)},
                {"colors", std::move(colors)}};
  });
}

// --- snapshots and the stream ------------------------------------------------------------------

json Engine::buildState() const {
  const world::WorldState& world = cell_.components().world();
  json state = {{"type", "state"}, {"t", rounded(toSeconds(cell_.clock().now()), 1e4)}};
  const std::int64_t active = active_run_.load();
  state["run"] = active;
  state["mode"] = active == 0 ? "idle" : (paused_ ? "paused" : "running");

  std::set<std::string> arm_sources;
  std::set<std::string> declared;
  const arm::ArmComponent* arm = nullptr;
  for (const auto& component : cell_.components().components()) {
    const auto& description = component->description();
    if (std::find(description.implements.begin(), description.implements.end(), "Arm") !=
        description.implements.end()) {
      arm_sources.insert(description.name);
      if (arm == nullptr) {
        arm = dynamic_cast<const arm::ArmComponent*>(component.get());
      }
    }
    for (const auto& symbol : description.symbols) {
      declared.insert(symbol.name);
    }
  }

  json arm_json = json::object();
  if (const auto endpoint = world.worldPose("endpoint")) {
    arm_json["endpoint"] = poseJson(*endpoint);
  }
  if (const world::Symbol* joints = world.symbol("arm_joints"); joints != nullptr && joints->joints() != nullptr) {
    json positions = json::array();
    for (const double q : joints->joints()->positions) {
      positions.push_back(rounded(q));
    }
    arm_json["joints"] = std::move(positions);
  }
  arm_json["moving"] = world.holds("arm_moving", kNoArgs);
  state["arm"] = std::move(arm_json);

  json gripper = {{"open", world.holds("gripper_open", kNoArgs)},
                  {"closed", world.holds("gripper_closed", kNoArgs)},
                  {"holding", world.holds("gripper_holding", kNoArgs)}};
  for (const world::Predicate* predicate : world.predicates("gripper_mode")) {
    if (predicate->value && !predicate->args.empty()) {
      gripper["mode"] = predicate->args.front();
    }
  }
  state["gripper"] = std::move(gripper);

  std::set<std::string> objects;
  json objects_json = json::array();
  for (const world::Predicate* predicate : world.predicates("is_a")) {
    if (!predicate->value || predicate->args.size() != 2 || objects.contains(predicate->args[0])) {
      continue;
    }
    const auto pose = world.worldPose(predicate->args[0]);
    if (!pose) {
      continue;
    }
    objects.insert(predicate->args[0]);
    json item = poseJson(*pose);
    item["name"] = predicate->args[0];
    item["class"] = predicate->args[1];
    item["source"] = predicate->source;
    objects_json.push_back(std::move(item));
  }
  state["objects"] = std::move(objects_json);

  json waypoints = json::array();
  json frames = json::array();
  for (const world::Symbol* symbol : world.symbols()) {
    if (arm_sources.contains(symbol->source) && !declared.contains(symbol->name)) {
      json item = {{"name", symbol->name}};
      if (const world::FrameValue* frame = symbol->frame()) {
        item["kind"] = "pose";
        item["frame"] = frame->parent;
        if (const auto pose = world.worldPose(symbol->name)) {
          item.update(poseJson(*pose));
        }
      } else if (const world::JointsValue* joints = symbol->joints()) {
        item["kind"] = "joints";
        if (arm != nullptr && joints->positions.size() == arm::kJointCount) {
          arm::JointVector q{};
          std::copy(joints->positions.begin(), joints->positions.end(), q.begin());
          item.update(poseJson(arm->toolAt(q)));
        }
      }
      waypoints.push_back(std::move(item));
    } else if (symbol->frame() != nullptr && !objects.contains(symbol->name) && symbol->name != "endpoint") {
      json item = {{"name", symbol->name}, {"parent", symbol->frame()->parent}};
      if (const auto pose = world.worldPose(symbol->name)) {
        item.update(poseJson(*pose));
      }
      frames.push_back(std::move(item));
    }
  }
  state["waypoints"] = std::move(waypoints);
  state["frames"] = std::move(frames);

  json predicates = json::array();
  for (const world::Predicate* predicate : world.predicates()) {
    if (predicate->value && predicate->name != "is_a") {
      predicates.push_back(predicate->str());
      if (predicates.size() >= 2000) {
        break;
      }
    }
  }
  state["predicates"] = std::move(predicates);
  return state;
}

void Engine::takeSnapshot() {
  const auto begin = std::chrono::steady_clock::now();
  std::string text = buildState().dump(-1, ' ', false, json::error_handler_t::replace);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
  const std::lock_guard lock(mutex_);
  state_json_ = std::move(text);
  ++state_version_;
  ++stats_.snapshots;
  stats_.snapshot_seconds += seconds;
}

std::vector<std::string> Engine::drainStream() {
  std::vector<std::string> out;
  std::optional<json> statuses;
  std::string state;
  {
    const std::lock_guard lock(mutex_);
    out.swap(events_);
    if (current_ && current_->active && !current_->dirty.empty()) {
      statuses = statusesJson(*current_, true);
    }
    if (state_version_ != drained_state_version_) {
      drained_state_version_ = state_version_;
      state = state_json_;
    }
  }
  if (statuses) {
    out.push_back(statuses->dump(-1, ' ', false, json::error_handler_t::replace));
  }
  if (!state.empty()) {
    out.push_back(std::move(state));
  }
  return out;
}

std::string Engine::helloMessage() {
  json hello = {{"type", "hello"}, {"info", info()}};
  std::string state;
  {
    const std::lock_guard lock(mutex_);
    if (current_) {
      json run = runJson(*current_, true);
      run["statuses"] = statusesJson(*current_, false)["nodes"];
      hello["run"] = std::move(run);
    } else {
      hello["run"] = nullptr;
    }
    state = state_json_;
  }
  std::string text = hello.dump(-1, ' ', false, json::error_handler_t::replace);
  text.pop_back();  // '}'
  return text + ",\"state\":" + state + "}";
}

EngineStats Engine::stats() const {
  const std::lock_guard lock(mutex_);
  return stats_;
}

void Engine::setPace(double pace) {
  pace_request_ = std::max(0.0, pace);
  task_cv_.notify_all();
}

// --- the run log writer --------------------------------------------------------------------

void Engine::pushLog(LogCommand command) {
  {
    const std::lock_guard lock(log_mutex_);
    if (command.kind == LogCommand::Kind::kEnd && !log_pending_.empty()) {
      LogCommand transitions;
      transitions.kind = LogCommand::Kind::kTransitions;
      transitions.record.id = log_pending_run_;
      transitions.transitions.swap(log_pending_);
      log_queue_.push_back(std::move(transitions));
    }
    log_queue_.push_back(std::move(command));
  }
  log_cv_.notify_all();
}

void Engine::logWriterLoop() {
  while (true) {
    std::deque<LogCommand> commands;
    bool stopping = false;
    {
      std::unique_lock lock(log_mutex_);
      log_cv_.wait_for(lock, std::chrono::milliseconds(200), [this] { return log_stopping_ || !log_queue_.empty(); });
      if (!log_pending_.empty()) {
        LogCommand transitions;
        transitions.kind = LogCommand::Kind::kTransitions;
        transitions.record.id = log_pending_run_;
        transitions.transitions.swap(log_pending_);
        log_queue_.push_back(std::move(transitions));
      }
      commands.swap(log_queue_);
      stopping = log_stopping_;
    }
    for (LogCommand& command : commands) {
      if (store_ == nullptr) {
        continue;
      }
      try {
        switch (command.kind) {
          case LogCommand::Kind::kBegin:
            store_->beginRun(command.record, command.nodes);
            break;
          case LogCommand::Kind::kTransitions:
            store_->appendTransitions(command.record.id, command.transitions);
            break;
          case LogCommand::Kind::kEnd:
            store_->endRun(command.record);
            break;
        }
      } catch (const std::exception&) {
        // The run log is best effort: a full disk must not stop the robot.
      }
    }
    if (stopping && commands.empty()) {
      return;
    }
  }
}

}  // namespace costar::server
