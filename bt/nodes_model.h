#pragma once
// The <TreeNodesModel> of BehaviorTree.CPP v4 / Groot2: every node type with its ports,
// types and defaults, so that editors can show and check plans that use them.

#include <set>
#include <string>

#include "bt/plan.h"

namespace costar::bt {

class NodeRegistry;
class XmlWriter;

struct ModelOptions {
  /// Also describe node types that BehaviorTree.CPP has built in (Groot2 knows them).
  bool include_btcpp_builtins = false;
};

/// A whole `<root BTCPP_format="4"><TreeNodesModel>...` document.
std::string treeNodesModelXml(const NodeRegistry& registry, const ModelOptions& options = {});

/// Writes a <TreeNodesModel> element for the node types in `ids` (all if empty) that are
/// not BehaviorTree.CPP built-ins.
void writeTreeNodesModel(XmlWriter& writer, const NodeRegistry& registry, const std::set<std::string>& ids,
                         const ModelOptions& options = {});

/// Adds the IDs of `node` and its descendants to `ids`.
void collectNodeIds(const PlanNode& node, std::set<std::string>& ids);

}  // namespace costar::bt
