#pragma once
// The NodeRegistry knows every node type a plan may use: built-in control nodes,
// decorators and leaves, and (registered by component/) every robot operation. It is the
// source of plan validation and of the TreeNodesModel that Groot2 and the editor read.

#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "bt/node.h"

namespace costar::bt {

/// BehaviorTree.CPP's node families (the element names of the explicit XML form).
enum class NodeKind { kControl, kDecorator, kAction, kCondition, kSubTree };
const char* toString(NodeKind kind);

/// The editor's colour groups (the paper's Fig. 5): internal nodes blue, robot actions
/// green, knowledge updates and queries purple.
enum class NodeCategory { kInternal, kRobotAction, kKnowledge };
const char* toString(NodeCategory category);

/// One parameter of a node type, written as an XML attribute.
struct PortSpec {
  std::string name;
  /// Type as shown in the TreeNodesModel ("int", "double", "bool", "std::string", ...).
  std::string type_name = "std::string";
  std::string description;
  /// Absent: the attribute is required.
  std::optional<std::string> default_value;
  /// For enumerations: the allowed values (the editor offers them as a list).
  std::vector<std::string> choices;
  /// Checks a written value: empty string when valid, else what is wrong with it.
  std::function<std::string(std::string_view)> check;

  static PortSpec text(std::string name, std::string description,
                       std::optional<std::string> default_value = std::nullopt);
  /// Integer within [min, max]; `special` is an extra allowed value (e.g. -1 = forever).
  static PortSpec integer(std::string name, std::string description, std::optional<std::string> default_value,
                          long long min, long long max, std::optional<long long> special = std::nullopt);
  static PortSpec number(std::string name, std::string description, std::optional<std::string> default_value,
                         double min, double max);
  static PortSpec boolean(std::string name, std::string description, std::optional<std::string> default_value);
  static PortSpec choice(std::string name, std::string description, std::vector<std::string> choices,
                         std::optional<std::string> default_value);
};

/// Strict parsers for attribute values (surrounding whitespace allowed). Empty on error.
std::optional<long long> parseInteger(std::string_view text);
std::optional<double> parseNumber(std::string_view text);
/// true/false/1/0, case-insensitive.
std::optional<bool> parseBoolean(std::string_view text);

struct NodeSpec;

/// The attributes of one node instance, after validation, with defaults applied.
class NodeArgs {
 public:
  NodeArgs(const NodeSpec& spec, const std::vector<std::pair<std::string, std::string>>& attributes);
  const NodeSpec& spec() const { return *spec_; }
  const std::string& name() const { return name_; }
  /// The written value, or the port's default. @throws std::out_of_range for an unknown port.
  const std::string& get(std::string_view port) const;
  long long getInt(std::string_view port) const;
  double getDouble(std::string_view port) const;
  bool getBool(std::string_view port) const;

 private:
  const NodeSpec* spec_;
  std::string name_;
  std::map<std::string, std::string, std::less<>> values_;
};

using NodeBuilder = std::function<std::unique_ptr<TreeNode>(const NodeArgs&)>;

struct NodeSpec {
  std::string id;
  NodeKind kind = NodeKind::kAction;
  NodeCategory category = NodeCategory::kInternal;
  std::string description;
  std::vector<PortSpec> ports;
  /// Returns RUNNING across ticks by itself (an action that takes time, a loop). Control
  /// nodes and most decorators are not: they run only when a descendant does. Reactive
  /// nodes re-tick every child but the last on each tick, so those children must not run.
  bool asynchronous = false;
  /// Extra checks of one instance beyond its ports (e.g. Parallel's counts against its
  /// number of children): empty string when valid, else the problem.
  std::function<std::string(const NodeArgs& args, std::size_t child_count)> check_instance;
  /// Built into BehaviorTree.CPP v4 under the same ID and semantics: Groot2 knows it, so
  /// the TreeNodesModel need not describe it.
  bool btcpp_builtin = false;
  /// Creates the node; children are attached by the builder. Unset for SubTree.
  NodeBuilder build;

  const PortSpec* port(std::string_view name) const;
};

class NodeRegistry {
 public:
  /// @throws std::invalid_argument if a node type with this ID exists already.
  void add(NodeSpec spec);
  const NodeSpec* find(std::string_view id) const;
  /// Every node type, sorted by ID.
  std::vector<const NodeSpec*> all() const;
  /// The registered ID closest to `id` by edit distance, if close enough to be a typo.
  std::optional<std::string> suggest(std::string_view id) const;

 private:
  std::map<std::string, NodeSpec, std::less<>> specs_;
};

/// Registers Sequence, Fallback, Parallel, Repeat, Reset, ... (docs/BEHAVIOR_TREES.md).
void registerBuiltinNodes(NodeRegistry& registry);

/// A registry with the built-in nodes only.
NodeRegistry builtinRegistry();

}  // namespace costar::bt
