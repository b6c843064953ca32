#include "bt/plan.h"

namespace costar::bt {

std::string toString(const SourceLocation& where) {
  std::string text = where.file.empty() ? "<plan>" : where.file;
  if (where.line > 0) {
    text += ':';
    text += std::to_string(where.line);
  }
  return text;
}

std::string Diagnostic::str() const { return toString(where) + ": " + message; }

namespace {

std::string joinDiagnostics(const std::vector<Diagnostic>& diagnostics) {
  std::string text;
  for (const auto& diagnostic : diagnostics) {
    if (!text.empty()) {
      text += '\n';
    }
    text += diagnostic.str();
  }
  return text;
}

}  // namespace

PlanError::PlanError(std::vector<Diagnostic> diagnostics)
    : std::runtime_error(joinDiagnostics(diagnostics)), diagnostics_(std::move(diagnostics)) {}

std::optional<std::string> PlanNode::attribute(std::string_view key) const {
  for (const auto& [name, value] : attributes) {
    if (name == key) {
      return value;
    }
  }
  return std::nullopt;
}

void PlanNode::setAttribute(std::string_view key, std::string value) {
  for (auto& [name, existing] : attributes) {
    if (name == key) {
      existing = std::move(value);
      return;
    }
  }
  attributes.emplace_back(std::string(key), std::move(value));
}

std::size_t PlanNode::size() const {
  std::size_t count = 1;
  for (const auto& child : children) {
    count += child.size();
  }
  return count;
}

const PlanTree* Plan::findTree(std::string_view id) const {
  for (const auto& tree : file.trees) {
    if (tree.id == id) {
      return &tree;
    }
  }
  for (const auto& other : included) {
    for (const auto& tree : other.trees) {
      if (tree.id == id) {
        return &tree;
      }
    }
  }
  return nullptr;
}

std::string Plan::mainTreeId() const {
  if (!file.main_tree.empty()) {
    return file.main_tree;
  }
  if (file.trees.size() == 1) {
    return file.trees.front().id;
  }
  Diagnostic problem;
  problem.where = {file.path, 0};
  problem.message = file.trees.empty() ? "the file defines no BehaviorTree"
                                       : "the file defines several BehaviorTrees but no main_tree_to_execute";
  throw PlanError({std::move(problem)});
}

bool sameContent(const PlanNode& a, const PlanNode& b) {
  if (a.id != b.id || a.attributes != b.attributes || a.children.size() != b.children.size()) {
    return false;
  }
  for (std::size_t i = 0; i < a.children.size(); ++i) {
    if (!sameContent(a.children[i], b.children[i])) {
      return false;
    }
  }
  return true;
}

bool sameContent(const PlanFile& a, const PlanFile& b) {
  if (a.main_tree != b.main_tree || a.includes.size() != b.includes.size() || a.trees.size() != b.trees.size()) {
    return false;
  }
  for (std::size_t i = 0; i < a.includes.size(); ++i) {
    if (a.includes[i].path != b.includes[i].path) {
      return false;
    }
  }
  for (std::size_t i = 0; i < a.trees.size(); ++i) {
    if (a.trees[i].id != b.trees[i].id || !sameContent(a.trees[i].root, b.trees[i].root)) {
      return false;
    }
  }
  return true;
}

}  // namespace costar::bt
