#pragma once
// The palette the editor builds plans from (GET /api/nodes) and what it is told about the
// cell (GET /api/info), read once from a workcell: every node type with its ports, where each
// operation parameter's choices come from, its extra choices, exclusions and range, and which
// features the menu offers.

#include <nlohmann/json.hpp>
#include <string>

namespace costar::workcell {
class Workcell;
}

namespace costar::server {

struct Palette {
  /// Every node type as JSON text: {id, kind, category, description, asynchronous, ports,
  /// component}.
  std::string nodes_json;
  /// The cell's name, description, clock kind, whether it is simulated, the menu's features.
  nlohmann::json info;
};

/// The palette of `cell`'s node types and its info.
Palette describePalette(workcell::Workcell& cell);

}  // namespace costar::server
