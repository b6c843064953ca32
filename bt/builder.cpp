#include "bt/builder.h"

#include <algorithm>
#include <limits>
#include <map>
#include <optional>
#include <unordered_map>
#include <unordered_set>

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

/// The trees of a plan by ID, found as Plan::findTree finds them (the file's own first, then
/// the included files' in order), in constant time: a plan of thousands of trees stays linear.
class TreeIndex {
 public:
  explicit TreeIndex(const Plan& plan) {
    add(plan.file);
    for (const PlanFile& file : plan.included) {
      add(file);
    }
  }
  /// The number of different tree IDs.
  std::size_t size() const { return trees_.size(); }
  const PlanTree* find(std::string_view id) const {
    const auto it = trees_.find(id);
    return it == trees_.end() ? nullptr : it->second;
  }
  /// The tree a SubTree node names, or nullptr.
  const PlanTree* find(const PlanNode& subtree) const {
    for (const auto& [key, value] : subtree.attributes) {
      if (key == "ID") {
        return find(value);
      }
    }
    return nullptr;
  }

 private:
  void add(const PlanFile& file) {
    for (const PlanTree& tree : file.trees) {
      trees_.emplace(tree.id, &tree);
    }
  }
  std::unordered_map<std::string_view, const PlanTree*> trees_;
};

/// Sums and products of sizes that saturate instead of wrapping around (a tree used twice at
/// each of 200 levels has 2^200 nodes).
constexpr std::size_t kSaturated = std::numeric_limits<std::size_t>::max() / 2;
std::size_t addSaturated(std::size_t a, std::size_t b) {
  return a > kSaturated - std::min(b, kSaturated) ? kSaturated : a + b;
}
std::size_t mulSaturated(std::size_t a, std::size_t b) { return b != 0 && a > kSaturated / b ? kSaturated : a * b; }

/// At least the bytes of a node's segment of a path (`Sequence "pick"`, `Sequence[12]`).
std::size_t segmentBytes(const PlanNode& node) {
  std::size_t name = 0;
  for (const auto& [key, value] : node.attributes) {
    if (key == "name") {
      name = value.size();
    }
  }
  return node.id.size() + name + 24;
}

