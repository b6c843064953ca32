#include "server/plan_json.h"

#include <unordered_map>

namespace costar::server {

std::string checkName(std::string_view name) {
  if (name.empty() || name.size() > 64) {
    return "a name has 1 to 64 characters";
  }
  const auto alnum = [](char c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9'); };
  if (!alnum(name.front())) {
    return "a name starts with a letter or digit";
  }
  for (const char c : name) {
    if (!alnum(c) && c != '_' && c != '-') {
      return "a name has only letters, digits, '_' and '-' (names are not paths)";
    }
  }
  return {};
}

std::size_t jsonNestingDepth(std::string_view text) {
  std::size_t depth = 0;
  std::size_t deepest = 0;
  bool in_string = false;
  bool escaped = false;
  for (const char c : text) {
    if (in_string) {
      if (escaped) {
        escaped = false;
      } else if (c == '\\') {
        escaped = true;
      } else if (c == '"') {
        in_string = false;
      }
      continue;
    }
    if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      deepest = std::max(deepest, ++depth);
    } else if ((c == ']' || c == '}') && depth > 0) {
      --depth;
    }
  }
  return deepest;
}

nlohmann::json parseRequestJson(std::string_view text, std::size_t max_depth) {
  if (jsonNestingDepth(text) > max_depth) {
    throw RequestError(400, "JSON nested deeper than " + std::to_string(max_depth) + " levels");
  }
  nlohmann::json json = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (json.is_discarded()) {
    throw RequestError(400, "the request body is not valid JSON");
  }
  return json;
}

nlohmann::json planNodeToJson(const bt::PlanNode& node) {
  nlohmann::json attributes = nlohmann::json::array();
  for (const auto& [key, value] : node.attributes) {
    attributes.push_back({key, value});
  }
  nlohmann::json children = nlohmann::json::array();
  for (const auto& child : node.children) {
    children.push_back(planNodeToJson(child));
  }
  return {{"id", node.id}, {"attributes", std::move(attributes)}, {"children", std::move(children)}};
}

nlohmann::json planFileToJson(const bt::PlanFile& file) {
  nlohmann::json trees = nlohmann::json::array();
  for (const auto& tree : file.trees) {
    trees.push_back({{"id", tree.id}, {"root", planNodeToJson(tree.root)}});
  }
  return {{"main_tree", file.main_tree}, {"trees", std::move(trees)}};
}

namespace {

const std::string& stringField(const nlohmann::json& object, const char* key, const std::string& where) {
  const auto it = object.find(key);
  if (it == object.end() || !it->is_string()) {
    throw RequestError(400, where + ": '" + key + "' must be a string");
  }
  return it->get_ref<const std::string&>();
}

void checkXmlText(const std::string& text, const std::string& where) {
  // XML 1.0 cannot hold NUL at all; everything else is escaped by the writer.
  if (text.find('\0') != std::string::npos) {
    throw RequestError(400, where + ": text may not contain NUL characters");
  }
}

bool isXmlName(const std::string& name) {
  if (name.empty() || name.size() > 128) {
    return false;
  }
  const auto start = [](char c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_'; };
  if (!start(name.front())) {
    return false;
  }
  for (const char c : name) {
    if (!start(c) && !(c >= '0' && c <= '9') && c != '-' && c != '.') {
      return false;
    }
  }
  return true;
}

bt::PlanNode nodeFromJson(const nlohmann::json& json, const std::string& where, std::size_t& budget) {
  if (!json.is_object()) {
    throw RequestError(400, where + ": a node must be an object");
  }
  if (budget == 0) {
    throw RequestError(400, "the plan has too many nodes");
  }
  --budget;
  bt::PlanNode node;
  node.id = stringField(json, "id", where);
  if (!isXmlName(node.id)) {
    throw RequestError(400, where + ": '" + node.id.substr(0, 64) + "' is not a node type name");
  }
  if (const auto it = json.find("attributes"); it != json.end()) {
    if (!it->is_array()) {
      throw RequestError(400, where + ": 'attributes' must be a list of [name, value] pairs");
    }
    for (const auto& pair : *it) {
      if (!pair.is_array() || pair.size() != 2 || !pair[0].is_string() || !pair[1].is_string()) {
        throw RequestError(400, where + ": each attribute must be a [name, value] pair of strings");
      }
      const std::string& key = pair[0].get_ref<const std::string&>();
      const std::string& value = pair[1].get_ref<const std::string&>();
      if (!isXmlName(key)) {
        throw RequestError(400, where + ": '" + key.substr(0, 64) + "' is not an attribute name");
      }
      if (node.attribute(key)) {
        throw RequestError(400, where + ": attribute '" + key + "' given twice");
      }
      checkXmlText(value, where);
      node.attributes.emplace_back(key, value);
    }
  }
  if (const auto it = json.find("children"); it != json.end()) {
    if (!it->is_array()) {
      throw RequestError(400, where + ": 'children' must be a list");
    }
    std::size_t index = 0;
    for (const auto& child : *it) {
      node.children.push_back(nodeFromJson(child, where + "/" + std::to_string(index++), budget));
    }
  }
  return node;
}

}  // namespace

bt::PlanFile planFileFromJson(const nlohmann::json& json, const std::string& label, std::size_t max_nodes) {
  if (!json.is_object()) {
    throw RequestError(400, "a plan must be an object with 'main_tree' and 'trees'");
  }
  bt::PlanFile file;
  file.path = label;
  if (const auto it = json.find("main_tree"); it != json.end() && !it->is_null()) {
    if (!it->is_string()) {
      throw RequestError(400, "'main_tree' must be a string");
    }
    file.main_tree = it->get<std::string>();
    checkXmlText(file.main_tree, "main_tree");
  }
  if (json.contains("includes")) {
    throw RequestError(400, "plans from the editor cannot include files; insert saved subtrees instead");
  }
  const auto trees = json.find("trees");
  if (trees == json.end() || !trees->is_array() || trees->empty()) {
    throw RequestError(400, "'trees' must be a non-empty list");
  }
  std::size_t budget = max_nodes;
  for (std::size_t i = 0; i < trees->size(); ++i) {
    const auto& tree = (*trees)[i];
    const std::string where = "trees[" + std::to_string(i) + "]";
    if (!tree.is_object()) {
      throw RequestError(400, where + " must be an object");
    }
    bt::PlanTree plan_tree;
    plan_tree.id = stringField(tree, "id", where);
    checkXmlText(plan_tree.id, where);
    if (plan_tree.id.empty()) {
      throw RequestError(400, where + ": a tree needs an ID");
    }
    const auto root = tree.find("root");
    if (root == tree.end()) {
      throw RequestError(400, where + ": a tree needs a root node");
    }
    plan_tree.root = nodeFromJson(*root, plan_tree.id, budget);
    file.trees.push_back(std::move(plan_tree));
  }
  return file;
}

namespace {

/// Finds the first node written on each of `lines` (as parsed), in one walk over the file
/// with an explicit stack: a plan with thousands of problems costs one walk, not one each.
void locateLines(const bt::PlanFile& file, std::unordered_map<int, std::optional<NodeLocation>>& lines) {
  struct Frame {
    const bt::PlanNode* node;
    std::size_t next = 0;  // the next child to visit
  };
  std::size_t left = lines.size();
  for (const auto& tree : file.trees) {
    std::vector<Frame> frames{{&tree.root}};
    std::vector<std::size_t> path;
    const auto visit = [&](const bt::PlanNode& node) {
      if (const auto it = lines.find(node.location.line); it != lines.end() && !it->second) {
        it->second = NodeLocation{tree.id, path};
        --left;
      }
    };
    visit(tree.root);
    while (!frames.empty() && left > 0) {
      Frame& frame = frames.back();
      if (frame.next == frame.node->children.size()) {
        frames.pop_back();
        if (!path.empty()) {
          path.pop_back();
        }
        continue;
      }
      const bt::PlanNode& child = frame.node->children[frame.next];
      path.push_back(frame.next++);
      frames.push_back({&child});
      visit(child);
    }
  }
}

}  // namespace

std::optional<NodeLocation> nodeAtLine(const bt::PlanFile& file, int line) {
  if (line <= 0) {
    return std::nullopt;
  }
  std::unordered_map<int, std::optional<NodeLocation>> lines{{line, std::nullopt}};
  locateLines(file, lines);
  return lines[line];
}

nlohmann::json diagnosticsToJson(const std::vector<bt::Diagnostic>& diagnostics, const bt::PlanFile& file) {
  std::unordered_map<int, std::optional<NodeLocation>> lines;
  for (const auto& diagnostic : diagnostics) {
    if (diagnostic.where.file == file.path && diagnostic.where.line > 0) {
      lines.emplace(diagnostic.where.line, std::nullopt);
    }
  }
  locateLines(file, lines);
  nlohmann::json list = nlohmann::json::array();
  for (const auto& diagnostic : diagnostics) {
    nlohmann::json item = {
        {"where", bt::toString(diagnostic.where)}, {"line", diagnostic.where.line}, {"message", diagnostic.message}};
    if (diagnostic.where.file == file.path) {
      if (const auto it = lines.find(diagnostic.where.line); it != lines.end() && it->second) {
        item["node"] = {{"tree", it->second->tree}, {"path", it->second->index_path}};
      }
    }
    list.push_back(std::move(item));
  }
  return list;
}

}  // namespace costar::server
