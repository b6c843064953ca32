#include "bt/builder.h"

#include <algorithm>
#include <map>
#include <set>

#include "bt/decorator_nodes.h"

namespace costar::bt {

namespace {

// Attributes BehaviorTree.CPP evaluates as scripts: they need a blackboard, which CoSTAR
// plans do not have (the paper: no user variables, no scope). Each with what to use instead.
struct ScriptAttribute {
  std::string_view key;
  std::string_view instead;
};
constexpr std::string_view kUseConditionBefore =
    "put a condition (CheckPredicate) before the node instead, in a Sequence, IfThenElse or WhileDoElse";
constexpr std::string_view kUseResult =
    "there are no variables to update: act on the node's result instead (Fallback, IfThenElse, TryCatch)";
constexpr ScriptAttribute kScriptAttributes[] = {
    {"_skipIf", kUseConditionBefore},    {"_failureIf", kUseConditionBefore},
    {"_successIf", kUseConditionBefore}, {"_while", kUseConditionBefore},
    {"_onSuccess", kUseResult},          {"_onFailure", kUseResult},
    {"_onHalted", kUseResult},           {"_post", kUseResult}};

const ScriptAttribute* findScriptAttribute(std::string_view key) {
  for (const ScriptAttribute& attribute : kScriptAttributes) {
    if (attribute.key == key) {
      return &attribute;
    }
  }
  return nullptr;
}

// BehaviorTree.CPP built-ins that read or write the blackboard: refused by design, each with
// what a CoSTAR plan uses instead.
struct BlackboardNode {
  std::string_view id;
  std::string_view instead;
};
constexpr std::string_view kUseCondition = "test the world state with a condition (CheckPredicate) instead";
constexpr std::string_view kUseBranch =
    "branch on conditions instead: IfThenElse, WhileDoElse or a Fallback over CheckPredicate nodes";
constexpr std::string_view kUseLoop = "loop with Repeat, RepeatRuns or RetryUntilSuccessful instead";
constexpr std::string_view kUseParameters = "write each value as a parameter of the node that uses it instead";
constexpr BlackboardNode kBlackboardNodes[] = {{"Script", kUseParameters},
                                               {"ScriptCondition", kUseCondition},
                                               {"Precondition", kUseBranch},
                                               {"SetBlackboard", kUseParameters},
                                               {"UnsetBlackboard", kUseParameters},
                                               {"Switch2", kUseBranch},
                                               {"Switch3", kUseBranch},
                                               {"Switch4", kUseBranch},
                                               {"Switch5", kUseBranch},
                                               {"Switch6", kUseBranch},
                                               {"LoopInt", kUseLoop},
                                               {"LoopDouble", kUseLoop},
                                               {"LoopString", kUseLoop},
                                               {"LoopBool", kUseLoop},
                                               {"WasEntryUpdated", kUseCondition},
                                               {"SkipUnlessUpdated", kUseCondition},
                                               {"WaitValueUpdate", kUseCondition}};

const BlackboardNode* findBlackboardNode(std::string_view id) {
  for (const BlackboardNode& node : kBlackboardNodes) {
    if (node.id == id) {
      return &node;
    }
  }
  return nullptr;
}

constexpr std::string_view kByDesign =
    "CoSTAR plans have no blackboard, by design (the paper: no user variables, no scope)";

bool isBlackboardReference(std::string_view value) {
  const auto open = value.find('{');
  return open != std::string_view::npos && value.find('}', open) != std::string_view::npos;
}

std::string portList(const NodeSpec& spec) {
  if (spec.ports.empty()) {
    return "it takes none";
  }
  std::string list = "it takes ";
  for (std::size_t i = 0; i < spec.ports.size(); ++i) {
    list += (i == 0 ? "" : ", ") + spec.ports[i].name;
  }
  return list;
}

class Validator {
 public:
  Validator(const Plan& plan, const NodeRegistry& registry, const BuildLimits& limits)
      : plan_(plan), registry_(registry), limits_(limits) {}

