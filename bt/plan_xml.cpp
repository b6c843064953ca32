#include "bt/plan_xml.h"

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <memory>
#include <pugixml.hpp>
#include <set>
#include <sstream>

#include "bt/nodes_model.h"
#include "bt/registry.h"
#include "bt/xml_writer.h"
#include "core/files.h"
#include "core/text.h"

namespace costar::bt {

namespace {

constexpr std::string_view kExplicitKinds[] = {"Action", "Condition", "Control", "Decorator"};

bool isExplicitKind(std::string_view element) {
  return std::find(std::begin(kExplicitKinds), std::end(kExplicitKinds), element) != std::end(kExplicitKinds);
}

/// Nesting deeper than this is refused with a message (BehaviorTree.CPP's XML parser, tinyxml2
/// 10, refuses more than 500 levels); it keeps the recursive walks over a plan within the stack.
constexpr int kMaxElementDepth = 500;

/// The text an element starts with (its first child, when that is text), as tinyxml2's
/// GetText(); nullptr when it starts with an element or is empty.
const char* leadingText(const pugi::xml_node& element) {
  const pugi::xml_node first = element.first_child();
  return first.type() == pugi::node_pcdata || first.type() == pugi::node_cdata ? first.value() : nullptr;
}

/// The characters XML 1.0 allows (its production Char).
bool isXmlCharacter(std::uint64_t code) {
  return code == 0x9 || code == 0xA || code == 0xD || (code >= 0x20 && code <= 0xD7FF) ||
         (code >= 0xE000 && code <= 0xFFFD) || (code >= 0x10000 && code <= 0x10FFFF);
}

std::string hexBytes(std::string_view bytes) {
  static constexpr char kDigits[] = "0123456789ABCDEF";
  std::string out;
  for (const char c : bytes) {
    const auto value = static_cast<unsigned char>(c);
    out += (out.empty() ? "" : " ") + std::string{kDigits[value >> 4], kDigits[value & 15]};
  }
  return out;
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
    xml_ = xml;
    checkCharacters();
    if (!diagnostics_.empty()) {
      throw PlanError(std::move(diagnostics_));
    }
    pugi::xml_document document;
    // Entities and CDATA as XML has them; attribute values kept as written (no whitespace
    // conversion), as BehaviorTree.CPP reads them.
    const pugi::xml_parse_result result = document.load_buffer(
        xml.data(), xml.size(), pugi::parse_cdata | pugi::parse_escapes | pugi::parse_eol, pugi::encoding_utf8);
    if (result.status == pugi::status_no_document_element) {
      error(0, "no XML element found");
      throw PlanError(std::move(diagnostics_));
    }
    if (result.status == pugi::status_end_element_mismatch) {
      // Name the element left open, at its line (the parser stops at the wrong end tag).
      const auto [name, open_line] = openElementAt(static_cast<std::size_t>(result.offset));
      error(open_line, "malformed XML: <" + name + "> is not closed (mismatched end tag on line " +
                           std::to_string(lineAt(result.offset)) + ")");
      throw PlanError(std::move(diagnostics_));
    }
    if (!result) {
      error(lineAt(result.offset), std::string("malformed XML: ") + result.description());
      throw PlanError(std::move(diagnostics_));
    }
    const pugi::xml_node root = document.document_element();
    if (std::string_view(root.name()) != "root") {
      error(line(root), "the top element must be <root BTCPP_format=\"4\">, found <" + std::string(root.name()) + ">");
    } else {
      if (const pugi::xml_node next = nextElement(root)) {
        error(line(next), "only one top-level <root> element is allowed");
      }
      parseRoot(root);
    }
    if (!diagnostics_.empty()) {
      throw PlanError(std::move(diagnostics_));
    }
    return std::move(file_);
  }

 private:
  void error(int line, std::string message) { diagnostics_.push_back({{file_.path, line}, std::move(message)}); }