class Validator {
 public:
  Validator(const Plan& plan, const NodeRegistry& registry, const BuildLimits& limits)
      : plan_(plan), registry_(registry), limits_(limits), index_(plan) {}

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
    const PlanTree* main = index_.find(main_id);
    if (main == nullptr) {
      error({plan_.file.path, 0}, "main_tree_to_execute names '" + main_id + "', but no BehaviorTree has that ID");
      return;
    }
    measure(*main);
  }

  /// A subtree with its SubTrees expanded: nodes, levels, and the bytes of every node's path
  /// below where it hangs (each node keeps its path: it can dwarf the node count).
  struct Measure {
    std::size_t nodes = 0;
    std::size_t depth = 0;
    std::size_t path_bytes = 0;
  };

  /// Recursion, size, depth and path bytes of the main tree once every SubTree is expanded,
  /// reporting the first limit crossed. One walk with an explicit stack, so a chain of any
  /// number of SubTrees cannot overflow the call stack; nothing deeper than the limit is
  /// entered; each tree is measured once, however often it is used.
  void measure(const PlanTree& main) {
    struct Frame {
      const PlanNode* node;
      const PlanTree* tree;  // the tree whose root this is, or nullptr
      std::size_t segment;   // bytes this node adds to each path below it
      Measure total;
      std::size_t next_child = 0;
      bool expanded = false;  // a SubTree's tree was looked at
    };
    std::vector<Frame> frames;
    std::unordered_set<const PlanTree*> on_stack;
    const auto enter = [&](const PlanNode& node, const PlanTree* tree, std::size_t prefix) {
      if (frames.size() >= limits_.max_depth) {
        error(node.location, tooDeep());
        return false;
      }
      const std::size_t segment = prefix + segmentBytes(node);
      frames.push_back({&node, tree, segment, {1, 1, segment}});
      if (tree != nullptr) {
        on_stack.insert(tree);
      }
      return true;
    };
    const auto addChild = [](Frame& parent, const Measure& child) {
      parent.total.nodes = addSaturated(parent.total.nodes, child.nodes);
      parent.total.depth = std::max(parent.total.depth, child.depth + 1);
      parent.total.path_bytes = addSaturated(
          parent.total.path_bytes, addSaturated(child.path_bytes, mulSaturated(child.nodes, parent.segment + 1)));
    };
    // Every path starts with the main tree's ID and a slash.
    if (!enter(main.root, &main, main.id.size() + 1)) {
      return;
    }
    while (!frames.empty()) {
      Frame& frame = frames.back();
      const PlanNode& node = *frame.node;
      if (!frame.expanded) {
        frame.expanded = true;
        const NodeSpec* spec = registry_.find(node.id);
        const PlanTree* tree =  // an unknown one is reported by checkSubTree
            spec != nullptr && spec->kind == NodeKind::kSubTree ? index_.find(node) : nullptr;
        if (tree != nullptr) {
          if (const auto it = measured_.find(tree); it != measured_.end()) {
            addChild(frame, it->second);
          } else if (on_stack.contains(tree)) {
            std::string cycle;
            for (const Frame& step : frames) {
              if (step.tree != nullptr) {
                cycle += step.tree->id + " -> ";
              }
            }
            error(node.location, "subtree '" + tree->id + "' contains itself: " + cycle + tree->id);
            return;
          } else if (!enter(tree->root, tree, 0)) {
            return;
          } else {
            continue;
          }
        }
      }
      if (frame.next_child < node.children.size()) {
        if (!enter(node.children[frame.next_child++], nullptr, 0)) {
          return;
        }
        continue;
      }
      // Done with this node: the levels above it count towards the depth too. Paths only for
      // the whole plan: a plan too large in nodes is told so, not that its paths are long.
      if (!withinLimits(node, frame.total, frames.size() - 1, /*whole_plan=*/frames.size() == 1)) {
        return;
      }
      const Measure done = frame.total;
      const PlanTree* tree = frame.tree;
      frames.pop_back();
      if (tree != nullptr) {
        measured_[tree] = done;
        on_stack.erase(tree);
      }
      if (!frames.empty()) {
        addChild(frames.back(), done);
      }
    }
  }

  std::string tooDeep() const {
    return "the plan nests deeper than " + std::to_string(limits_.max_depth) +
           " levels once its subtrees are instantiated";
  }

  bool withinLimits(const PlanNode& node, const Measure& total, std::size_t levels_above, bool whole_plan) {
    if (total.nodes > limits_.max_nodes) {
      error(node.location, "the plan expands to more than " + std::to_string(limits_.max_nodes) +
                               " nodes once its subtrees are instantiated");
      return false;
    }
    if (levels_above + total.depth > limits_.max_depth) {
      error(node.location, tooDeep());
      return false;
    }
    if (whole_plan && total.path_bytes > limits_.max_path_bytes) {
      error(node.location, "the plan's node paths (main/Sequence[1]/..., one per node) add up to more than " +
                               std::to_string(limits_.max_path_bytes >> 20) +
                               " MiB once its subtrees are instantiated: use shorter names or fewer levels "
                               "of subtrees");
      return false;
    }
    return true;
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
    if (!id || index_.find(*id) != nullptr) {
      return;
    }
    // The first few IDs: a plan of thousands of trees that names a missing one thousands of
    // times must not make a message per reference that lists them all.
    constexpr std::size_t kListed = 20;
    std::string known;
    std::size_t count = 0;
    for (const PlanFile* file : files()) {
      for (std::size_t i = 0; i < file->trees.size() && count < kListed; ++i, ++count) {
        known += (known.empty() ? "" : ", ") + file->trees[i].id;
      }
    }
    if (index_.size() > count) {
      known += " and " + std::to_string(index_.size() - count) + " more";
    }
    error(node.location, "unknown subtree '" + *id + "' (the plan defines: " + known + ")");
  }

  /// Visits the nodes below `root` (itself included) that a tick can reach without entering a
  /// SubTree; `visit` returns whether to look below a node. An explicit stack, not recursion.
  template <typename Visit>
  static void visitTree(const PlanNode& root, Visit&& visit) {
    std::vector<const PlanNode*> pending{&root};
    while (!pending.empty()) {
      const PlanNode& node = *pending.back();
      pending.pop_back();
      if (visit(node)) {
        for (const PlanNode& child : node.children) {
          pending.push_back(&child);
        }
      }
    }
  }

  /// Whether a node can return RUNNING: it is asynchronous, or a node it ticks is, looking
  /// through SubTrees (their trees worked out once for the whole plan, see runningTrees()).
  bool mayRun(const PlanNode& node) {
    const auto& running = runningTrees();
    bool found = false;
    visitTree(node, [&](const PlanNode& next) {
      const NodeSpec* spec = registry_.find(next.id);
      if (found || spec == nullptr) {
        return false;
      }
      if (spec->asynchronous) {
        found = true;
      } else if (spec->kind == NodeKind::kSubTree) {
        const PlanTree* tree = index_.find(next);
        found = tree != nullptr && running.contains(tree);
      }
      return !found && spec->kind != NodeKind::kSubTree;
    });
    return found;
  }

  /// The trees that can return RUNNING: those with an asynchronous node of their own, and
  /// those that use one of them through SubTrees, however deep (a search backwards along the
  /// SubTree references: linear in the plan, without recursion). Once per plan.
  const std::unordered_set<const PlanTree*>& runningTrees() {
    if (running_trees_) {
      return *running_trees_;
    }
    running_trees_.emplace();
    std::unordered_map<const PlanTree*, std::vector<const PlanTree*>> used_by;
    std::vector<const PlanTree*> pending;
    for (const PlanFile* file : files()) {
      for (const PlanTree& tree : file->trees) {
        bool asynchronous = false;
        visitTree(tree.root, [&](const PlanNode& node) {
          const NodeSpec* spec = registry_.find(node.id);
          if (spec == nullptr) {
            return false;
          }
          if (spec->asynchronous) {
            asynchronous = true;
          } else if (spec->kind == NodeKind::kSubTree) {
            if (const PlanTree* used = index_.find(node)) {
              used_by[used].push_back(&tree);
            }
          }
          return !spec->asynchronous && spec->kind != NodeKind::kSubTree;
        });
        if (asynchronous && running_trees_->insert(&tree).second) {
          pending.push_back(&tree);
        }
      }
    }
    while (!pending.empty()) {
      const PlanTree* tree = pending.back();
      pending.pop_back();
      for (const PlanTree* user : used_by[tree]) {
        if (running_trees_->insert(user).second) {
          pending.push_back(user);
        }
      }
    }
    return *running_trees_;
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
  const TreeIndex index_;
  std::vector<Diagnostic> diagnostics_;
  std::unordered_map<const PlanTree*, Measure> measured_;
  std::optional<std::unordered_set<const PlanTree*>> running_trees_;
};

class Instantiator {
 public:
  Instantiator(const Plan& plan, const NodeRegistry& registry) : index_(plan), registry_(registry) {}

  // Recursive: the plan was validated, so it nests no deeper than BuildLimits::max_depth.

  TreeNode* build(const PlanNode& node) {
    const NodeSpec& spec = *registry_.find(node.id);
    std::unique_ptr<TreeNode> instance;
    if (spec.kind == NodeKind::kSubTree) {
      const std::string id = *node.attribute("ID");
      auto subtree = std::make_unique<SubTreeNode>(spec.id, node.name(), id);
      subtree->setChild(build(index_.find(id)->root));
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
  const TreeIndex index_;
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
    Diagnostic missing;  // built in place: GCC 12 warns maybe-uninitialized on the braced temporary
    missing.where = {plan.file.path, 0};
    missing.message = "no BehaviorTree with ID '" + id + "'";
    throw PlanError({std::move(missing)});
  }
  Instantiator instantiator(plan, registry);
  TreeNode* root = instantiator.build(tree->root);
  return Tree(id, std::move(instantiator.nodes_), root, clock);
}

}  // namespace costar::bt