  std::vector<Diagnostic> run() {
    checkDuplicateTrees();
    for (const PlanFile* file : files()) {
      for (const PlanTree& tree : file->trees) {
        checkNode(tree.root);
      }
    }
    checkMainTree();
    std::sort(diagnostics_.begin(), diagnostics_.end(), [](const Diagnostic& a, const Diagnostic& b) {
      return std::tie(a.where.file, a.where.line) < std::tie(b.where.file, b.where.line);
    });
    return std::move(diagnostics_);
  }

 private:
  std::vector<const PlanFile*> files() const {
    std::vector<const PlanFile*> all{&plan_.file};
    for (const auto& file : plan_.included) {
      all.push_back(&file);
    }
    return all;
  }

  void error(const SourceLocation& where, std::string message) { diagnostics_.push_back({where, std::move(message)}); }

  void checkDuplicateTrees() {
    std::map<std::string, SourceLocation> seen;
    for (const PlanFile* file : files()) {
      for (const PlanTree& tree : file->trees) {
        const auto [it, inserted] = seen.emplace(tree.id, tree.location);
        if (!inserted && it->second.file != tree.location.file) {
          error(tree.location, "BehaviorTree '" + tree.id + "' is also defined at " + toString(it->second));
        }
      }
    }
  }

  void checkMainTree() {
    std::string main_id;
    try {
      main_id = plan_.mainTreeId();
    } catch (const PlanError& missing) {
      diagnostics_.insert(diagnostics_.end(), missing.diagnostics().begin(), missing.diagnostics().end());
      return;
    }
    const PlanTree* main = plan_.findTree(main_id);
    if (main == nullptr) {
      error({plan_.file.path, 0}, "main_tree_to_execute names '" + main_id + "', but no BehaviorTree has that ID");
      return;
    }
    // Recursion, size and depth of the main tree once every SubTree is expanded.
    std::vector<std::string> stack;
    measure(*main, stack);
  }

  struct Measure {
    std::size_t nodes = 0;
    std::size_t depth = 0;
  };

  // Size and depth of a tree with its SubTrees expanded; reports recursion.
  std::optional<Measure> measure(const PlanTree& tree, std::vector<std::string>& stack) {
    if (const auto it = measured_.find(tree.id); it != measured_.end()) {
      return it->second;
    }
    if (std::find(stack.begin(), stack.end(), tree.id) != stack.end()) {
      return std::nullopt;  // reported by the caller, which knows the SubTree's line
    }
    stack.push_back(tree.id);
    const auto result = measureNode(tree.root, stack);
    stack.pop_back();
    if (result) {
      measured_[tree.id] = *result;
    }
    return result;
  }

  std::optional<Measure> measureNode(const PlanNode& node, std::vector<std::string>& stack) {
    Measure total{1, 1};
    if (node.id == "SubTree") {
      const auto id = node.attribute("ID");
      const PlanTree* tree = id ? plan_.findTree(*id) : nullptr;
      if (tree == nullptr) {
        return total;  // reported by checkNode
      }
      if (std::find(stack.begin(), stack.end(), *id) != stack.end()) {
        std::string cycle;
        for (const auto& step : stack) {
          cycle += step + " -> ";
        }
        error(node.location, "subtree '" + *id + "' contains itself: " + cycle + *id);
        return std::nullopt;
      }
      const auto inner = measure(*tree, stack);
      if (!inner) {
        return std::nullopt;
      }
      total.nodes += inner->nodes;
      total.depth += inner->depth;
    }
    for (const PlanNode& child : node.children) {
      const auto inner = measureNode(child, stack);
      if (!inner) {
        return std::nullopt;
      }
      total.nodes += inner->nodes;
      total.depth = std::max(total.depth, inner->depth + 1);
    }
    if (total.nodes > limits_.max_nodes) {
      error(node.location, "the plan expands to more than " + std::to_string(limits_.max_nodes) +
                               " nodes once its subtrees are instantiated");
      return std::nullopt;
    }
    if (total.depth > limits_.max_depth) {
      error(node.location, "the plan nests deeper than " + std::to_string(limits_.max_depth) +
                               " levels once its subtrees are instantiated");
      return std::nullopt;
    }
    return total;
  }