  /// 1-based line of a byte offset in the file.
  int lineAt(std::ptrdiff_t offset) {
    if (line_starts_.empty()) {
      line_starts_.push_back(0);
      for (std::size_t i = 0; i < xml_.size(); ++i) {
        if (xml_[i] == '\n') {
          line_starts_.push_back(i + 1);
        }
      }
    }
    const auto at = static_cast<std::size_t>(std::max<std::ptrdiff_t>(offset, 0));
    return static_cast<int>(std::upper_bound(line_starts_.begin(), line_starts_.end(), at) - line_starts_.begin());
  }
  int line(const pugi::xml_node& node) { return lineAt(node.offset_debug()); }
  /// "line L, column C" of a byte offset (columns count bytes from 1).
  std::string position(std::size_t offset) {
    const int at = lineAt(static_cast<std::ptrdiff_t>(offset));
    return "column " + std::to_string(offset - line_starts_[static_cast<std::size_t>(at - 1)] + 1);
  }

  /// A plan is UTF-8 text whose character references name characters XML allows: its names
  /// and parameters end up in JSON (the server's answers, `costar trials --json`), which holds
  /// nothing else, and the XML parser would turn `&#xD800;` into bytes that are not UTF-8.
  /// The first problem of each line (of the first ten), naming line, column and bytes.
  void checkCharacters() {
    constexpr std::size_t kReportedLines = 10;
    std::size_t lines = 0;
    int last_line = 0;
    const auto report = [&](std::size_t offset, const std::string& message) {
      const int at = lineAt(static_cast<std::ptrdiff_t>(offset));
      if (at == last_line) {
        return;
      }
      last_line = at;
      if (lines++ < kReportedLines) {
        error(at, position(offset) + ": " + message);
      } else if (lines == kReportedLines + 1) {
        error(at, "more lines with characters that are not UTF-8 or not allowed in XML follow");
      }
    };
    std::string_view end_of_skipped;  // "-->" inside a comment, "]]>" inside CDATA: no references
    for (std::size_t i = 0; i < xml_.size();) {
      const char first = xml_[i];
      const auto byte = static_cast<unsigned char>(first);
      if (byte < 0x20 && first != '\t' && first != '\n' && first != '\r') {
        // A NUL byte ended the plan where it stood, unseen (a hostile tester's finding).
        char code[5];
        std::snprintf(code, sizeof(code), "0x%02X", static_cast<unsigned>(byte));
        report(i, std::string("a control character (byte ") + code + ") is not allowed in XML");
        ++i;
        continue;
      }
      if (first != '<' && first != '&' && first != '-' && first != ']' && byte < 0x80) {
        ++i;  // most bytes: nothing to look at
        continue;
      }
      const std::string_view rest = xml_.substr(i);
      if (static_cast<unsigned char>(rest[0]) >= 0x80) {
        const std::size_t length = utf8Length(rest);
        if (length == 0) {
          std::size_t bad = 1;
          while (bad < 4 && bad < rest.size() && utf8Length(rest.substr(bad)) == 0) {
            ++bad;
          }
          report(i, "invalid UTF-8 (bytes " + hexBytes(rest.substr(0, bad)) +
                        "): plan files are UTF-8 text (save it as UTF-8)");
        }
        i += std::max<std::size_t>(length, 1);
        continue;
      }
      if (!end_of_skipped.empty()) {
        if (rest.starts_with(end_of_skipped)) {
          i += end_of_skipped.size();
          end_of_skipped = {};
          continue;
        }
      } else if (rest.starts_with("<!--")) {
        end_of_skipped = "-->";
      } else if (rest.starts_with("<![CDATA[")) {
        end_of_skipped = "]]>";
      } else if (rest.starts_with("<!DOCTYPE")) {
        // Its entities would stay unexpanded ("&part;" in a value as written): refused, as
        // BehaviorTree.CPP's files have none.
        report(i, "a <!DOCTYPE> is not allowed in a plan (its entities would not be expanded)");
      } else if (rest.starts_with("&#")) {
        checkReference(i, report);
      }
      ++i;
    }
  }

