#pragma once
// What the HTTP API and its live stream need from the system behind it. The Engine (engine.h)
// implements it on a workcell; the fuzz targets and some tests implement it without one.

#include <array>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "bt/plan.h"

namespace costar::server {

/// A plan to run: parsed (not yet validated; the backend validates it where the workcell lives).
struct RunRequest {
  bt::Plan plan;
  /// The plan file as it will be logged (bt::writePlanFile of plan.file).
  std::string xml;
  /// The saved plan it came from, if any.
  std::string plan_name;
  int version = 0;
  /// A single operation from the menu or the waypoint panel: not written to the run log.
  bool operation = false;
  /// Start paused (for stepping through from the first tick).
  bool start_paused = false;
};

struct StartResult {
  /// The run's id when it started.
  std::int64_t run_id = 0;
  /// On refusal: an HTTP status (409 busy, 422 invalid plan) and why.
  int status = 0;
  std::string error;
  std::vector<bt::Diagnostic> diagnostics;
  bool started() const { return run_id != 0; }
};

enum class RunControl { kPause, kResume, kStep, kStop };

/// Thrown when the backend cannot answer in time (its thread is stuck in a long computation)
/// or is shutting down: the API answers 503.
class BackendBusy : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class Backend {
 public:
  virtual ~Backend() = default;
  /// Workcell name and description, clock kind, pacing, features the menu offers.
  virtual nlohmann::json info() = 0;
  /// Every node type (the palette), as JSON text; fixed for the server's lifetime.
  virtual const std::string& nodesJson() = 0;
  /// What the system knows now, for the editor's lists: waypoints, frames, object classes,
  /// predicates (name, arity), grasps per class.
  virtual nlohmann::json choices() = 0;
  /// Every problem of a plan against the workcell's node types (what saving refuses).
  virtual std::vector<bt::Diagnostic> validate(const bt::Plan& plan) = 0;
  /// validate() and what the plan names that the cell does not know now (a waypoint renamed
  /// or deleted, a frame that is gone): what Check shows and a run refuses. A plan saved today
  /// may name a waypoint taught tomorrow, so saving does not refuse these.
  virtual std::vector<bt::Diagnostic> checkForCell(const bt::Plan& plan) { return validate(plan); }
  /// Starts a run unless one is active (409) or the plan is invalid (422).
  virtual StartResult start(RunRequest request) = 0;
  /// Pause, resume, single step or stop the active run (stop halts it, which cancels its
  /// operations: the arm decelerates and stops). False when nothing runs.
  virtual bool control(RunControl control) = 0;
  /// The latest snapshot of the cell (same as the stream's "state" message).
  virtual nlohmann::json state() = 0;
  /// A run the backend still remembers (the active one, recent ones, operations), with its
  /// nodes' last statuses; nullopt for an unknown id. No id: the active or last run.
  virtual std::optional<nlohmann::json> runStatus(std::optional<std::int64_t> id) = 0;
  /// TEST ONLY: the simulator's true part poses (nullopt without a simulator).
  virtual std::optional<nlohmann::json> groundTruth() = 0;
  /// Points seen by the cell's RGB-D camera, in the world frame (nullopt without one).
  virtual std::optional<nlohmann::json> pointCloud(std::size_t max_points) = 0;
  /// The cell's robot as the editor draws it: the URDF the planner reads (the arm's with the
  /// gripper's mounted on its flange), where it stands, its joints and its gripper (nullopt
  /// for a cell without a robot).
  virtual std::optional<nlohmann::json> robot() { return std::nullopt; }
  /// Simulated cells: builds the scene afresh from its file and seed, the arm at home. Status 0
  /// when done; refused (409) while a run or an operation is active, 404 for a cell without a
  /// scene.
  virtual StartResult resetScene() {
    StartResult refused;
    refused.status = 404;
    refused.error = "this cell has no simulated scene to reset";
    return refused;
  }

  /// Free-drive's hand and dead-man (docs/TEACHING.md): while a FreeDrive operation runs, the
  /// person's push on the tool (force N and torque N m, world axes, at the tool centre point).
  /// The page sends one every kDragPeriod (50 ms) while the pointer is held; each is a lease of
  /// two lengths: the push acts for `push_seconds` (kDragPushSeconds: the arm moves only on a
  /// push at most 0.25 s old, so a page that stalls or dies leaves the arm standing within it),
  /// and the dead-man stays held for `hold_seconds` (kDragLeaseSeconds, 2 s: a page whose timer
  /// runs late on a loaded machine keeps free-drive and its recording instead of losing them;
  /// when the pushes stop for longer it lapses: the arm stops and holds, the operation ends).
  /// `release` (the pointer let go) lets go now. Status 0 when applied, with why free-drive's last
  /// step was not wholly taken (a contact ahead, a joint limit, near a singularity: what the page
  /// shows the person guiding) and its speed; 409 when no FreeDrive runs, 404 for a cell without a
  /// simulator (a real arm is pushed by a real hand, with the arm's own enabling button).
  static constexpr double kDragPeriodSeconds = 0.05;
  static constexpr double kDragPushSeconds = 0.25;
  static constexpr double kDragLeaseSeconds = 2.0;
  struct Drag {
    std::array<double, 3> force{};
    std::array<double, 3> torque{};
    double push_seconds = kDragPushSeconds;
    double hold_seconds = kDragLeaseSeconds;
    bool release = false;
  };
  struct DragResult {
    int status = 0;  // as StartResult's
    std::string error;
    std::string blocked;  // arm::ArmComponent::FreeDriveStatus::blocked (empty: the step was taken)
    double speed = 0.0;   // m/s of free-drive's reference
  };
  virtual DragResult drag(const Drag& drag) {
    DragResult refused;
    refused.status = 404;
    refused.error = "this backend has no arm to guide";
    (void)drag;
    return refused;
  }

  // --- the live stream (the WebSocket of http_server.cpp) ------------------------------------
  /// The messages since the last call, in order (JSON texts). One caller (the broadcaster).
  virtual std::vector<std::string> drainStream() = 0;
  /// The first message for a newly connected client (JSON text).
  virtual std::string helloMessage() = 0;
};

}  // namespace costar::server
