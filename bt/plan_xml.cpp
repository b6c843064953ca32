#include "bt/plan_xml.h"

#include <tinyxml2.h>

#include <algorithm>
#include <fstream>
#include <memory>
#include <set>
#include <sstream>

#include "bt/nodes_model.h"
#include "bt/registry.h"
#include "bt/xml_writer.h"
#include "core/files.h"

namespace costar::bt {

namespace {

constexpr std::string_view kExplicitKinds[] = {"Action", "Condition", "Control", "Decorator"};

bool isExplicitKind(std::string_view element) {
  return std::find(std::begin(kExplicitKinds), std::end(kExplicitKinds), element) != std::end(kExplicitKinds);
}

bool isBlank(const char* text) {
  if (text == nullptr) {
    return true;
  }
  for (; *text != '\0'; ++text) {
    if (std::string_view(" \t\r\n").find(*text) == std::string_view::npos) {
      return false;
    }
  }
  return true;
}

/// Reads one file's XML; collects problems instead of stopping at the first.
class FileParser {
 public:
  explicit FileParser(std::string label) { file_.path = std::move(label); }

  PlanFile parse(std::string_view xml) {
    tinyxml2::XMLDocument document(/*processEntities=*/true, tinyxml2::COLLAPSE_WHITESPACE);
    if (document.Parse(xml.data(), xml.size()) != tinyxml2::XML_SUCCESS) {
      error(document.ErrorLineNum(), std::string("malformed XML: ") + document.ErrorStr());
      throw PlanError(std::move(diagnostics_));
    }
    const tinyxml2::XMLElement* root = document.RootElement();
    if (root == nullptr) {
      error(0, "no XML element found");
    } else if (std::string_view(root->Name()) != "root") {
      error(root->GetLineNum(),
            "the top element must be <root BTCPP_format=\"4\">, found <" + std::string(root->Name()) + ">");
    } else {
      if (root->NextSiblingElement() != nullptr) {
        error(root->NextSiblingElement()->GetLineNum(), "only one top-level <root> element is allowed");
      }
      parseRoot(*root);
    }
    if (!diagnostics_.empty()) {
      throw PlanError(std::move(diagnostics_));
    }
    return std::move(file_);
  }

 private:
  void error(int line, std::string message) { diagnostics_.push_back({{file_.path, line}, std::move(message)}); }

  void parseRoot(const tinyxml2::XMLElement& root) {
    for (const auto* attribute = root.FirstAttribute(); attribute != nullptr; attribute = attribute->Next()) {
      const std::string_view key = attribute->Name();
      if (key == "BTCPP_format") {
        if (std::string_view(attribute->Value()) != "4") {
          error(root.GetLineNum(), "BTCPP_format=\"" + std::string(attribute->Value()) +
                                       "\" is not supported: plans use BehaviorTree.CPP's format 4");
        }
      } else if (key == "main_tree_to_execute") {
        file_.main_tree = attribute->Value();
      }
      // Other attributes (Groot2's project_name, ...) are ignored, as BehaviorTree.CPP does.
    }
    std::set<std::string> tree_ids;
    for (const auto* tree = root.FirstChildElement("BehaviorTree"); tree != nullptr;
         tree = tree->NextSiblingElement("BehaviorTree")) {
      ++tree_count_;
    }
    for (const auto* element = root.FirstChildElement(); element != nullptr; element = element->NextSiblingElement()) {
      const std::string_view name = element->Name();
      if (name == "BehaviorTree") {
        parseBehaviorTree(*element, tree_ids);
      } else if (name == "include") {
        parseInclude(*element);
      } else if (name == "TreeNodesModel") {
        continue;  // derived data: regenerated from the registry when saving
      } else {
        error(element->GetLineNum(), "unexpected element <" + std::string(name) +
                                         "> in <root>: expected <BehaviorTree>, <include> or "
                                         "<TreeNodesModel>");
      }
    }
  }

  void parseInclude(const tinyxml2::XMLElement& element) {
    const char* path = element.Attribute("path");
    if (element.Attribute("ros_pkg") != nullptr) {
      error(element.GetLineNum(), "<include ros_pkg=...> is not supported (there is no ROS here)");
    } else if (path == nullptr || *path == '\0') {
      error(element.GetLineNum(), "<include> needs a path attribute");
    } else {
      file_.includes.push_back({path, {file_.path, element.GetLineNum()}});
    }
  }

