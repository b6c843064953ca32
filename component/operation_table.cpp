#include "component/operation_table.h"

#include <stdexcept>

namespace costar::component {

OperationTable& OperationTable::add(OperationSpec spec, Handler handler) {
  if (spec.name.empty()) {
    throw std::logic_error("an operation without a name");
  }
  if (!handler) {
    throw std::logic_error("operation '" + spec.name + "' has no handler");
  }
  if (handlers_.contains(spec.name)) {
    throw std::logic_error("operation '" + spec.name + "' is declared twice");
  }
  handlers_.emplace(spec.name, std::move(handler));
  specs_.push_back(std::move(spec));
  return *this;
}

std::unique_ptr<RunningOperation> OperationTable::begin(const std::string& component, const std::string& operation,
                                                        const ParamMap& params) const {
  const auto it = handlers_.find(operation);
  if (it == handlers_.end()) {
    throw std::invalid_argument(component + " has no operation '" + operation + "'");
  }
  return it->second(params);
}

void TableComponent::declare(ComponentDescription description, OperationTable operations) {
  const std::string who = "component '" + description.name + "'";
  if (declared_) {
    throw std::logic_error(who + ": its operations are declared twice");
  }
  std::string problems;
  for (const OperationSpec& spec : description.operations) {
    if (!operations.contains(spec.name)) {
      problems += "\n  - operation '" + spec.name + "' is declared but has no handler";
    }
  }
  if (!description.operations.empty()) {
    for (const OperationSpec& spec : operations.specs()) {
      if (description.operation(spec.name) == nullptr) {
        problems += "\n  - operation '" + spec.name + "' has a handler but is not declared";
      }
    }
  }
  if (!problems.empty()) {
    throw std::logic_error(who + ": its description and its operation table disagree:" + problems);
  }
  description.operations = operations.specs();
  description_ = std::move(description);
  operations_ = std::move(operations);
  declared_ = true;
}

std::unique_ptr<RunningOperation> TableComponent::begin(const std::string& operation, const ParamMap& params) {
  return operations_.begin(description_.name, operation, params);
}

}  // namespace costar::component