  /// A character reference (`&#55296;`, `&#xD800;`) at `offset` names a character XML allows.
  template <typename Report>
  void checkReference(std::size_t offset, Report& report) {
    const bool hex = offset + 2 < xml_.size() && xml_[offset + 2] == 'x';
    std::size_t i = offset + (hex ? 3 : 2);
    std::uint64_t code = 0;
    std::size_t digits = 0;
    for (; i < xml_.size(); ++i, ++digits) {
      const char c = xml_[i];
      int value = -1;
      if (c >= '0' && c <= '9') {
        value = c - '0';
      } else if (hex && c >= 'a' && c <= 'f') {
        value = c - 'a' + 10;
      } else if (hex && c >= 'A' && c <= 'F') {
        value = c - 'A' + 10;
      } else {
        break;
      }
      code = std::min<std::uint64_t>(code * (hex ? 16 : 10) + static_cast<std::uint64_t>(value), 0x7FFFFFFF);
    }
    if (digits == 0 || i >= xml_.size() || xml_[i] != ';') {
      return;  // not a reference: the XML parser says what is wrong with it
    }
    if (!isXmlCharacter(code)) {
      const std::string written(xml_.substr(offset, std::min<std::size_t>(i + 1 - offset, 24)));
      report(offset, "the character reference '" + written + "' is not a character XML allows" +
                         (code >= 0xD800 && code <= 0xDFFF ? " (a UTF-16 surrogate, not a character)" : ""));
    }
  }

  /// The innermost element open at `offset` of well-formed text before it, and its line.
  std::pair<std::string, int> openElementAt(std::size_t offset) {
    offset = std::min(xml_.rfind("</", offset), offset);  // the mismatched end tag closes nothing
    std::vector<std::pair<std::string, std::size_t>> open;
    const auto skipPast = [this](std::size_t from, std::string_view end) {
      const std::size_t at = xml_.find(end, from);
      return at == std::string_view::npos ? xml_.size() : at + end.size();
    };
    std::size_t i = 0;
    while ((i = xml_.find('<', i)) != std::string_view::npos && i < offset) {
      const std::string_view rest = xml_.substr(i);
      if (rest.starts_with("<!--")) {
        i = skipPast(i, "-->");
      } else if (rest.starts_with("<![CDATA[")) {
        i = skipPast(i, "]]>");
      } else if (rest.starts_with("<?")) {
        i = skipPast(i, "?>");
      } else if (rest.starts_with("<!")) {
        i = skipPast(i, ">");
      } else if (rest.starts_with("</")) {
        if (!open.empty()) {
          open.pop_back();
        }
        i = skipPast(i, ">");
      } else {
        const std::size_t name_end = xml_.find_first_of(" \t\r\n/>", i + 1);
        const std::size_t start = i;
        char quote = 0;
        for (++i; i < xml_.size() && (quote != 0 || xml_[i] != '>'); ++i) {
          if (quote == 0 && (xml_[i] == '"' || xml_[i] == '\'')) {
            quote = xml_[i];
          } else if (xml_[i] == quote) {
            quote = 0;
          }
        }
        if (i < xml_.size() && xml_[i - 1] != '/') {
          open.emplace_back(std::string(xml_.substr(start + 1, name_end - start - 1)), start);
        }
      }
    }
    if (open.empty()) {
      return {"?", lineAt(static_cast<std::ptrdiff_t>(offset))};
    }
    return {open.back().first, lineAt(static_cast<std::ptrdiff_t>(open.back().second))};
  }

  void parseRoot(const pugi::xml_node& root) {
    for (const pugi::xml_attribute attribute : root.attributes()) {
      const std::string_view key = attribute.name();
      if (key == "BTCPP_format") {
        if (std::string_view(attribute.value()) != "4") {
          error(line(root), "BTCPP_format=\"" + std::string(attribute.value()) +
                                "\" is not supported: plans use BehaviorTree.CPP's format 4");
        }
      } else if (key == "main_tree_to_execute") {
        file_.main_tree = attribute.value();
      }
      // Other attributes (Groot2's project_name, ...) are ignored, as BehaviorTree.CPP does.
    }
    std::set<std::string> tree_ids;
    for (const pugi::xml_node tree : root.children("BehaviorTree")) {
      static_cast<void>(tree);
      ++tree_count_;
    }
    for (const pugi::xml_node element : root.children()) {
      if (element.type() != pugi::node_element) {
        continue;
      }
      const std::string_view name = element.name();
      if (name == "BehaviorTree") {
        parseBehaviorTree(element, tree_ids);
      } else if (name == "include") {
        parseInclude(element);
      } else if (name == "TreeNodesModel") {
        continue;  // derived data: regenerated from the registry when saving
      } else {
        error(line(element), "unexpected element <" + std::string(name) +
                                 "> in <root>: expected <BehaviorTree>, <include> or "
                                 "<TreeNodesModel>");
      }
    }
  }

