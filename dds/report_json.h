#pragma once
// A component's report (its symbols and predicates) as JSON, for the wire: what a component
// host publishes and a proxy hands to the registry. Poses travel as their 12 matrix entries,
// so a report read back equals the one written, to the bit.

#include <nlohmann/json.hpp>

#include "world/world_state.h"

namespace costar::dds {

nlohmann::json toJson(const world::Report& report);
/// @throws std::invalid_argument naming the symbol or predicate and the field that is wrong.
world::Report reportFromJson(const nlohmann::json& json);

}  // namespace costar::dds
