#include "gripper/gripper_description.h"

#include <algorithm>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "core/files.h"
#include "core/json_file.h"
#include "core/paths.h"
#include "gripper/description_fields.h"

namespace costar::gripper {

namespace {

constexpr const char* kFormat = "costar-gripper-description/1";
constexpr const char* kKinds[] = {"parallel", "adaptive-3f"};

nlohmann::json parse(const std::filesystem::path& file, const detail::Fields& fields) {
  const std::string text = readFile(file, "gripper description");
  nlohmann::json root;
  try {
    root = core::parseJson(text);
  } catch (const core::JsonSyntaxError& e) {
    fields.fail("(syntax)", e.what());
  } catch (const std::runtime_error& e) {  // a key given twice: "FIELD: key 'K' appears twice ..."
    throw std::runtime_error("gripper description '" + file.string() + "': " + e.what());
  }
  if (!root.is_object() || root.value("format", "") != kFormat) {
    fields.fail("format", std::string("must be \"") + kFormat + "\"");
  }
  const auto& kind = fields.at(root, "kind", "");
  if (!kind.is_string() || std::none_of(std::begin(kKinds), std::end(kKinds),
                                        [&kind](const char* k) { return kind.get<std::string>() == k; })) {
    fields.fail("kind", "must be \"parallel\" or \"adaptive-3f\"");
  }
  return root;
}

}  // namespace

std::filesystem::path gripperDescriptionFile(const std::string& name, const std::filesystem::path& data_root) {
  const std::filesystem::path root = data_root.empty() ? dataRoot() : data_root;
  return root / "robots" / "grippers" / (name + ".json");
}

std::vector<std::string> gripperDescriptionNames(const std::filesystem::path& data_root) {
  const std::filesystem::path folder = gripperDescriptionFile("x", data_root).parent_path();
  std::vector<std::string> names;
  std::error_code error;
  for (const auto& entry : std::filesystem::directory_iterator(folder, error)) {
    if (entry.is_regular_file() && entry.path().extension() == ".json") {
      names.push_back(entry.path().stem().string());
    }
  }
  if (error) {
    throw std::runtime_error("cannot list the gripper descriptions in '" + folder.string() + "': " + error.message());
  }
  std::sort(names.begin(), names.end());
  return names;
}

std::string gripperKind(const std::filesystem::path& file) {
  const detail::Fields fields("gripper description '" + file.string() + "'");
  return parse(file, fields).at("kind").get<std::string>();
}

namespace detail {

nlohmann::json readGripperDescription(const std::filesystem::path& file, const Fields& fields,
                                      const std::string& kind) {
  nlohmann::json root = parse(file, fields);
  if (root.at("kind") != kind) {
    fields.fail("kind",
                "is \"" + root.at("kind").get<std::string>() + "\": this reader reads a \"" + kind + "\" gripper");
  }
  const auto& name = fields.at(root, "name", "");
  if (!name.is_string() || name.get<std::string>() != file.stem().string()) {
    fields.fail("name", "must be the file's name (" + file.stem().string() + ")");
  }
  return root;
}

}  // namespace detail

}  // namespace costar::gripper
