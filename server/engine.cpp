// The Engine's thread: the loop (idle ticks between runs, paced), starting and executing runs,
// holding a paused one. The work network threads hand it comes through task_queue.h; a run's
// state and JSON are run_state.h's, its observer run_observer.h's, its pause, step and stop
// run_controls.h's; the lists the editor offers are in engine_lists.cpp (the palette in
// palette.cpp), what the stream shows in engine_views.cpp (the cell's state in
// cell_state.cpp), the simulator's views in engine_sim_views.cpp; runs are logged by
// run_log_writer.h.

#include "server/engine_parts.h"

#include "bt/builder.h"
#include "component/nodes.h"
#include "server/cell_state.h"
#include "server/guard.h"
#include "server/plan_json.h"
#include "server/run_observer.h"
#include "workcell/workcell.h"

namespace costar::server {

Engine::Engine(std::unique_ptr<workcell::Workcell> cell, Store* store, EngineOptions options)
    : Engine(*cell, store, std::move(options)) {
  owned_cell_ = std::move(cell);
}

Engine::Engine(workcell::Workcell& cell, Store* store, EngineOptions options)
    : cell_(&cell), options_(std::move(options)), palette_(describePalette(cell)) {
  const double pace = options_.pace;
  pacer_.setFactor(pace > 0 ? pace : 1.0);
  if (store != nullptr) {
    next_run_id_ = store->maxRunId() + 1;
    log_ = std::make_unique<RunLogWriter>(*store);
  }
  takeSnapshot();
}

Engine::~Engine() { shutdown(); }

void Engine::startThread() {
  if (!tasks_.open()) {
    return;
  }
  if (log_) {
    log_->start();
  }
  // An exception that escapes the loop is logged and the loop goes on (guard.h).
  thread_ = std::thread([this] {
    prepareServerThread("engine");
    while (!guarded("engine thread", [this] { loop(); })) {
    }
  });
}

void Engine::shutdown() {
  if (!tasks_.close()) {
    return;
  }
  stopping_ = true;
  controls_.requestStop();
  tasks_.notify();
  if (thread_.joinable()) {
    thread_.join();
  }
  if (log_) {
    log_->stop();
  }
}

void Engine::waitWall(std::chrono::steady_clock::duration duration) {
  const auto deadline = std::chrono::steady_clock::now() + duration;
  while (!stopping_) {
    tasks_.waitUntil(deadline);
    tasks_.runPending();
    if (std::chrono::steady_clock::now() >= deadline) {
      return;
    }
  }
}

void Engine::loop() {
  while (!stopping_) {
    tasks_.runPending();
    if (pending_tree_) {
      executePending();
      continue;
    }
    try {
      hook(false);
      Clock& clock = cell_->clock();
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
  tasks_.runPending();
}

void Engine::hook(bool running) {
  tasks_.runPending();
  if (const double pace = pace_request_.exchange(-1); pace >= 0) {
    {
      const std::lock_guard lock(mutex_);
      options_.pace = pace;
    }
    pacer_.setFactor(running && pace <= 0 ? 0.0 : (pace > 0 ? pace : 1.0));
  }
  cell_->beforeTick();
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
  if (cell_->clock().simulated()) {
    const auto delay = pacer_.delay(cell_->clock().now(), std::chrono::steady_clock::now());
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

  RunObserver observer(*run, mutex_, log_.get(), options_.max_logged_transitions);
  tree.addObserver(&observer);
  bt::ExecutorOptions executor_options;
  executor_options.tick_period = options_.tick_period;
  bt::Executor executor(tree, cell_->clock(), executor_options);
  controls_.setPaused(start_paused_);
  next_logged_state_ = cell_->clock().now();
  executor.setBeforeTick([this, &executor, &run] {
    hook(true);
    logState(*run);
    if (controls_.apply(executor)) {
      return;
    }
    holdWhilePaused(executor);
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
  tree.removeObserver(&observer);
  pacer_.setFactor(options_.pace > 0 ? options_.pace : 1.0);
  cell_->beforeTick();
  next_logged_state_ = TimePoint::min();  // the cell as the run left it
  logState(*run);

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
      events_.push_back(jsonText(statusesJson(*run, true)));
    }
    events_.push_back(jsonText({{"type", "run_ended"}, {"run", runJson(*run, controls_.paused(), false)}}));
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
  controls_.reset(false);
  if (!run->operation && log_) {
    log_->end(std::move(record));
  }
  cell_->beforeTick();
  takeSnapshot();
}

void Engine::holdWhilePaused(bt::Executor& executor) {
  if (!controls_.paused()) {
    return;
  }
  bool held = false;
  while (true) {
    if (controls_.takeStep()) {
      break;  // this tick; the executor then lets one tick period pass
    }
    // The clock stands still: a wall-clock period of waiting (answering the network), the
    // world refreshed and shown as it is.
    held = true;
    waitWall(options_.tick_period);
    cell_->beforeTick();
    const auto now = std::chrono::steady_clock::now();
    if (now >= next_snapshot_) {
      takeSnapshot();
      next_snapshot_ = now + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                 std::chrono::duration<double>(1.0 / std::max(1.0, options_.stream_hz)));
    }
    {
      const std::lock_guard lock(mutex_);
      ++stats_.ticks;
    }
    if (controls_.apply(executor) || !controls_.paused() || stopping_) {
      break;
    }
  }
  if (held) {
    pacer_.reset();  // the clock stood still on purpose: no burst to catch up
  }
}

void Engine::logState(const RunState& run) {
  if (run.operation || !log_ || options_.logged_state_hz <= 0) {
    return;
  }
  const TimePoint now = cell_->clock().now();
  if (now < next_logged_state_) {
    return;
  }
  next_logged_state_ = now + fromSeconds(1.0 / options_.logged_state_hz);
  json state = cellState(*cell_, active_run_.load(), controls_.paused());
  state.erase("waypoints");
  state.erase("frames");
  StateRecord record;
  record.t = toSeconds(now - run.start_time);
  record.state = jsonText(state);
  log_->addState(run.id, std::move(record));
}

std::vector<bt::Diagnostic> Engine::problems(const bt::Plan& plan) {
  std::vector<bt::Diagnostic> diagnostics = bt::validatePlan(plan, cell_->nodes());
  for (bt::Diagnostic& diagnostic : checkAgainstCell(plan)) {
    diagnostics.push_back(std::move(diagnostic));
  }
  return diagnostics;
}

std::vector<bt::Diagnostic> Engine::validate(const bt::Plan& plan) {
  return call(
      [this, copy = std::make_shared<const bt::Plan>(plan)] { return bt::validatePlan(*copy, cell_->nodes()); });
}

std::vector<bt::Diagnostic> Engine::checkForCell(const bt::Plan& plan) {
  return call([this, copy = std::make_shared<const bt::Plan>(plan)] { return problems(*copy); });
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
      const bt::NodeSpec* spec = cell_->nodes().find(main->root.id);
      if (spec != nullptr && spec->kind != bt::NodeKind::kAction && spec->kind != bt::NodeKind::kCondition) {
        out.status = 422;
        out.error = "an operation is one action or condition, not a " + std::string(bt::toString(spec->kind));
        return out;
      }
    }
    try {
      if (auto diagnostics = problems(request.plan); !diagnostics.empty()) {
        out.status = 422;
        out.diagnostics = std::move(diagnostics);
        return out;
      }
      pending_tree_.emplace(bt::buildTree(request.plan, cell_->nodes(), cell_->clock()));
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
    run->workcell = cell_->name();
    if (!request.operation) {
      run->plan_json = planFileToJson(request.plan.file);
    }
    for (const bt::TreeNode* node : pending_tree_->nodes()) {
      run->nodes.push_back({node->uid(),
                            node->parent() != nullptr ? static_cast<std::int64_t>(node->parent()->uid()) : -1,
                            node->id(), node->name(), node->path()});
    }
    run->statuses.resize(run->nodes.size());
    run->start_time = cell_->clock().now();
    run->started_at = unixNow();
    controls_.reset(request.start_paused);
    start_paused_ = request.start_paused;
    {
      const std::lock_guard lock(mutex_);
      // Plan runs are numbered 1, 2, 3 ... as the run log numbers them; single operations (a
      // jog, a menu button) are not runs of a plan and count apart, downwards from -1.
      run->id = run->operation ? next_operation_id_-- : next_run_id_++;
      current_ = run;
      ++stats_.runs;
      events_.push_back(jsonText({{"type", "run_started"}, {"run", runJson(*run, controls_.paused(), true)}}));
    }
    active_run_ = run->id;
    if (!run->operation && log_) {
      RunRecord begin;
      begin.id = run->id;
      begin.plan = run->plan_name;
      begin.version = run->version;
      begin.xml = run->xml;
      begin.started_at = run->started_at;
      begin.workcell = cell_->name();
      log_->begin(std::move(begin), run->nodes);
    }
    pending_run_ = run;
    out.run_id = run->id;
    return out;
  });
}

StartResult Engine::resetScene() {
  return call([this]() -> StartResult {
    StartResult out;
    if (!options_.make_cell || cell_->simulation() == nullptr) {
      out.status = 404;
      out.error = "this cell has no simulated scene to reset";
      return out;
    }
    if (active_run_ != 0 || pending_tree_) {
      out.status = 409;
      out.error = "run " + std::to_string(active_run_.load()) + " is active: stop it before resetting the scene";
      return out;
    }
    try {
      std::unique_ptr<workcell::Workcell> fresh = options_.make_cell();
      if (fresh->name() != cell_->name()) {
        out.status = 500;
        out.error = "the reset made a different cell ('" + fresh->name() + "')";
        return out;
      }
      owned_cell_ = std::move(fresh);  // the old one (if the engine owned it) goes here
      cell_ = owned_cell_.get();
    } catch (const std::exception& error) {
      out.status = 500;
      out.error = std::string("the scene could not be made again: ") + error.what();
      return out;
    }
    pacer_.reset();
    cell_->beforeTick();
    takeSnapshot();
    {
      const std::lock_guard lock(mutex_);
      events_.push_back(json{{"type", "scene_reset"}, {"t", toSeconds(cell_->clock().now())}}.dump());
    }
    return out;  // status 0: done
  });
}

bool Engine::control(RunControl control) {
  if (active_run_ == 0) {
    return false;
  }
  controls_.request(control);
  tasks_.notify();
  return true;
}

EngineStats Engine::stats() const {
  const std::lock_guard lock(mutex_);
  return stats_;
}

void Engine::setPace(double pace) {
  pace_request_ = std::max(0.0, pace);
  tasks_.notify();
}

}  // namespace costar::server
