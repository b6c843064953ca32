#pragma once
// The Engine owns the workcell for the server: one thread (the executor's) ticks plans,
// single operations and, between them, an idle loop that keeps the world state fresh and the
// simulated robot alive. Nothing else touches the workcell, its world state or a tree:
// network threads hand work to the engine thread (validation, starting runs, snapshots of
// what the editor lists) and read copies that the engine thread publishes:
//   - a snapshot of the cell (joints, endpoint, gripper, objects, waypoints, frames,
//     predicates) at most `stream_hz` times a wall second,
//   - each node's last status in the active run (coalesced between two reads of the stream),
//   - run start and end events.
// Every status transition of a plan run also goes to the store's run log, written by a
// separate thread in batches, so ticks never wait for the disk.
//
// A simulated clock is paced to `pace` times real time for a person watching (0: as fast as
// the machine allows while a plan runs; the idle loop then runs at real time).
//
// Pausing holds the cell: while a run is paused the engine thread does not advance the clock,
// so a simulated cell stands still (the arm where it was, the fingers as they were) and no
// operation's time limit runs out while nobody ticks it; a step ticks the tree once and lets one
// tick period pass. A real clock cannot be held: there the tree is not ticked, and time goes on.

#include <atomic>
#include <deque>
#include <filesystem>
#include <functional>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "bt/executor.h"
#include "bt/tree.h"
#include "server/backend.h"
#include "server/pacing.h"
#include "server/palette.h"
#include "server/run_controls.h"
#include "server/run_lifecycle.h"
#include "server/run_log_writer.h"
#include "server/run_state.h"
#include "server/store.h"
#include "server/task_queue.h"

namespace costar::workcell {
class Workcell;
}

namespace costar::server {

struct EngineOptions {
  /// Simulated seconds per wall second (simulated clocks only); 0: unpaced runs.
  double pace = 1.0;
  /// Time between ticks (clock time).
  Duration tick_period = std::chrono::milliseconds(10);
  /// Snapshots of the cell per wall second (the stream's rate).
  double stream_hz = 20.0;
  /// Transitions kept in the run log per run; the rest are counted, not stored.
  std::size_t max_logged_transitions = 200'000;
  /// How long a network thread waits for the engine thread to answer (then 503).
  std::chrono::milliseconds call_timeout{20000};
  /// Finished runs and operations remembered for GET /api/runs/{id}.
  std::size_t remembered_runs = 64;
  /// Grasp files offered as choices (read-only here; SmartMove's GraspLibrary owns them).
  std::filesystem::path grasp_defaults;
  std::filesystem::path grasp_taught;
  /// Builds the cell afresh (its scene from its file and seed, the arm at home) for "Reset
  /// scene"; empty: the scene cannot be reset.
  std::function<std::unique_ptr<workcell::Workcell>()> make_cell;
  /// Snapshots of the cell kept in a plan run's log per second of clock time (replay draws the
  /// arm, the gripper and the parts from them); 0: none.
  double logged_state_hz = 5.0;
};

/// Counters of the engine thread, for benchmarks and the info endpoint.
struct EngineStats {
  std::uint64_t ticks = 0;        // before-tick hooks run (plan ticks, idle ticks, held periods while paused)
  std::uint64_t snapshots = 0;    // state snapshots taken
  double snapshot_seconds = 0;    // wall time spent taking them
  double paced_wait_seconds = 0;  // wall time waited for the pace
  std::uint64_t runs = 0;         // runs started (plans and operations)
};

class Engine final : public Backend {
 public:
  /// `cell` and `store` (may be null: nothing logged) must outlive the engine.
  Engine(workcell::Workcell& cell, Store* store, EngineOptions options = {});
  /// The same, owning the cell.
  Engine(std::unique_ptr<workcell::Workcell> cell, Store* store, EngineOptions options = {});
  ~Engine() override;
  Engine(const Engine&) = delete;
  Engine& operator=(const Engine&) = delete;

  /// Starts the engine thread (and the log writer).
  void startThread();
  /// Stops the active run (cancelling its operations), ends the threads, writes what is
  /// left of the run log. Idempotent.
  void shutdown();