  void parseBehaviorTree(const tinyxml2::XMLElement& element, std::set<std::string>& tree_ids) {
    PlanTree tree;
    tree.location = {file_.path, element.GetLineNum()};
    const char* id = element.Attribute("ID");
    if (id == nullptr && tree_count_ > 1) {
      error(element.GetLineNum(), "<BehaviorTree> needs an ID attribute: the file has " + std::to_string(tree_count_) +
                                      " trees (only a file's single tree may leave it out)");
      return;
    } else if (id == nullptr) {
      // A file's single tree may leave the ID out; BehaviorTree.CPP then names it "BehaviorTree_<k>".
      tree.id = "BehaviorTree_" + std::to_string(unnamed_trees_++);
    } else if (*id == '\0') {
      error(element.GetLineNum(), "<BehaviorTree ID=\"\"> has an empty ID: name the tree, or leave ID out");
      return;
    } else {
      tree.id = id;
    }
    for (const auto* attribute = element.FirstAttribute(); attribute != nullptr; attribute = attribute->Next()) {
      const std::string_view key = attribute->Name();
      if (key != "ID" && !key.starts_with("_")) {
        error(element.GetLineNum(),
              "unknown attribute '" + std::string(key) + "' on <BehaviorTree ID=\"" + tree.id + "\">");
      }
    }
    if (!tree_ids.insert(tree.id).second) {
      error(element.GetLineNum(), "BehaviorTree '" + tree.id + "' is defined twice");
    }
    if (!isBlank(element.GetText())) {
      error(element.GetLineNum(), "unexpected text inside <BehaviorTree ID=\"" + tree.id + "\">");
    }
    const auto* first = element.FirstChildElement();
    if (first == nullptr) {
      error(element.GetLineNum(), "BehaviorTree '" + tree.id + "' has no root node");
      return;
    }
    if (first->NextSiblingElement() != nullptr) {
      error(first->NextSiblingElement()->GetLineNum(),
            "BehaviorTree '" + tree.id + "' has more than one root node: wrap them in a Sequence");
    }
    tree.root = parseNode(*first);
    file_.trees.push_back(std::move(tree));
  }

  PlanNode parseNode(const tinyxml2::XMLElement& element) {
    PlanNode node;
    node.location = {file_.path, element.GetLineNum()};
    const std::string_view element_name = element.Name();
    const bool explicit_form = isExplicitKind(element_name);
    if (!explicit_form) {
      node.id = element_name;
    }
    std::set<std::string_view> seen;
    for (const auto* attribute = element.FirstAttribute(); attribute != nullptr; attribute = attribute->Next()) {
      const std::string_view key = attribute->Name();
      if (!seen.insert(key).second) {
        error(element.GetLineNum(), "attribute '" + std::string(key) + "' is written twice");
        continue;
      }
      if (explicit_form && key == "ID") {
        node.id = attribute->Value();
        continue;
      }
      node.attributes.emplace_back(std::string(key), attribute->Value());
    }
    if (explicit_form && node.id.empty()) {
      error(element.GetLineNum(), "<" + std::string(element_name) + "> needs an ID attribute");
      node.id = element_name;
    }
    if (!isBlank(element.GetText())) {
      error(element.GetLineNum(), "unexpected text inside <" + std::string(element_name) + ">");
    }
    for (const auto* child = element.FirstChildElement(); child != nullptr; child = child->NextSiblingElement()) {
      node.children.push_back(parseNode(*child));
    }
    return node;
  }

  PlanFile file_;
  std::vector<Diagnostic> diagnostics_;
  int unnamed_trees_ = 0;
  int tree_count_ = 0;
};

std::optional<std::string> readFile(const std::filesystem::path& path, std::size_t max_bytes,
                                    const SourceLocation& referenced_from, std::vector<Diagnostic>& diagnostics) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    diagnostics.push_back({referenced_from, "cannot open plan file '" + path.string() + "': no such regular file"});
    return std::nullopt;
  }
  const auto size = std::filesystem::file_size(path, ec);
  if (ec || size > max_bytes) {
    diagnostics.push_back(
        {referenced_from, "plan file '" + path.string() + "' is larger than " + std::to_string(max_bytes) + " bytes"});
    return std::nullopt;
  }
  std::ifstream stream(path, std::ios::binary);
  std::ostringstream content;
  content << stream.rdbuf();
  if (!stream) {
    diagnostics.push_back({referenced_from, "cannot read plan file '" + path.string() + "'"});
    return std::nullopt;
  }
  return content.str();
}

/// Follows includes depth-first, each file once; a file already on the stack is a cycle.
/// Iterative (an explicit stack of files), so a chain of any length cannot overflow the call
/// stack. Included files are listed after the files they include.
class IncludeLoader {
 public:
  explicit IncludeLoader(const LoadOptions& options) : options_(options) {}

