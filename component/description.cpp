#include "component/description.h"

#include <stdexcept>

#include "core/json_file.h"

namespace costar::component {

namespace {

ValueType valueTypeNamed(const std::string& name) {
  for (const ValueType type : {ValueType::kBool, ValueType::kInt, ValueType::kDouble, ValueType::kString,
                               ValueType::kPose, ValueType::kStringList}) {
    if (name == typeName(type)) {
      return type;
    }
  }
  throw std::invalid_argument("unknown parameter type '" + name + "'");
}

world::SymbolKind symbolKindNamed(const std::string& name) {
  for (const world::SymbolKind kind :
       {world::SymbolKind::kFrame, world::SymbolKind::kJoints, world::SymbolKind::kObjectClass,
        world::SymbolKind::kWrench, world::SymbolKind::kNumber}) {
    if (name == world::toString(kind)) {
      return kind;
    }
  }
  throw std::invalid_argument("unknown symbol kind '" + name + "'");
}

const char* kindName(OperationKind kind) {
  switch (kind) {
    case OperationKind::kKnowledge:
      return "knowledge";
    case OperationKind::kInternal:
      return "internal";
    case OperationKind::kRobotAction:
      break;
  }
  return "robot_action";
}

/// json[key] as T, with the key named when it is missing or has the wrong type.
template <typename T>
T field(const nlohmann::json& json, const char* key) {
  if (!json.is_object() || !json.contains(key)) {
    throw std::invalid_argument(std::string("missing field '") + key + "'");
  }
  try {
    return json.at(key).get<T>();
  } catch (const nlohmann::json::exception& e) {
    throw std::invalid_argument(std::string("field '") + key + "': " + core::jsonErrorText(e));
  }
}

template <typename T>
T optionalField(const nlohmann::json& json, const char* key, T fallback) {
  return json.contains(key) ? field<T>(json, key) : fallback;
}

}  // namespace

ParamSpec paramSpecFromJson(const nlohmann::json& json) {
  ParamSpec spec;
  spec.name = field<std::string>(json, "name");
  spec.type = valueTypeNamed(field<std::string>(json, "type"));
  spec.description = optionalField<std::string>(json, "description", "");
  if (json.contains("default")) {
    std::string error;
    spec.default_value = parseValue(spec.type, field<std::string>(json, "default"), &error);
    if (!spec.default_value) {
      throw std::invalid_argument("parameter '" + spec.name + "': default: " + error);
    }
  }
  spec.choices = optionalField<std::vector<std::string>>(json, "choices", {});
  if (json.contains("min")) {
    spec.min = field<double>(json, "min");
  }
  if (json.contains("max")) {
    spec.max = field<double>(json, "max");
  }
  spec.choices_from = optionalField<std::string>(json, "choices_from", "");
  spec.less_than = optionalField<std::string>(json, "less_than", "");
  if (!spec.less_than.empty() && spec.type != ValueType::kDouble && spec.type != ValueType::kInt) {
    throw std::invalid_argument("parameter '" + spec.name + "': less_than: only a number is less than another");
  }
  return spec;
}

nlohmann::json toJson(const ComponentDescription& description) {
  nlohmann::json operations = nlohmann::json::array();
  for (const OperationSpec& operation : description.operations) {
    nlohmann::json params = nlohmann::json::array();
    for (const ParamSpec& param : operation.params) {
      params.push_back(toJson(param));
    }
    operations.push_back({{"name", operation.name},
                          {"description", operation.description},
                          {"kind", kindName(operation.kind)},
                          {"params", std::move(params)}});
  }
  nlohmann::json symbols = nlohmann::json::array();
  for (const SymbolDecl& symbol : description.symbols) {
    symbols.push_back(
        {{"name", symbol.name}, {"kind", world::toString(symbol.kind)}, {"description", symbol.description}});
  }
  nlohmann::json predicates = nlohmann::json::array();
  for (const PredicateDecl& predicate : description.predicates) {
    nlohmann::json item = {
        {"name", predicate.name}, {"arity", predicate.arity}, {"description", predicate.description}};
    if (predicate.numeric_arguments) {
      item["numeric_arguments"] = true;
    }
    predicates.push_back(std::move(item));
  }
  return {{"name", description.name},      {"type", description.type},           {"implements", description.implements},
          {"inputs", description.inputs},  {"outputs", description.outputs},     {"operations", std::move(operations)},
          {"symbols", std::move(symbols)}, {"predicates", std::move(predicates)}};
}

ComponentDescription descriptionFromJson(const nlohmann::json& json) {
  ComponentDescription description;
  description.name = field<std::string>(json, "name");
  try {
    description.type = field<std::string>(json, "type");
    description.implements = optionalField<std::vector<std::string>>(json, "implements", {});
    description.inputs = optionalField<std::vector<std::string>>(json, "inputs", {});
    description.outputs = optionalField<std::vector<std::string>>(json, "outputs", {});
    for (const auto& item : optionalField<nlohmann::json>(json, "operations", nlohmann::json::array())) {
      OperationSpec operation;
      operation.name = field<std::string>(item, "name");
      operation.description = optionalField<std::string>(item, "description", "");
      const std::string kind = optionalField<std::string>(item, "kind", "robot_action");
      if (kind != "robot_action" && kind != "knowledge" && kind != "internal") {
        throw std::invalid_argument("operation '" + operation.name + "': unknown kind '" + kind + "'");
      }
      operation.kind = kind == "knowledge"  ? OperationKind::kKnowledge
                       : kind == "internal" ? OperationKind::kInternal
                                            : OperationKind::kRobotAction;
      for (const auto& param : optionalField<nlohmann::json>(item, "params", nlohmann::json::array())) {
        operation.params.push_back(paramSpecFromJson(param));
      }
      for (const ParamSpec& param : operation.params) {
        const ParamSpec* bound = param.less_than.empty() ? nullptr : operation.param(param.less_than);
        if (!param.less_than.empty() &&
            (bound == nullptr || (bound->type != ValueType::kDouble && bound->type != ValueType::kInt))) {
          throw std::invalid_argument("operation '" + operation.name + "': parameter '" + param.name +
                                      "': less_than: '" + param.less_than + "' is not a number of the operation");
        }
      }
      description.operations.push_back(std::move(operation));
    }
    for (const auto& item : optionalField<nlohmann::json>(json, "symbols", nlohmann::json::array())) {
      description.symbols.push_back({field<std::string>(item, "name"),
                                     symbolKindNamed(field<std::string>(item, "kind")),
                                     optionalField<std::string>(item, "description", "")});
    }
    for (const auto& item : optionalField<nlohmann::json>(json, "predicates", nlohmann::json::array())) {
      description.predicates.push_back({field<std::string>(item, "name"), field<std::size_t>(item, "arity"),
                                        optionalField<std::string>(item, "description", ""),
                                        optionalField<bool>(item, "numeric_arguments", false)});
    }
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument("component '" + description.name + "': " + e.what());
  }
  return description;
}

OperationId DescribedComponent::start(const std::string& operation, const ParamMap& /*params*/) {
  throw std::runtime_error("component '" + description_.name + "' is only described here (loaded to check plans); " +
                           operation + " cannot run");
}

OperationResult DescribedComponent::poll(OperationId id) {
  throw std::runtime_error("component '" + description_.name + "' runs no operations (asked for #" +
                           std::to_string(id) + ")");
}

}  // namespace costar::component
