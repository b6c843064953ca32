#include "component/registry.h"

#include <spdlog/spdlog.h>

#include "component/nodes.h"

namespace costar::component {

ComponentRegistry::ComponentRegistry() {
  for (auto abstract : {abstractArm(), abstractGripper(), abstractPowerTool()}) {
    addAbstract(std::move(abstract));
  }
}

void ComponentRegistry::addAbstract(AbstractComponent abstract) {
  std::string name = abstract.name;
  abstracts_.insert_or_assign(std::move(name), std::move(abstract));
}

void ComponentRegistry::add(std::shared_ptr<Component> component) {
  if (!component) {
    throw ComponentError("cannot add a null component");
  }
  const ComponentDescription& description = component->description();
  const std::string who = "component '" + description.name + "' (" + description.type + ")";
  if (description.name.empty()) {
    throw ComponentError("a component of type " + description.type + " has no name");
  }
  if (find(description.name) != nullptr) {
    throw ComponentError(who + ": the name is already taken");
  }
  std::string problems;
  for (const auto& implemented : description.implements) {
    const auto it = abstracts_.find(implemented);
    if (it == abstracts_.end()) {
      problems += "\n  - it claims to implement '" + implemented + "', which is not a known abstract component";
      continue;
    }
    for (const auto& missing : missingRequirements(it->second, description)) {
      problems += "\n  - " + implemented + " requires " + missing + ", which it does not provide";
    }
  }
  for (const auto& operation : description.operations) {
    if (const auto it = providers_.find(operation.name); it != providers_.end()) {
      problems += "\n  - operation '" + operation.name + "' is already offered by component '" +
                  it->second->description().name + "'";
    }
  }
  for (const auto& predicate : description.predicates) {
    const auto it = predicates_.find(predicate.name);
    if (it != predicates_.end() && it->second.arity != predicate.arity) {
      problems += "\n  - predicate '" + predicate.name + "' takes " + std::to_string(predicate.arity) +
                  " arguments here but " + std::to_string(it->second.arity) + " elsewhere";
    }
  }
  if (!problems.empty()) {
    throw ComponentError("cannot add " + who + ":" + problems);
  }
  for (const auto& operation : description.operations) {
    providers_[operation.name] = component.get();
  }
  for (const auto& predicate : description.predicates) {
    predicates_.emplace(predicate.name, predicate);
  }
  components_.push_back(std::move(component));
}

Component* ComponentRegistry::find(std::string_view name) const {
  for (const auto& component : components_) {
    if (component->description().name == name) {
      return component.get();
    }
  }
  return nullptr;
}

Component* ComponentRegistry::provider(std::string_view operation) const {
  const auto it = providers_.find(operation);
  return it == providers_.end() ? nullptr : it->second;
}

namespace {

bt::PortSpec portOf(const ParamSpec& param) {
  bt::PortSpec port;
  port.name = param.name;
  port.type_name = typeName(param.type);
  port.description = param.description;
  if (param.default_value) {
    port.default_value = formatValue(*param.default_value);
  }
  port.choices = param.choices;
  if (param.type == ValueType::kBool) {
    port.choices = {"true", "false"};
  }
  port.check = [param](std::string_view text) { return param.check(text); };
  return port;
}

ParamMap parseParams(const OperationSpec& operation, const bt::NodeArgs& args) {
  ParamMap params;
  for (const auto& param : operation.params) {
    std::string error;
    auto value = parseValue(param.type, args.get(param.name), &error);
    if (!value) {
      throw std::invalid_argument("parameter '" + param.name + "': " + error);
    }
    params.emplace(param.name, std::move(*value));
  }
  return params;
}

}  // namespace

void ComponentRegistry::registerNodes(bt::NodeRegistry& nodes) {
  for (const auto& component : components_) {
    Component* target = component.get();
    for (const OperationSpec& operation : component->description().operations) {
      if (operation.kind == OperationKind::kInternal) {
        continue;  // for other components, not for plans
      }
      bt::NodeSpec spec;
      spec.id = operation.name;
      spec.kind = bt::NodeKind::kAction;
      spec.category =
          operation.kind == OperationKind::kKnowledge ? bt::NodeCategory::kKnowledge : bt::NodeCategory::kRobotAction;
      spec.description = operation.description + " [" + component->description().name + "]";
      spec.asynchronous = true;
      for (const ParamSpec& param : operation.params) {
        spec.ports.push_back(portOf(param));
      }
      if (operation.checksAcrossParams()) {
        spec.check_instance = [operation](const bt::NodeArgs& args, std::size_t) -> std::string {
          try {
            return operation.checkParams(parseParams(operation, args));
          } catch (const std::invalid_argument&) {
            return {};  // an ill-typed parameter: the port check names it
          }
        };
      }
      spec.build = [this, target, operation](const bt::NodeArgs& args) {
        return std::make_unique<OperationNode>(
            operation.name, args.name(), *target, parseParams(operation, args), [this] { refreshWorld(); },
            [this] { return stop_reason_; });
      };
      nodes.add(std::move(spec));
    }
  }

  bt::NodeSpec check;
  check.id = "CheckPredicate";
  check.kind = bt::NodeKind::kCondition;
  check.category = bt::NodeCategory::kKnowledge;
  check.description = "SUCCESS when the predicate holds for the arguments (or does not, with expected=false).";
  std::vector<std::string> names;
  for (const auto& [name, decl] : predicates_) {
    names.push_back(name);
  }
  check.ports = {names.empty() ? bt::PortSpec::text("predicate", "predicate name")
                               : bt::PortSpec::choice("predicate", "predicate name", names, std::nullopt),
                 bt::PortSpec::text("args", "arguments (symbol names), ';'-separated; one may be ? (any symbol)", ""),
                 bt::PortSpec::boolean("expected", "the value that makes the condition succeed", "true")};
  check.check_instance = [this](const bt::NodeArgs& args, std::size_t) -> std::string {
    const auto it = predicates_.find(args.get("predicate"));
    if (it == predicates_.end()) {
      return {};
    }
    const auto list = parseValue(ValueType::kStringList, args.get("args"))->asList();
    const std::size_t count = list.size();
    if (std::count(list.begin(), list.end(), "?") > 1) {
      return "only one argument may be the wildcard ?";
    }
    if (count != it->second.arity) {
      return "predicate '" + it->first + "' takes " + std::to_string(it->second.arity) + " argument(s), " +
             std::to_string(count) + " given";
    }
    if (it->second.numeric_arguments) {
      for (const std::string& arg : list) {
        const auto number = parseValue(ValueType::kDouble, arg);
        if (!number || !(number->asDouble() >= 0.0)) {
          return "predicate '" + it->first + "' takes a number of 0 or more (e.g. 15 for 15 N), not '" + arg + "'";
        }
      }
    }
    return {};
  };
  check.build = [this](const bt::NodeArgs& args) {
    return std::make_unique<PredicateCondition>("CheckPredicate", args.name(), world_, args.get("predicate"),
                                                parseValue(ValueType::kStringList, args.get("args"))->asList(),
                                                args.getBool("expected"));
  };
  nodes.add(std::move(check));
}

void ComponentRegistry::stopCell(const std::string& reason) {
  if (!stop_reason_.empty()) {
    return;
  }
  stop_reason_ = reason;
  spdlog::error("the cell stopped: {}", reason);
  if (on_stop_) {
    try {
      on_stop_(reason);
    } catch (const std::exception& e) {
      spdlog::error("stopping the cell: {}", e.what());
    }
  }
}

void ComponentRegistry::refreshWorld() {
  for (const auto& component : components_) {
    const ComponentDescription& description = component->description();
    world::Report report;
    try {
      report = component->report();
    } catch (const std::exception& e) {
      // Its symbols and predicates are no longer known; the cell stops.
      world_.update(description.name, {});
      stopCell("component '" + description.name + "' failed: " + e.what());
      continue;
    }
    std::erase_if(report.predicates, [&](const world::Predicate& predicate) {
      const bool declared =
          std::any_of(description.predicates.begin(), description.predicates.end(), [&](const PredicateDecl& decl) {
            return decl.name == predicate.name && decl.arity == predicate.args.size();
          });
      if (!declared && warned_.insert(description.name + "/" + predicate.name).second) {
        spdlog::warn(
            "component '{}' reported predicate '{}' with {} argument(s), which it does not declare; "
            "ignored",
            description.name, predicate.name, predicate.args.size());
      }
      return !declared;
    });
    world_.update(description.name, std::move(report));
  }
}

}  // namespace costar::component
