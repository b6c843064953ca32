#pragma once
// A task plan as data: the content of BehaviorTree.CPP v4 XML files, before it is validated
// against a NodeRegistry and instantiated as a Tree. No XML parser here (see plan_xml.h).

#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace costar::bt {

/// Where something was written: file (as given to the loader) and 1-based line (0: unknown).
struct SourceLocation {
  std::string file;
  int line = 0;
};

/// `file:line`, or `file` when the line is unknown.
std::string toString(const SourceLocation& where);

/// A problem found while reading or validating a plan, e.g. `plan.xml:12: unknown node 'Sequense'`.
struct Diagnostic {
  SourceLocation where;
  std::string message;
  std::string str() const;
};

/// Thrown when a plan cannot be read or is invalid; carries every problem found.
class PlanError : public std::runtime_error {
 public:
  explicit PlanError(std::vector<Diagnostic> diagnostics);
  const std::vector<Diagnostic>& diagnostics() const { return diagnostics_; }

 private:
  std::vector<Diagnostic> diagnostics_;
};

/// One node element: its type ID, attributes in written order (including `name`), children.
struct PlanNode {
  std::string id;
  std::vector<std::pair<std::string, std::string>> attributes;
  std::vector<PlanNode> children;
  SourceLocation location;

  /// The attribute's value, or nullopt if absent.
  std::optional<std::string> attribute(std::string_view key) const;
  void setAttribute(std::string_view key, std::string value);
  std::string name() const { return attribute("name").value_or(""); }
  /// Number of nodes in this subtree (this one included).
  std::size_t size() const;
};

/// An `<include path=...>` element.
struct PlanInclude {
  std::string path;
  SourceLocation location;
};

/// A `<BehaviorTree ID=...>` element with its single root node.
struct PlanTree {
  std::string id;
  PlanNode root;
  SourceLocation location;
};

/// The content of one plan file.
struct PlanFile {
  /// Path the file was loaded from, or a label for text.
  std::string path;
  /// `main_tree_to_execute`; empty if the file does not name one.
  std::string main_tree;
  /// `<include path=...>` elements; paths as written (relative to this file's folder).
  std::vector<PlanInclude> includes;
  std::vector<PlanTree> trees;
};

/// A plan file together with every file it includes (transitively, each once).
struct Plan {
  PlanFile file;
  std::vector<PlanFile> included;

  /// The tree with this ID in any of the files, or nullptr.
  const PlanTree* findTree(std::string_view id) const;
  /// The main tree's ID: main_tree_to_execute, else the only tree of the file.
  /// @throws PlanError when neither applies.
  std::string mainTreeId() const;
};

/// True when both have the same trees, nodes, attributes and includes (locations ignored).
bool sameContent(const PlanFile& a, const PlanFile& b);
bool sameContent(const PlanNode& a, const PlanNode& b);

}  // namespace costar::bt