  void parseInclude(const pugi::xml_node& element) {
    const pugi::xml_attribute path = element.attribute("path");
    if (element.attribute("ros_pkg")) {
      error(line(element), "<include ros_pkg=...> is not supported (there is no ROS here)");
    } else if (!path || *path.value() == '\0') {
      error(line(element), "<include> needs a path attribute");
    } else {
      file_.includes.push_back({path.value(), {file_.path, line(element)}});
    }
  }

  void parseBehaviorTree(const pugi::xml_node& element, std::set<std::string>& tree_ids) {
    PlanTree tree;
    tree.location = {file_.path, line(element)};
    const pugi::xml_attribute id = element.attribute("ID");
    if (!id && tree_count_ > 1) {
      error(line(element), "<BehaviorTree> needs an ID attribute: the file has " + std::to_string(tree_count_) +
                               " trees (only a file's single tree may leave it out)");
      return;
    } else if (!id) {
      // A file's single tree may leave the ID out; BehaviorTree.CPP then names it "BehaviorTree_<k>".
      tree.id = "BehaviorTree_" + std::to_string(unnamed_trees_++);
    } else if (*id.value() == '\0') {
      error(line(element), "<BehaviorTree ID=\"\"> has an empty ID: name the tree, or leave ID out");
      return;
    } else {
      tree.id = id.value();
    }
    for (const pugi::xml_attribute attribute : element.attributes()) {
      const std::string_view key = attribute.name();
      if (key != "ID" && !key.starts_with("_")) {
        error(line(element), "unknown attribute '" + std::string(key) + "' on <BehaviorTree ID=\"" + tree.id + "\">");
      }
    }
    if (!tree_ids.insert(tree.id).second) {
      error(line(element), "BehaviorTree '" + tree.id + "' is defined twice");
    }
    if (!isBlank(leadingText(element))) {
      error(line(element), "unexpected text inside <BehaviorTree ID=\"" + tree.id + "\">");
    }
    const pugi::xml_node first =
        element.first_child().type() == pugi::node_element ? element.first_child() : nextElement(element.first_child());
    if (!first) {
      error(line(element), "BehaviorTree '" + tree.id + "' has no root node");
      return;
    }
    if (const pugi::xml_node second = nextElement(first)) {
      error(line(second), "BehaviorTree '" + tree.id + "' has more than one root node: wrap them in a Sequence");
    }
    tree.root = parseNode(first, 1);
    file_.trees.push_back(std::move(tree));
  }

  static pugi::xml_node nextElement(const pugi::xml_node& node) {
    pugi::xml_node next = node.next_sibling();
    while (next && next.type() != pugi::node_element) {
      next = next.next_sibling();
    }
    return next;
  }

  PlanNode parseNode(const pugi::xml_node& element, int depth) {
    PlanNode node;
    node.location = {file_.path, line(element)};
    const std::string_view element_name = element.name();
    const bool explicit_form = isExplicitKind(element_name);
    if (!explicit_form) {
      node.id = element_name;
    }
    std::set<std::string_view> seen;
    for (const pugi::xml_attribute attribute : element.attributes()) {
      const std::string_view key = attribute.name();
      if (!seen.insert(key).second) {
        error(line(element), "attribute '" + std::string(key) + "' is written twice");
        continue;
      }
      if (explicit_form && key == "ID") {
        node.id = attribute.value();
        continue;
      }
      node.attributes.emplace_back(std::string(key), attribute.value());
    }
    if (explicit_form && node.id.empty()) {
      error(line(element), "<" + std::string(element_name) + "> needs an ID attribute");
      node.id = element_name;
    }
    if (!isBlank(leadingText(element))) {
      error(line(element), "unexpected text inside <" + std::string(element_name) + ">");
    }
    for (pugi::xml_node child = element.first_child(); child; child = child.next_sibling()) {
      if (child.type() != pugi::node_element) {
        continue;
      }
      if (depth + 3 > kMaxElementDepth) {  // <root>, <BehaviorTree> and this node's level
        error(line(child),
              "nesting is too deep: more than " + std::to_string(kMaxElementDepth) + " levels of elements");
        break;
      }
      node.children.push_back(parseNode(child, depth + 1));
    }
    return node;
  }

  std::string_view xml_;
  std::vector<std::size_t> line_starts_;
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