  void follow(const PlanFile& root, const std::filesystem::path& base_dir) {
    std::vector<Frame> frames;
    frames.push_back({&root, nullptr, base_dir});
    stack_.push_back(root.path);
    while (!frames.empty()) {
      if (frames.back().next == frames.back().file->includes.size()) {
        Frame done = std::move(frames.back());
        frames.pop_back();
        stack_.pop_back();
        if (done.owned) {
          on_stack_.erase(stack_keys_.back());
          stack_keys_.pop_back();
          files_.push_back(std::move(*done.owned));
        }
        continue;
      }
      Frame& frame = frames.back();
      const PlanInclude& include = frame.file->includes[frame.next++];
      const SourceLocation& where = include.location;
      if (!options_.follow_includes) {
        diagnostics_.push_back({where, "includes are not allowed here ('" + include.path + "')"});
        continue;
      }
      const std::filesystem::path target = frame.base_dir / include.path;
      std::error_code ec;
      const std::string key = std::filesystem::weakly_canonical(target, ec).string();
      if (on_stack_.contains(key)) {
        std::string cycle;
        for (const auto& step : stack_) {
          cycle += step + " -> ";
        }
        diagnostics_.push_back({where, "cycle of includes: " + cycle + target.string()});
        continue;
      }
      if (!loaded_.insert(key).second) {
        continue;
      }
      const auto text = readFile(target, options_.max_file_bytes, where, diagnostics_);
      if (!text) {
        continue;
      }
      try {
        auto included = std::make_unique<PlanFile>(parsePlanFile(*text, target.string()));
        stack_keys_.push_back(key);
        on_stack_.insert(key);
        stack_.push_back(included->path);
        const PlanFile* file = included.get();
        frames.push_back({file, std::move(included), target.parent_path()});  // `frame` is invalid now
      } catch (const PlanError& error) {
        diagnostics_.insert(diagnostics_.end(), error.diagnostics().begin(), error.diagnostics().end());
      }
    }
  }

  void markRoot(const std::filesystem::path& path) {
    std::error_code ec;
    const std::string key = std::filesystem::weakly_canonical(path, ec).string();
    stack_keys_.push_back(key);
    on_stack_.insert(key);
    loaded_.insert(key);
  }

  std::vector<PlanFile> files_;
  std::vector<Diagnostic> diagnostics_;

 private:
  struct Frame {
    const PlanFile* file;
    std::unique_ptr<PlanFile> owned;  // null for the root file, which the caller owns
    std::filesystem::path base_dir;
    std::size_t next = 0;  // the next of file->includes to follow
  };

  const LoadOptions& options_;
  std::vector<std::string> stack_;       // paths of the files being followed, for messages
  std::vector<std::string> stack_keys_;  // their canonical paths
  std::set<std::string> on_stack_;       // the same, for lookup
  std::set<std::string> loaded_;
};

Plan finishLoad(PlanFile file, const std::filesystem::path& base_dir, const std::filesystem::path& self,
                const LoadOptions& options) {
  IncludeLoader loader(options);
  if (!self.empty()) {
    loader.markRoot(self);
  }
  loader.follow(file, base_dir);
  if (!loader.diagnostics_.empty()) {
    throw PlanError(std::move(loader.diagnostics_));
  }
  Plan plan;
  plan.file = std::move(file);
  plan.included = std::move(loader.files_);
  return plan;
}

void writeNode(XmlWriter& writer, const PlanNode& node) {
  writer.open(node.id);
  for (const auto& [key, value] : node.attributes) {
    writer.attribute(key, value);
  }
  for (const auto& child : node.children) {
    writeNode(writer, child);
  }
  writer.close();
}

}  // namespace

PlanFile parsePlanFile(std::string_view xml, const std::string& label) { return FileParser(label).parse(xml); }

Plan loadPlan(const std::filesystem::path& path, const LoadOptions& options) {
  std::vector<Diagnostic> diagnostics;
  const auto text = readFile(path, options.max_file_bytes, {path.string(), 0}, diagnostics);
  if (!text) {
    throw PlanError(std::move(diagnostics));
  }
  return finishLoad(parsePlanFile(*text, path.string()), path.parent_path(), path, options);
}

Plan loadPlanText(std::string_view xml, const std::string& label, const LoadOptions& options) {
  return finishLoad(parsePlanFile(xml, label), options.base_dir, {}, options);
}

std::string writePlanFile(const PlanFile& file, const WriteOptions& options) {
  XmlWriter writer;
  writer.open("root");
  writer.attribute("BTCPP_format", "4");
  if (!file.main_tree.empty()) {
    writer.attribute("main_tree_to_execute", file.main_tree);
  }
  for (const auto& include : file.includes) {
    writer.open("include");
    writer.attribute("path", include.path);
    writer.close();
  }
  for (const auto& tree : file.trees) {
    writer.open("BehaviorTree");
    writer.attribute("ID", tree.id);
    writeNode(writer, tree.root);
    writer.close();
  }
  if (options.model_from != nullptr) {
    std::set<std::string> used;
    for (const auto& tree : file.trees) {
      collectNodeIds(tree.root, used);
    }
    writeTreeNodesModel(writer, *options.model_from, used);
  }
  writer.close();
  return writer.str();
}

void savePlanFile(const PlanFile& file, const std::filesystem::path& path, const WriteOptions& options) {
  writeFileAtomically(path, writePlanFile(file, options));
}

}  // namespace costar::bt
