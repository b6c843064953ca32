#include "server/palette.h"

#include "component/component.h"
#include "workcell/workcell.h"

namespace costar::server {

using nlohmann::json;

Palette describePalette(workcell::Workcell& cell) {
  // The palette: every node type with its ports; operation parameters add where their
  // choices come from and their range.
  json nodes = json::array();
  bool detect = false;
  bool calibrate = false;
  for (const bt::NodeSpec* spec : cell.nodes().all()) {
    const component::Component* provider = cell.components().provider(spec->id);
    const component::OperationSpec* operation =
        provider != nullptr ? provider->description().operation(spec->id) : nullptr;
    json ports = json::array();
    for (const auto& port : spec->ports) {
      json item = {{"name", port.name}, {"type", port.type_name}, {"description", port.description}};
      if (port.default_value) {
        item["default"] = *port.default_value;
      }
      if (!port.choices.empty()) {
        item["choices"] = port.choices;
      }
      if (const component::ParamSpec* param = operation != nullptr ? operation->param(port.name) : nullptr) {
        if (!param->choices_from.empty()) {
          item["choices_from"] = param->choices_from;
        }
        if (!param->extra_choices.empty()) {
          item["extra_choices"] = param->extra_choices;
        }
        if (!param->excludes.empty()) {
          item["excludes"] = param->excludes;
        }
        if (!param->less_than.empty()) {
          item["less_than"] = param->less_than;
        }
        if (param->min) {
          item["min"] = *param->min;
        }
        if (param->max) {
          item["max"] = *param->max;
        }
      }
      ports.push_back(std::move(item));
    }
    json node = {{"id", spec->id},
                 {"kind", bt::toString(spec->kind)},
                 {"category", bt::toString(spec->category)},
                 {"description", spec->description},
                 {"asynchronous", spec->asynchronous},
                 {"ports", std::move(ports)}};
    if (provider != nullptr) {
      node["component"] = provider->description().name;
    }
    // An operation without parameters that this cell refuses whatever the plan (a 2-finger
    // gripper's Scissor mode): the palette leaves it out, saying why; Check still names it.
    if (operation != nullptr && operation->params.empty() && operation->check) {
      if (std::string problem = operation->check({}); !problem.empty()) {
        node["unavailable"] = std::move(problem);
      }
    }
    nodes.push_back(std::move(node));
    detect = detect || spec->id == "DetectObjects";
    calibrate = calibrate || spec->id == "Calibrate" || spec->id == "HandEyeCalibration";
  }
  Palette palette;
  palette.nodes_json = nodes.dump();
  palette.info = {
      {"workcell", cell.name()},
      {"description", cell.description()},
      {"simulated_clock", cell.clock().simulated()},
      {"simulator", cell.simulation() != nullptr},
      {"features",
       {{"detect", detect},
        {"calibrate", calibrate},
        {"pointcloud", cell.simulation() != nullptr},
        // Free-drive from the 3D view: the simulator is the hand that pushes (POST /api/drag).
        {"free_drive", cell.simulation() != nullptr && cell.nodes().find("FreeDrive") != nullptr},
        {"detect_node", detect ? "DetectObjects" : ""},
        {"calibrate_node", cell.nodes().find("Calibrate") != nullptr ? "Calibrate" : "HandEyeCalibration"}}},
      {"version", "0.1.0"}};
  return palette;
}

}  // namespace costar::server