  // --- Backend ----------------------------------------------------------------------------
  nlohmann::json info() override;
  const std::string& nodesJson() override { return palette_.nodes_json; }
  nlohmann::json choices() override;
  std::vector<bt::Diagnostic> validate(const bt::Plan& plan) override;
  std::vector<bt::Diagnostic> checkForCell(const bt::Plan& plan) override;
  StartResult start(RunRequest request) override;
  bool control(RunControl control) override;
  nlohmann::json state() override;
  std::optional<nlohmann::json> runStatus(std::optional<std::int64_t> id) override;
  std::optional<nlohmann::json> groundTruth() override;
  std::optional<nlohmann::json> pointCloud(std::size_t max_points) override;
  std::optional<nlohmann::json> robot() override;
  StartResult resetScene() override;
  DragResult drag(const Drag& drag) override;

  // --- the live stream ----------------------------------------------------------------------
  /// The messages since the last call, in order: run_started, statuses (each changed node's
  /// current and last status, failure reason, operation data), run_ended, and the newest
  /// state snapshot if there is a new one. One caller (the broadcaster).
  std::vector<std::string> drainStream() override;
  /// The first message for a newly connected client: info, the active (or last) run with
  /// every node's status, and the latest snapshot.
  std::string helloMessage() override;

  /// The fatal-error path (fatal.h): asks the engine thread to stop the active run (which
  /// cancels its operations: the arm decelerates and stops). Async-signal-safe.
  void requestStop() noexcept { controls_.requestStop(); }
  /// Whether a run or an operation is active. Async-signal-safe.
  bool runActive() const noexcept { return active_run_.load() != 0; }

  EngineStats stats() const;
  /// Changes the pace (thread-safe).
  void setPace(double pace);

 private:
  /// Runs `task` on the engine thread and waits for its result.
  template <typename F>
  auto call(F task) -> decltype(task());

  /// What a plan names that the cell does not know now: waypoints (unless the plan teaches
  /// them), frames (unless it detects parts first), object classes (engine thread).
  std::vector<bt::Diagnostic> checkAgainstCell(const bt::Plan& plan);
  /// Every problem of a plan for this cell: the plan's own, then checkAgainstCell (engine thread).
  std::vector<bt::Diagnostic> problems(const bt::Plan& plan);
  void loop();
  /// Before each tick (a run's or the idle loop's): answers the network, applies a pace asked
  /// for, refreshes the cell, publishes a snapshot when one is due, waits for the pace.
  void hook();
  /// Holds a paused run (the clock stands still) until it resumes, a step is asked for (then
  /// true: tick once) or it is stopped.
  void holdWhilePaused(bt::Executor& executor);
  /// Keeps a snapshot of the cell in the run's log when one is due (clock time).
  void logState(const RunState& run);
  void waitWall(std::chrono::steady_clock::duration duration);
  void executePending();
  void takeSnapshot();

  std::unique_ptr<workcell::Workcell> owned_cell_;  // a cell made by the engine (reset), or given to it
  workcell::Workcell* cell_;                        // the cell now (engine thread only, after construction)
  EngineOptions options_;
  /// Whose grasps the choices offer: the cell's gripper's (robotDrawing's gripper.grasps; the
  /// 3-finger gripper's on iiwa-3f-sim, not the 2-finger one's).
  std::string grasp_gripper_;
  const Palette palette_;

  std::thread thread_;
  std::atomic<bool> stopping_{false};
  // Work handed to the engine thread.
  TaskQueue tasks_;
  // Plan runs to the store (null without a store).
  std::unique_ptr<RunLogWriter> log_;

  // Control of the active run, set by network threads, applied by the engine thread.
  std::atomic<std::int64_t> active_run_{0};
  RunControls controls_;

  // The pace, asked for by any thread, kept by the engine thread.
  PaceControl pace_;

  // Engine-thread only.
  std::optional<PreparedRun> pending_;  // started, to execute
  std::chrono::steady_clock::time_point next_snapshot_{};
  bool start_paused_ = false;
  TimePoint next_logged_state_{};

  // Published for network threads (guarded by mutex_).
  mutable std::mutex mutex_;
  std::shared_ptr<RunState> current_;               // the active or last run
  std::deque<std::shared_ptr<RunState>> finished_;  // recent runs
  std::vector<std::string> events_;                 // stream messages not yet drained
  std::string state_json_;
  std::uint64_t state_version_ = 0;
  std::uint64_t drained_state_version_ = 0;
  EngineStats stats_;
  std::int64_t next_run_id_ = 1;
  std::int64_t next_operation_id_ = -1;
  std::string last_error_;  // the last exception of the idle loop, shown by info()
};

}  // namespace costar::server
