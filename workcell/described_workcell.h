#pragma once
// A workcell's description: what its components declare (operations with their parameters,
// symbols, predicates), the frames that exist when it starts and the object classes a plan
// may name. Enough to build the workcell's node types and validate plans against them
// exactly as the running cell would, with none of its robot libraries: `costar validate` and
// `costar nodes` read the simulated UR5 cell's description, written at build time by
// `costar-robot describe-workcell`, rather than starting a simulator, camera and planner.

#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "component/component.h"
#include "workcell/workcell.h"

namespace costar::workcell {

struct WorkcellDescription {
  std::string name;
  std::string description;
  std::vector<component::ComponentDescription> components;
  /// Symbols that exist before a plan runs (fixed frames, the arm's frames), without
  /// waypoints: those are read from the waypoint file when the description is used.
  std::vector<std::string> references;
  /// Object classes a predicate pattern may name.
  std::vector<std::string> object_classes;
};

/// Describes a built workcell (built with memory_only and no waypoint file, so that no
/// user's waypoints end up in the description).
WorkcellDescription describeWorkcell(Workcell& cell, std::vector<std::string> object_classes);

nlohmann::json toJson(const WorkcellDescription& description);
/// @throws std::invalid_argument naming what is missing or wrong.
WorkcellDescription workcellDescriptionFromJson(const nlohmann::json& json);
/// @throws std::runtime_error naming the file when it cannot be read or is not a description.
WorkcellDescription loadWorkcellDescription(const std::filesystem::path& file);

/// A workcell with the node types of the described one, for validating plans and writing
/// node models: its operations cannot run. Waypoints come from the file `options` names, as
/// in the real cell (options.waypoints, else the default file unless memory_only).
/// Predicate-list parameters (choices_from "predicate") get the real cell's check: syntax,
/// declared predicates and their arity, known reference frames and classes.
/// @throws std::runtime_error when the waypoint file cannot be read.
std::unique_ptr<Workcell> makeDescribedWorkcell(const WorkcellDescription& description, const WorkcellOptions& options);

}  // namespace costar::workcell
