#pragma once
// A workcell: the clock, the components and the node types a plan runs against. The CLI
// and the server pick one by name: "ur5-sim" (the simulated UR5 cell, the default robot),
// "test" (test components without a robot), "none" (built-in nodes only).

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "bt/registry.h"
#include "component/registry.h"
#include "core/clock.h"

namespace costar::arm {
class MotionService;
}
namespace costar::sim {
class Simulation;
}
namespace costar::faults {
class Injector;
}

namespace costar::workcell {

struct WorkcellOptions {
  std::string name = "ur5-sim";
  /// Simulated cells: the scene file (default: sim/scenes/assembly.json).
  std::filesystem::path scene;
  /// Simulated cells: seed of the part placement and of the sensor noise (default: the scene's).
  std::optional<std::uint64_t> seed;
  /// Where taught waypoints are kept (default: $XDG_STATE_HOME or ~/.local/state, then
  /// costar/<workcell>/waypoints.json). Empty string in `memory_only` mode.
  std::filesystem::path waypoints;
  /// Never write waypoints or taught grasps (tests, trials): the waypoint file, if given, is
  /// read only.
  bool memory_only = false;
  /// Simulated cells: the camera moved from where the cell's drawings put it, by `distance`
  /// (m) in a random direction and turned by `angle_deg` about a random axis, drawn from
  /// `seed` (default: the cell's seed); overrides the scene's camera_offset.
  struct CameraMove {
    double distance = 0.0;
    double angle_deg = 0.0;
    std::optional<std::uint64_t> seed;
  };
  std::optional<CameraMove> camera_move;
  /// Where the cell's calibration (calibration/) is kept (default: beside the waypoints,
  /// calibration.json; in `memory_only` mode read from here if given, never written). Without
  /// a marker calibration there, the one the cell's description names (`calibration`, e.g.
  /// data/calibration/parallel-2f_marker.json: the marker on that gripper) is used.
  std::filesystem::path calibration;
  /// TEST ONLY: report the simulator's true part poses as object symbols in place of
  /// perception, to test SmartMove apart from perception. Never set by the CLI.
  bool test_oracle_perception = false;
  /// Faults to inject (faults/injector.h): the cell wraps its drivers and components with
  /// it. Keep the pointer to read what happened. Null: nothing is broken on purpose.
  std::shared_ptr<faults::Injector> faults;
  /// The same as fault specs (faults/fault.h grammar), for the CLI: the executable that builds
  /// the cell makes the injector from them (seeded with `seed`, else 1) when `faults` is null.
  std::vector<std::string> inject;
  /// A JSON file naming the components that run in hosts elsewhere (`costar host`), reached over
  /// DDS: {"domain", "partition", "interface", "components"} (dds/remote_config.h). Empty: every
  /// component runs in this process (or, in a simulated cell, as its description's `remote`
  /// says). A simulated cell's remote components (gripper, perception) run in lockstep with its
  /// simulation (dds/lockstep.h, workcell/remote_sim.h).
  std::filesystem::path remote;
  /// Simulated cells: a spare part of each class named here, parked off the table, for a
  /// disturbance that puts a part on it mid-task (sim::SimulationOptions::spare_classes).
  std::vector<std::string> spare_parts;
};

class Workcell {
 public:
  Workcell(const Workcell&) = delete;
  Workcell& operator=(const Workcell&) = delete;
  virtual ~Workcell() = default;

  virtual std::string name() const = 0;
  virtual std::string description() const = 0;

  Clock& clock() { return *clock_; }
  component::ComponentRegistry& components() { return components_; }
  /// Built-in nodes plus one node type per operation of the components.
  const bt::NodeRegistry& nodes() const { return nodes_; }

