#include "bt/nodes_model.h"

#include <tinyxml2.h>

#include "bt/registry.h"

namespace costar::bt {

void collectNodeIds(const PlanNode& node, std::set<std::string>& ids) {
  ids.insert(node.id);
  for (const auto& child : node.children) {
    collectNodeIds(child, ids);
  }
}

void writeTreeNodesModel(tinyxml2::XMLPrinter& printer, const NodeRegistry& registry,
                         const std::set<std::string>& ids, const ModelOptions& options) {
  printer.OpenElement("TreeNodesModel");
  for (const NodeSpec* spec : registry.all()) {
    if ((!ids.empty() && !ids.contains(spec->id)) ||
        (spec->btcpp_builtin && !options.include_btcpp_builtins)) {
      continue;
    }
    const char* kind = spec->kind == NodeKind::kSubTree ? "SubTree" : toString(spec->kind);
    printer.OpenElement(kind);
    printer.PushAttribute("ID", spec->id.c_str());
    for (const PortSpec& port : spec->ports) {
      printer.OpenElement("input_port");
      printer.PushAttribute("name", port.name.c_str());
      printer.PushAttribute("type", port.type_name.c_str());
      if (port.default_value) {
        printer.PushAttribute("default", port.default_value->c_str());
      }
      std::string description = port.description;
      if (!port.choices.empty()) {
        description += " (one of:";
        for (const auto& choice : port.choices) {
          description += " " + choice;
        }
        description += ")";
      }
      printer.PushText(description.c_str());
      printer.CloseElement();
    }
    printer.OpenElement("MetadataFields");
    const std::pair<const char*, std::string> metadata[] = {
        {"description", spec->description},
        {"category", toString(spec->category)},
        {"asynchronous", spec->asynchronous ? "true" : "false"}};
    for (const auto& [key, value] : metadata) {
      printer.OpenElement("Metadata");
      printer.PushAttribute("key", key);
      printer.PushAttribute("value", value.c_str());
      printer.CloseElement();
    }
    printer.CloseElement();
    printer.CloseElement();
  }
  printer.CloseElement();
}

std::string treeNodesModelXml(const NodeRegistry& registry, const ModelOptions& options) {
  tinyxml2::XMLPrinter printer(nullptr, /*compact=*/false);
  printer.PushHeader(false, true);
  printer.OpenElement("root");
  printer.PushAttribute("BTCPP_format", "4");
  writeTreeNodesModel(printer, registry, {}, options);
  printer.CloseElement();
  return printer.CStr();
}

}  // namespace costar::bt
