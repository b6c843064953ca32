#include "component/component.h"

#include <algorithm>
#include <stdexcept>

namespace costar::component {

const ParamSpec* OperationSpec::param(std::string_view param_name) const {
  for (const auto& spec : params) {
    if (spec.name == param_name) {
      return &spec;
    }
  }
  return nullptr;
}

std::string OperationSpec::checkParams(const ParamMap& values) const {
  for (const ParamSpec& spec : params) {
    if (spec.less_than.empty()) {
      continue;
    }
    const auto value = values.find(spec.name);
    const auto bound = values.find(spec.less_than);
    if (value == values.end() || bound == values.end()) {
      continue;
    }
    if (value->second.asDouble() >= bound->second.asDouble()) {
      const ParamSpec* bound_spec = param(spec.less_than);
      return spec.name + " (" + formatValue(value->second) + ") must be below " + spec.less_than + " (" +
             formatValue(bound->second) + ")" +
             (bound_spec != nullptr && !bound_spec->description.empty() ? ": " + bound_spec->description : "");
    }
  }
  return check ? check(values) : std::string();
}

bool OperationSpec::checksAcrossParams() const {
  return check ||
         std::any_of(params.begin(), params.end(), [](const ParamSpec& spec) { return !spec.less_than.empty(); });
}

const OperationSpec* ComponentDescription::operation(std::string_view operation_name) const {
  for (const auto& spec : operations) {
    if (spec.name == operation_name) {
      return &spec;
    }
  }
  return nullptr;
}

const char* toString(OperationState state) {
  switch (state) {
    case OperationState::kRunning:
      return "running";
    case OperationState::kSuccess:
      return "success";
    case OperationState::kFailure:
      return "failure";
  }
  return "?";
}

nlohmann::json toJson(const OperationResult& result) {
  nlohmann::json json = {{"state", toString(result.state)}, {"reason", result.reason}};
  if (!result.data.is_null()) {
    json["data"] = result.data;
  }
  return json;
}

OperationResult resultFromJson(const nlohmann::json& json) {
  OperationResult result;
  const std::string state = json.at("state").get<std::string>();
  if (state == "running") {
    result.state = OperationState::kRunning;
  } else if (state == "success") {
    result.state = OperationState::kSuccess;
  } else if (state == "failure") {
    result.state = OperationState::kFailure;
  } else {
    throw std::invalid_argument("unknown operation state '" + state + "'");
  }
  result.reason = json.value("reason", "");
  if (json.contains("data")) {
    result.data = json.at("data");
  }
  return result;
}

OperationId LocalComponent::start(const std::string& operation, const ParamMap& params) {
  if (description().operation(operation) == nullptr) {
    throw std::invalid_argument(description().name + " has no operation '" + operation + "'");
  }
  auto running = begin(operation, params);
  std::lock_guard lock(mutex_);
  const OperationId id = next_id_++;
  running_.emplace(id, std::move(running));
  return id;
}

OperationResult LocalComponent::poll(OperationId id) {
  std::unique_lock lock(mutex_);
  const auto it = running_.find(id);
  if (it == running_.end()) {
    throw std::invalid_argument(description().name + ": unknown operation id " + std::to_string(id));
  }
  RunningOperation* operation = it->second.get();
  lock.unlock();
  OperationResult result = operation->poll();
  if (result.state != OperationState::kRunning) {
    lock.lock();
    running_.erase(id);
  }
  return result;
}

void LocalComponent::cancel(OperationId id) {
  std::unique_ptr<RunningOperation> operation;
  {
    std::lock_guard lock(mutex_);
    const auto it = running_.find(id);
    if (it == running_.end()) {
      return;
    }
    operation = std::move(it->second);
    running_.erase(it);
  }
  operation->cancel();
}

}  // namespace costar::component