  void checkNode(const PlanNode& node) {
    const NodeSpec* spec = registry_.find(node.id);
    if (spec == nullptr) {
      std::string message = "unknown node '" + node.id + "'";
      if (const BlackboardNode* blackboard = findBlackboardNode(node.id)) {
        message = "'" + node.id + "' is a BehaviorTree.CPP node that works on the blackboard; " +
                  std::string(kByDesign) + ": " + std::string(blackboard->instead);
      } else if (const auto suggestion = registry_.suggest(node.id)) {
        message += " (did you mean '" + *suggestion + "'?)";
      }
      error(node.location, message);
    } else {
      checkChildren(*spec, node);
      checkAttributes(*spec, node);
      if (spec->kind == NodeKind::kSubTree) {
        checkSubTree(node);
      }
      if (node.id == "ReactiveSequence" || node.id == "ReactiveFallback") {
        checkReactive(node);
      }
      if (node.id == "WhileDoElse" && !node.children.empty() && mayRun(node.children.front())) {
        error(node.children.front().location,
              node.children.front().id +
                  " can be RUNNING, but WhileDoElse re-checks its first child on every tick while a branch runs: "
                  "the condition must complete at once (use a condition such as CheckPredicate)");
      }
    }
    for (const PlanNode& child : node.children) {
      checkNode(child);
    }
  }

  void checkChildren(const NodeSpec& spec, const PlanNode& node) {
    const std::size_t n = node.children.size();
    switch (spec.kind) {
      case NodeKind::kControl:
        if (n == 0) {
          error(node.location, node.id + " needs at least one child");
        }
        break;
      case NodeKind::kDecorator:
        if (n != 1) {
          error(node.location, node.id + " needs exactly one child, has " + std::to_string(n));
        }
        break;
      default:
        if (n != 0) {
          error(node.location, node.id + " is a leaf and cannot have children, has " + std::to_string(n));
        }
    }
  }

  void checkAttributes(const NodeSpec& spec, const PlanNode& node) {
    bool ports_valid = true;
    for (const auto& [key, value] : node.attributes) {
      if (key == "name") {
        continue;
      }
      if (const ScriptAttribute* script = findScriptAttribute(key)) {
        error(node.location, "'" + key + "' is a BehaviorTree.CPP script; " + std::string(kByDesign) + ": " +
                                 std::string(script->instead));
        ports_valid = false;
        continue;
      }
      if (key.starts_with("_")) {
        // BehaviorTree.CPP's own attributes (_description, _uid, _fullpath, _autoremap, ...):
        // metadata for tools, not parameters; BehaviorTree.CPP accepts any, and so do we.
        continue;
      }
      const PortSpec* port = spec.port(key);
      if (port == nullptr) {
        std::string message = node.id + " has no parameter '" + key + "'";
        if (spec.kind == NodeKind::kSubTree) {
          message += ": SubTree port remapping needs a blackboard; " + std::string(kByDesign) +
                     ": write the values as parameters of the nodes inside the subtree instead";
        } else {
          message += " (" + portList(spec) + ")";
        }
        error(node.location, message);
        ports_valid = false;
        continue;
      }
      if (isBlackboardReference(value)) {
        error(node.location, "parameter '" + key + "' of " + node.id + " is '" + value + "', a blackboard reference; " +
                                 std::string(kByDesign) + ": write the value itself instead");
        ports_valid = false;
        continue;
      }
      if (port->check) {
        if (const std::string problem = port->check(value); !problem.empty()) {
          error(node.location, "parameter '" + key + "' of " + node.id + ": " + problem);
          ports_valid = false;
        }
      }
    }
    for (const PortSpec& port : spec.ports) {
      if (!port.default_value && !node.attribute(port.name)) {
        error(node.location, node.id + " needs parameter '" + port.name + "' (" + port.description + ")");
        ports_valid = false;
      }
    }
    if (ports_valid && spec.check_instance) {
      const NodeArgs args(spec, node.attributes);
      if (const std::string problem = spec.check_instance(args, node.children.size()); !problem.empty()) {
        error(node.location, node.id + ": " + problem);
      }
    }
  }

