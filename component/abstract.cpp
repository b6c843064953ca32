#include "component/abstract.h"

#include <algorithm>

namespace costar::component {

AbstractComponent abstractArm() {
  return {"Arm", "A robot arm: moves its endpoint and learns waypoints.", {"Teach", "Move"}, {"endpoint"}, {}};
}

AbstractComponent abstractGripper() {
  return {"Gripper",
          "A gripper: opens, closes, and has modes that decide how it grasps.",
          {"Open", "Close", "BasicMode", "PinchMode", "WideMode", "ScissorMode"},
          {},
          {"gripper_open", "gripper_closed", "gripper_holding", "gripper_mode"}};
}

AbstractComponent abstractPowerTool() {
  return {"PowerTool",
          "A tool that is switched on and off (a sander, a polisher).",
          {"ToolOn", "ToolOff"},
          {},
          {"tool_on"}};
}

std::vector<std::string> missingRequirements(const AbstractComponent& abstract,
                                             const ComponentDescription& description) {
  std::vector<std::string> missing;
  for (const auto& operation : abstract.operations) {
    if (description.operation(operation) == nullptr) {
      missing.push_back("operation '" + operation + "'");
    }
  }
  for (const auto& symbol : abstract.symbols) {
    if (std::none_of(description.symbols.begin(), description.symbols.end(),
                     [&](const SymbolDecl& decl) { return decl.name == symbol; })) {
      missing.push_back("symbol '" + symbol + "'");
    }
  }
  for (const auto& predicate : abstract.predicates) {
    if (std::none_of(description.predicates.begin(), description.predicates.end(),
                     [&](const PredicateDecl& decl) { return decl.name == predicate; })) {
      missing.push_back("predicate '" + predicate + "'");
    }
  }
  return missing;
}

}  // namespace costar::component