  /// Called by the executor before every tick: refreshes the world state.
  virtual void beforeTick() { components_.refreshWorld(); }
  /// The simulation behind a simulated cell (for tests, pictures and the trial judge, never
  /// for plans), or nullptr.
  virtual sim::Simulation* simulation() { return nullptr; }
  /// What may be asked of the cell's arm (forward and inverse kinematics, collisions, plans:
  /// arm/motion_service.h), or nullptr for a cell without an arm.
  virtual const arm::MotionService* motion() const { return nullptr; }
  /// The robot as the editor draws it, from the description the simulator and the planner
  /// use, or null for a cell without a robot: `urdf` (the arm's URDF with the gripper's mounted
  /// on its flange: the planner's model), `base_link`, `flange_link`, `tcp_link`,
  /// `base_in_world` {p, q [x, y, z, w]}, `joints` [{name, label, lower, upper}] (rad),
  /// `gripper` {key, grasps (its grasps' key in data/grasps.json), kind ("parallel": `max_opening`, `finger_boxes` of
  /// the +y finger closed, in the flange frame; "adaptive": `description`, the gripper's description file),
  /// `finger_links` (drawn from the gripper's reading, not from the URDF)}, and the `table`
  /// {centre, size} it stands by (m).
  virtual nlohmann::json robotDrawing() const { return nullptr; }

 protected:
  explicit Workcell(std::unique_ptr<Clock> clock);
  /// Call once the components are added: registers their node types and reads their state.
  void registerNodes();

 private:
  std::unique_ptr<Clock> clock_;
  component::ComponentRegistry components_;
  bt::NodeRegistry nodes_;
};

struct WorkcellInfo {
  std::string name;
  std::string description;
};

/// The workcells this build knows.
std::vector<WorkcellInfo> knownWorkcells();
/// Their names, comma-separated, for a command's help: all, or the simulated ones only
/// (workcells/*.json, listed from the folder).
std::string knownWorkcellNames(bool simulated_only = false);
/// @throws std::invalid_argument naming the known workcells when `name` is not one of them.
void requireKnownWorkcell(const std::string& name);
/// @throws std::invalid_argument when a scene or a camera move is given for a cell without a
/// simulation ("test", "none").
void refuseSimulationOptionsOfLightCells(const WorkcellOptions& options);

/// Creates a workcell. @throws std::invalid_argument naming the known ones for an unknown
/// name; std::runtime_error when its files cannot be read. In costar_workcell, which links
/// the robot libraries (simulator, perception, planning).
std::unique_ptr<Workcell> makeWorkcell(const WorkcellOptions& options);

/// Creates a workcell that needs none of the robot libraries ("test", "none"), or returns
/// nullptr for a known robot cell ("ur5-sim") and for any cell with faults to inject or remote
/// components, which only makeWorkcell() builds. In
/// costar_workcell_base, with the light `costar` executable.
/// @throws std::invalid_argument naming the known ones for an unknown name.
std::unique_ptr<Workcell> makeLightWorkcell(const WorkcellOptions& options);

/// Wraps a component (fault injection: faults::Injector::wrap).
using ComponentWrapper = std::function<std::shared_ptr<component::Component>(std::shared_ptr<component::Component>)>;

/// The TEST ONLY cell ("test"); each component goes through `wrap` when given, and `attach`
/// (if given) first sees the cell's clock. The "none" cell: built-in nodes only.
std::unique_ptr<Workcell> makeTestWorkcell(const ComponentWrapper& wrap,
                                           const std::function<void(const Clock&)>& attach);
std::unique_ptr<Workcell> makeBareWorkcell();

/// Where waypoints of `workcell` are kept by default.
std::filesystem::path defaultWaypointFile(const std::string& workcell);
/// Runs one operation of the cell (the component offering it) to its end outside a plan, as a
/// one-node plan would: the world is refreshed and the clock advanced in `tick` steps (on a
/// simulated clock, simulated time passes); `progress` is called after each poll. Gives up
/// with a FAILURE after `limit` of clock time, cancelling the operation.
/// @throws std::invalid_argument for an operation no component offers.
component::OperationResult runOperation(Workcell& cell, const std::string& operation, const component::ParamMap& params,
                                        Duration limit,
                                        const std::function<void(const component::OperationResult&)>& progress = {},
                                        Duration tick = std::chrono::milliseconds(10));

/// Where the calibration of `workcell` is kept by default.
std::filesystem::path defaultCalibrationFile(const std::string& workcell);
/// Where grasps taught on `workcell` are kept by default.
std::filesystem::path defaultGraspFile(const std::string& workcell);

}  // namespace costar::workcell
