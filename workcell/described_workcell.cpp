#include "workcell/described_workcell.h"

#include <algorithm>
#include <fstream>
#include <set>
#include <stdexcept>

#include "arm/waypoints.h"
#include "component/description.h"
#include "core/json_file.h"
#include "predicator/pattern.h"

namespace costar::workcell {

WorkcellDescription describeWorkcell(Workcell& cell, std::vector<std::string> object_classes) {
  WorkcellDescription description;
  description.name = cell.name();
  description.description = cell.description();
  for (const auto& component : cell.components().components()) {
    description.components.push_back(component->description());
  }
  cell.components().refreshWorld();
  for (const world::Symbol* symbol : cell.components().world().symbols()) {
    description.references.push_back(symbol->name);
  }
  std::sort(description.references.begin(), description.references.end());
  description.object_classes = std::move(object_classes);
  return description;
}

nlohmann::json toJson(const WorkcellDescription& description) {
  nlohmann::json components = nlohmann::json::array();
  for (const auto& component : description.components) {
    components.push_back(component::toJson(component));
  }
  return {{"workcell", description.name},
          {"description", description.description},
          {"components", std::move(components)},
          {"references", description.references},
          {"object_classes", description.object_classes}};
}

WorkcellDescription workcellDescriptionFromJson(const nlohmann::json& json) {
  WorkcellDescription description;
  try {
    description.name = json.at("workcell").get<std::string>();
    description.description = json.at("description").get<std::string>();
    for (const auto& component : json.at("components")) {
      description.components.push_back(component::descriptionFromJson(component));
    }
    description.references = json.at("references").get<std::vector<std::string>>();
    description.object_classes = json.at("object_classes").get<std::vector<std::string>>();
  } catch (const nlohmann::json::exception& e) {
    throw std::invalid_argument(std::string("not a workcell description: ") + core::jsonErrorText(e));
  }
  return description;
}

WorkcellDescription loadWorkcellDescription(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) {
    throw std::runtime_error("cannot read workcell description '" + file.string() + "'");
  }
  try {
    return workcellDescriptionFromJson(core::readJsonFile(file));
  } catch (const std::exception& e) {
    throw std::runtime_error(file.string() + ": " + e.what());
  }
}

namespace {

class DescribedWorkcell final : public Workcell {
 public:
  DescribedWorkcell(const WorkcellDescription& description, const WorkcellOptions& options)
      : Workcell(std::make_unique<SimClock>()),
        name_(description.name),
        description_(description.description),
        references_(description.references.begin(), description.references.end()) {
    references_.insert(description.object_classes.begin(), description.object_classes.end());
    const std::filesystem::path waypoint_file =
        !options.waypoints.empty() ? options.waypoints
                                   : (options.memory_only ? std::filesystem::path() : defaultWaypointFile(name_));
    // The waypoints are read as the robot binary's arm reads them, with its joint count (the
    // range of its JogJoint's joint number): `costar validate` said valid of a joint waypoint
    // with 7 values for the UR5, and `costar run` refused the file.
    int joint_count = 0;
    for (const auto& component : description.components) {
      if (const component::OperationSpec* jog = component.operation("JogJoint")) {
        if (const component::ParamSpec* joint = jog->param("joint"); joint != nullptr && joint->max) {
          joint_count = static_cast<int>(*joint->max);
        }
      }
    }
    for (const arm::Waypoint& waypoint : arm::WaypointStore(waypoint_file, /*persist=*/false, joint_count).all()) {
      references_.insert(waypoint.name);
    }
    for (component::ComponentDescription component : description.components) {
      for (auto& operation : component.operations) {
        for (auto& param : operation.params) {
          if (param.choices_from == "predicate" && param.type == component::ValueType::kString) {
            param.validate = [this](std::string_view text) {
              return predicator::checkPatternList(text, [this](const predicator::Pattern& pattern) {
                return predicator::checkPatternAgainst(
                    pattern, components().predicates(),
                    [this](const std::string& arg) { return references_.contains(arg); });
              });
            };
          }
        }
      }
      components().add(std::make_shared<component::DescribedComponent>(std::move(component)));
    }
    registerNodes();
  }

  std::string name() const override { return name_; }
  std::string description() const override { return description_; }

 private:
  std::string name_;
  std::string description_;
  std::set<std::string, std::less<>> references_;
};

}  // namespace

std::unique_ptr<Workcell> makeDescribedWorkcell(const WorkcellDescription& description,
                                                const WorkcellOptions& options) {
  return std::make_unique<DescribedWorkcell>(description, options);
}

}  // namespace costar::workcell