  void checkSubTree(const PlanNode& node) {
    const auto id = node.attribute("ID");
    if (!id || plan_.findTree(*id) != nullptr) {
      return;
    }
    std::string message = "unknown subtree '" + *id + "'";
    std::string known;
    for (const PlanFile* file : files()) {
      for (const PlanTree& tree : file->trees) {
        known += (known.empty() ? "" : ", ") + tree.id;
      }
    }
    error(node.location, message + " (the plan defines: " + known + ")");
  }

  // Whether a node can return RUNNING, looking through SubTrees.
  bool mayRun(const PlanNode& node, int depth = 0) {
    const NodeSpec* spec = registry_.find(node.id);
    if (spec == nullptr || depth > 64) {
      return false;
    }
    if (spec->asynchronous) {
      return true;
    }
    if (spec->kind == NodeKind::kSubTree) {
      const auto id = node.attribute("ID");
      const PlanTree* tree = id ? plan_.findTree(*id) : nullptr;
      return tree != nullptr && mayRun(tree->root, depth + 1);
    }
    return std::any_of(node.children.begin(), node.children.end(),
                       [&](const PlanNode& child) { return mayRun(child, depth + 1); });
  }

  void checkReactive(const PlanNode& node) {
    for (std::size_t i = 0; i + 1 < node.children.size(); ++i) {
      if (mayRun(node.children[i])) {
        error(node.children[i].location,
              node.children[i].id + " can be RUNNING, but " + node.id +
                  " re-ticks every child before its last one on each tick, which would restart it: "
                  "only the last child of a " +
                  node.id + " may take time (use conditions before it)");
      }
    }
  }

  const Plan& plan_;
  const NodeRegistry& registry_;
  const BuildLimits& limits_;
  std::vector<Diagnostic> diagnostics_;
  std::map<std::string, Measure> measured_;
};

class Instantiator {
 public:
  Instantiator(const Plan& plan, const NodeRegistry& registry) : plan_(plan), registry_(registry) {}

  TreeNode* build(const PlanNode& node) {
    const NodeSpec& spec = *registry_.find(node.id);
    std::unique_ptr<TreeNode> instance;
    if (spec.kind == NodeKind::kSubTree) {
      const std::string id = *node.attribute("ID");
      auto subtree = std::make_unique<SubTreeNode>(spec.id, node.name(), id);
      subtree->setChild(build(plan_.findTree(id)->root));
      instance = std::move(subtree);
    } else {
      try {
        instance = spec.build(NodeArgs(spec, node.attributes));
      } catch (const std::exception& e) {
        throw PlanError({{node.location, "cannot create " + node.id + ": " + e.what()}});
      }
      if (auto* control = dynamic_cast<ControlNode*>(instance.get())) {
        for (const PlanNode& child : node.children) {
          control->addChild(build(child));
        }
      } else if (auto* decorator = dynamic_cast<DecoratorNode*>(instance.get())) {
        decorator->setChild(build(node.children.front()));
      }
    }
    nodes_.push_back(std::move(instance));
    return nodes_.back().get();
  }

  std::vector<std::unique_ptr<TreeNode>> nodes_;

 private:
  const Plan& plan_;
  const NodeRegistry& registry_;
};

}  // namespace

std::vector<Diagnostic> validatePlan(const Plan& plan, const NodeRegistry& registry, const BuildLimits& limits) {
  return Validator(plan, registry, limits).run();
}

Tree buildTree(const Plan& plan, const NodeRegistry& registry, const Clock& clock, const std::string& tree_id,
               const BuildLimits& limits) {
  auto diagnostics = validatePlan(plan, registry, limits);
  if (!diagnostics.empty()) {
    throw PlanError(std::move(diagnostics));
  }
  const std::string id = tree_id.empty() ? plan.mainTreeId() : tree_id;
  const PlanTree* tree = plan.findTree(id);
  if (tree == nullptr) {
    throw PlanError({{{plan.file.path, 0}, "no BehaviorTree with ID '" + id + "'"}});
  }
  Instantiator instantiator(plan, registry);
  TreeNode* root = instantiator.build(tree->root);
  return Tree(id, std::move(instantiator.nodes_), root, clock);
}

}  // namespace costar::bt
