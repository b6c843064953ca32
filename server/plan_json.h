#pragma once
// The editor's JSON form of a task plan, and the checks on what the browser sends.
//
// The page edits plans as JSON; the server turns them into the BehaviorTree.CPP v4 XML that
// `costar run` reads (bt::writePlanFile), so a plan saved from the page is the same file the
// CLI runs. The JSON mirrors bt::PlanFile one to one (attribute order kept):
//
//   {"main_tree": "main",
//    "trees": [{"id": "main",
//               "root": {"id": "Sequence", "attributes": [["name", "pick"]],
//                        "children": [{"id": "Open", "attributes": [], "children": []}]}}]}
//
// Plans from the page are self-contained: <include> is refused (a saved subtree is inserted as
// a <BehaviorTree> of the same file), so nothing the browser sends can name a file.

#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "bt/plan.h"

namespace costar::server {

/// A request the server refuses: HTTP status (4xx) and a message for the user.
class RequestError : public std::runtime_error {
 public:
  RequestError(int status, const std::string& message) : std::runtime_error(message), status_(status) {}
  int status() const { return status_; }

 private:
  int status_;
};

/// Names of plans and saved subtrees are identifiers, never paths: 1-64 characters of letters,
/// digits, '_' and '-', starting with a letter or digit. Empty result when valid.
std::string checkName(std::string_view name);

/// Deepest nesting of arrays and objects in JSON text (strings skipped), counted without
/// parsing, so hostile input is refused before a recursive parser or printer sees it.
std::size_t jsonNestingDepth(std::string_view text);

/// Parses JSON text from a request. @throws RequestError 400 for bad JSON or nesting deeper
/// than `max_depth`.
nlohmann::json parseRequestJson(std::string_view text, std::size_t max_depth = 256);

/// The JSON form of a plan file (includes are not represented: see planFileFromJson).
nlohmann::json planFileToJson(const bt::PlanFile& file);
nlohmann::json planNodeToJson(const bt::PlanNode& node);

/// Reads the JSON form. @throws RequestError 400 naming what is malformed (wrong types,
/// missing fields, more than `max_nodes` nodes).
bt::PlanFile planFileFromJson(const nlohmann::json& json, const std::string& label, std::size_t max_nodes = 100'000);

/// Where a node is in the editor's terms: the tree's ID and the child indices from its root.
struct NodeLocation {
  std::string tree;
  std::vector<std::size_t> index_path;
};

/// A diagnostic as JSON: {"where": "label:12", "line": 12, "message": ..., and "node":
/// {"tree": "main", "path": [0, 2]} when it points at a node of `file`}.
nlohmann::json diagnosticsToJson(const std::vector<bt::Diagnostic>& diagnostics, const bt::PlanFile& file);

/// The node written at `line` of `file` (as parsed), if any.
std::optional<NodeLocation> nodeAtLine(const bt::PlanFile& file, int line);

}  // namespace costar::server
