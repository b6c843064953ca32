#pragma once
// The cell as the editor's page draws it (GET /api/state, the stream's "state" messages, the
// snapshots a run's log keeps for replay), read from the world state the components report.

#include <cstdint>
#include <nlohmann/json.hpp>
#include <set>
#include <string>

namespace costar::workcell {
class Workcell;
}
namespace costar::world {
struct Symbol;
}

namespace costar::server {

/// Which symbols of the world state are waypoints: those an arm (a component implementing the
/// abstract Arm) reports that no component declares.
class WaypointFinder {
 public:
  explicit WaypointFinder(workcell::Workcell& cell);
  bool isWaypoint(const world::Symbol& symbol) const;

 private:
  std::set<std::string> arm_sources_;
  std::set<std::string> declared_;
};

/// {type: "state", t (clock s), run (the active run's id, 0: none), mode (idle, running,
/// paused), arm {endpoint, joints, moving, wrench, in_contact}, tool (a cell with a power tool),
/// safety {separation, protective_distance (m), speed_scale (0-1), slowed, stopped, collaborative}
/// (a scene with a person: the speed and separation monitor's reading), gripper {open, closed,
/// holding, mode, reading},
/// objects [{name, class, source, p, q, color}], waypoints [{name, kind, frame, p, q}] (the
/// arm's; a joint waypoint drawn where the cell's motion service puts the tool), frames, and up
/// to 2,000 predicates that hold}. Engine thread only (it reads the cell).
nlohmann::json cellState(workcell::Workcell& cell, std::int64_t active, bool paused);

}  // namespace costar::server
