#include "bt/nodes_model.h"

#include "bt/registry.h"
#include "bt/xml_writer.h"

namespace costar::bt {

void collectNodeIds(const PlanNode& node, std::set<std::string>& ids) {
  ids.insert(node.id);
  for (const auto& child : node.children) {
    collectNodeIds(child, ids);
  }
}

void writeTreeNodesModel(XmlWriter& printer, const NodeRegistry& registry, const std::set<std::string>& ids,
                         const ModelOptions& options) {
  printer.open("TreeNodesModel");
  for (const NodeSpec* spec : registry.all()) {
    if ((!ids.empty() && !ids.contains(spec->id)) || (spec->btcpp_builtin && !options.include_btcpp_builtins)) {
      continue;
    }
    const char* kind = spec->kind == NodeKind::kSubTree ? "SubTree" : toString(spec->kind);
    printer.open(kind);
    printer.attribute("ID", spec->id);
    for (const PortSpec& port : spec->ports) {
      printer.open("input_port");
      printer.attribute("name", port.name);
      printer.attribute("type", port.type_name);
      if (port.default_value) {
        printer.attribute("default", *port.default_value);
      }
      std::string description = port.description;
      if (!port.choices.empty()) {
        description += " (one of:";
        for (const auto& choice : port.choices) {
          description += " " + choice;
        }
        description += ")";
      }
      printer.text(description);
      printer.close();
    }
    printer.open("MetadataFields");
    const std::pair<const char*, std::string> metadata[] = {{"description", spec->description},
                                                            {"category", toString(spec->category)},
                                                            {"asynchronous", spec->asynchronous ? "true" : "false"}};
    for (const auto& [key, value] : metadata) {
      printer.open("Metadata");
      printer.attribute("key", key);
      printer.attribute("value", value);
      printer.close();
    }
    printer.close();
    printer.close();
  }
  printer.close();
}

std::string treeNodesModelXml(const NodeRegistry& registry, const ModelOptions& options) {
  XmlWriter writer;
  writer.open("root");
  writer.attribute("BTCPP_format", "4");
  writeTreeNodesModel(writer, registry, {}, options);
  writer.close();
  return writer.str();
}

}  // namespace costar::bt
