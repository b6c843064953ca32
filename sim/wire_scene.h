#pragma once
// A scene file's "jig" and "wire" entries (sim/wire.h), read and written by sim/scene.cpp.
// Internal to sim/.

#include <string>

#include <nlohmann/json.hpp>

#include "sim/wire.h"

namespace costar::sim {

/// @throws std::runtime_error "FIELD: PROBLEM" (the caller names the file).
JigSpec parseJig(const nlohmann::json& value, const std::string& field);
WireSpec parseWire(const nlohmann::json& value, const std::string& field);

/// What needs both: a wire needs a jig to clamp it; its straight start must clear every pin;
/// the drawing's bends lie along the wire. @throws std::runtime_error "FIELD: PROBLEM".
void checkJigAndWire(const std::optional<JigSpec>& jig, const std::optional<WireSpec>& wire);

nlohmann::json jigJson(const JigSpec& jig);
nlohmann::json wireJson(const WireSpec& wire);

}  // namespace costar::sim
