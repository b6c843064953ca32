#pragma once
// A component's description (its operations with their parameters, symbols and predicates)
// as JSON, and a component made from a description alone. A workcell's node types, and so
// plan validation, need only the descriptions: the light `costar` executable validates a plan
// for the simulated UR5 cell from its stored description, without a simulator, camera or
// planner (workcell/described_workcell.h).

#include <nlohmann/json.hpp>

#include "component/component.h"

namespace costar::component {

nlohmann::json toJson(const ComponentDescription& description);
/// @throws std::invalid_argument naming the field that is missing or wrong.
ComponentDescription descriptionFromJson(const nlohmann::json& json);
/// Inverse of toJson(const ParamSpec&) except `validate` (a function, not data).
/// @throws std::invalid_argument naming the field that is missing or wrong.
ParamSpec paramSpecFromJson(const nlohmann::json& json);

/// A component known only by its description: its operations cannot be started (start()
/// throws, so a node of it fails with that reason) and it reports nothing.
class DescribedComponent final : public Component {
 public:
  explicit DescribedComponent(ComponentDescription description) : description_(std::move(description)) {}
  const ComponentDescription& description() const override { return description_; }
  OperationId start(const std::string& operation, const ParamMap& params) override;
  OperationResult poll(OperationId id) override;
  void cancel(OperationId /*id*/) override {}
  world::Report report() const override { return {}; }

 private:
  ComponentDescription description_;
};

}  // namespace costar::component
