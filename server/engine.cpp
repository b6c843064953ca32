// The Engine's thread: the loop (idle ticks between runs, paced), starting and executing runs,
// holding a paused one. The work network threads hand it comes through task_queue.h; a run is
// prepared and ended by run_lifecycle.h, its state and JSON are run_state.h's, its observer
// run_observer.h's, its pause, step and stop run_controls.h's, the pace pacing.h's; the lists
// the editor offers are in engine_lists.cpp (the palette in palette.cpp), what the stream
// shows in engine_views.cpp (the cell's state in cell_state.cpp), the simulator's views in
// engine_sim_views.cpp; runs are logged by run_log_writer.h.

#include "server/engine_parts.h"

#include "arm/arm_component.h"
#include "bt/builder.h"
#include "server/cell_state.h"
#include "server/guard.h"
#include "server/run_lifecycle.h"
#include "server/run_observer.h"
#include "sim/simulation.h"
#include "smartmove/grasps.h"
#include "workcell/workcell.h"

namespace costar::server {

Engine::Engine(std::unique_ptr<workcell::Workcell> cell, Store* store, EngineOptions options)
    : Engine(*cell, store, std::move(options)) {
  owned_cell_ = std::move(cell);
}

Engine::Engine(workcell::Workcell& cell, Store* store, EngineOptions options)
    : cell_(&cell), options_(std::move(options)), palette_(describePalette(cell)), pace_(options_.pace) {
  if (!options_.grasp_defaults.empty()) {
    const nlohmann::json drawing = cell.robotDrawing();
    grasp_gripper_ = drawing.is_object() && drawing.contains("gripper")
                         ? drawing["gripper"].value("grasps", std::string(smartmove::kParallelGripper))
                         : std::string(smartmove::kParallelGripper);
  }
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
    if (pending_) {
      executePending();
      continue;
    }
    try {
      hook();
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

void Engine::hook() {
  tasks_.runPending();
  pace_.apply();
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
    const auto delay = pace_.delay(cell_->clock().now(), std::chrono::steady_clock::now());
    if (delay > std::chrono::steady_clock::duration::zero()) {
      waitWall(delay);
      const std::lock_guard lock(mutex_);
      stats_.paced_wait_seconds += std::chrono::duration<double>(delay).count();
    }
  }
}

void Engine::executePending() {
  std::shared_ptr<RunState> run = std::move(pending_->run);
  bt::Tree tree = std::move(pending_->tree);
  pending_.reset();

  RunObserver observer(*run, mutex_, log_.get(), options_.max_logged_transitions);
  tree.addObserver(&observer);
  bt::ExecutorOptions executor_options;
  executor_options.tick_period = options_.tick_period;
  bt::Executor executor(tree, cell_->clock(), executor_options);
  controls_.setPaused(start_paused_);
  next_logged_state_ = cell_->clock().now();
  executor.setBeforeTick([this, &executor, &run] {
    hook();
    logState(*run);
    if (controls_.apply(executor)) {
      return;
    }
    holdWhilePaused(executor);
  });
  pace_.runBegins();

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
  pace_.runEnds();
  cell_->beforeTick();
  next_logged_state_ = TimePoint::min();  // the cell as the run left it
  logState(*run);

  {
    const std::lock_guard lock(mutex_);
    endRun(*run, result, threadCpuSeconds() - cpu_start,
           std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count());
    if (!run->dirty.empty()) {
      events_.push_back(jsonText(statusesJson(*run, true)));
    }
    events_.push_back(jsonText({{"type", "run_ended"}, {"run", runJson(*run, controls_.paused(), false)}}));
    finished_.push_front(run);
    while (finished_.size() > options_.remembered_runs) {
      finished_.pop_back();
    }
  }
  active_run_ = 0;
  controls_.reset(false);
  if (!run->operation && log_) {
    log_->end(runRecord(*run));
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
    pace_.reset();  // the clock stood still on purpose: no burst to catch up
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
    const RunRequest& request = *shared;
    StartResult out;
    if (active_run_ != 0 || pending_) {
      out.status = 409;
      out.error = "run " + std::to_string(active_run_.load()) + " is active: stop it or wait for it to end";
      return out;
    }
    auto prepared = prepareRun(request, *cell_, [this](const bt::Plan& plan) { return problems(plan); });
    if (auto* refusal = std::get_if<StartResult>(&prepared)) {
      return std::move(*refusal);
    }
    pending_.emplace(std::move(std::get<PreparedRun>(prepared)));
    const std::shared_ptr<RunState>& run = pending_->run;
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
      log_->begin(runRecord(*run), run->nodes);
    }
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
    if (active_run_ != 0 || pending_) {
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
    pace_.reset();
    cell_->beforeTick();
    takeSnapshot();
    {
      const std::lock_guard lock(mutex_);
      events_.push_back(json{{"type", "scene_reset"}, {"t", toSeconds(cell_->clock().now())}}.dump());
    }
    return out;  // status 0: done
  });
}

Backend::DragResult Engine::drag(const Drag& request) {
  return call([this, request]() -> DragResult {
    DragResult out;
    sim::Simulation* simulation = cell_->simulation();
    auto* arm = dynamic_cast<arm::ArmComponent*>(cell_->components().provider("FreeDrive"));
    if (simulation == nullptr || arm == nullptr) {
      out.status = 404;
      out.error = "this cell has no simulated arm to guide by hand";
      return out;
    }
    if (request.release) {
      simulation->setHandWrench({});
      arm->releaseFreeDrive();
      return out;
    }
    const auto hold = std::chrono::duration_cast<Duration>(std::chrono::duration<double>(request.hold_seconds));
    if (!arm->holdFreeDrive(hold)) {
      simulation->setHandWrench({});
      out.status = 409;
      out.error = "free-drive is off: start the FreeDrive operation first (refused while a plan runs)";
      return out;
    }
    arm::Wrench hand;
    hand.force = Eigen::Vector3d(request.force[0], request.force[1], request.force[2]);
    hand.torque = Eigen::Vector3d(request.torque[0], request.torque[1], request.torque[2]);
    simulation->setHandWrench(
        hand, std::chrono::duration_cast<Duration>(std::chrono::duration<double>(request.push_seconds)));
    const arm::ArmComponent::FreeDriveStatus status = arm->freeDriveStatus();
    out.blocked = status.blocked;
    out.speed = status.speed;
    return out;
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
  pace_.request(pace);
  tasks_.notify();
}

}  // namespace costar::server
