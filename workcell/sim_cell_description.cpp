#include "workcell/sim_cell_description.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <set>
#include <stdexcept>

#include "core/files.h"
#include "core/json_fields.h"
#include "core/json_file.h"
#include "core/paths.h"

namespace costar::workcell {

namespace {

using core::json_fields::fail;
using core::json_fields::join;
using core::json_fields::onlyKnown;
using core::json_fields::shown;
using nlohmann::json;

const json& member(const json& object, const std::string& field, const std::string& key) {
  if (!object.contains(key)) {
    fail(join(field, key), "missing");
  }
  return object.at(key);
}

const json& objectAt(const json& object, const std::string& field, const std::string& key) {
  const json& value = member(object, field, key);
  if (!value.is_object()) {
    fail(join(field, key), "must be an object {...}, not " + shown(value));
  }
  return value;
}

std::string text(const json& object, const std::string& field, const std::string& key) {
  const json& value = member(object, field, key);
  if (!value.is_string() || value.get<std::string>().empty()) {
    fail(join(field, key), "must be a non-empty string, not " + shown(value));
  }
  return value.get<std::string>();
}

/// The largest distance (m) and angle (rad) a cell's numbers may have: a cell is a few metres
/// across; 1e308 is a typing error, and would overflow what is computed from it.
constexpr double kMaxMetres = 10.0;
constexpr double kMaxRadians = 7.0;  // a little over 2 pi

/// 3 finite numbers, each of magnitude at most `limit` (`unit` for the message: "m").
Eigen::Vector3d vec3(const json& object, const std::string& field, const std::string& key, double limit,
                     const char* unit) {
  const json& value = member(object, field, key);
  if (!value.is_array() || value.size() != 3 || !std::all_of(value.begin(), value.end(), [](const json& x) {
        return x.is_number() && std::isfinite(x.get<double>());
      })) {
    fail(join(field, key), "must be 3 finite numbers [x, y, z], not " + shown(value));
  }
  const Eigen::Vector3d v(value[0].get<double>(), value[1].get<double>(), value[2].get<double>());
  if (v.cwiseAbs().maxCoeff() > limit) {
    char range[64];
    std::snprintf(range, sizeof range, "from -%g to %g %s", limit, limit, unit);
    fail(join(field, key), "must be 3 numbers " + std::string(range) + ", not " + shown(value));
  }
  return v;
}

std::filesystem::path file(const json& object, const std::string& key, const std::filesystem::path& root) {
  const std::filesystem::path path = root / text(object, "", key);
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) {
    fail(key, "no such file '" + path.string() + "' (paths are relative to the data root)");
  }
  return path;
}

SimCellDescription parse(const json& root, const std::filesystem::path& data_root) {
  if (!root.is_object()) {
    fail("(top level)", "must be an object {\"name\": ..., \"robot\": ..., ...}, not " + shown(root));
  }
  onlyKnown(root, "",
            {"name", "label", "notes", "robot", "gripper", "robot_base", "cell_model", "scene", "waypoints", "table",
             "workspace", "part_area", "calibration", "perception_model", "power_tool", "remote"});
  SimCellDescription cell;
  cell.name = text(root, "", "name");
  cell.label = text(root, "", "label");
  cell.robot = text(root, "", "robot");
  cell.gripper = text(root, "", "gripper");
  const json& base = objectAt(root, "", "robot_base");
  onlyKnown(base, "robot_base", {"position", "rpy"});
  const Eigen::Vector3d position = vec3(base, "robot_base", "position", kMaxMetres, "m");
  const Eigen::Vector3d rpy = vec3(base, "robot_base", "rpy", kMaxRadians, "rad");
  cell.robot_base = world::poseFromXyzRpy(position.x(), position.y(), position.z(), rpy.x(), rpy.y(), rpy.z());
  cell.cell_model = file(root, "cell_model", data_root);
  cell.scene = file(root, "scene", data_root);
  if (root.contains("waypoints")) {
    cell.waypoints = file(root, "waypoints", data_root);
  }
  cell.calibration = file(root, "calibration", data_root);
  if (root.contains("perception_model")) {
    // Not checked here: `costar perception retrain -w NAME` writes it; DetectObjects names it
    // when it is missing.
    cell.perception_model = data_root / text(root, "", "perception_model");
  }
  if (root.contains("remote")) {
    cell.remote = objectAt(root, "", "remote");
  }
  const json& table = objectAt(root, "", "table");
  onlyKnown(table, "table", {"centre", "size"});
  cell.table_centre = vec3(table, "table", "centre", kMaxMetres, "m");
  cell.table_size = vec3(table, "table", "size", kMaxMetres, "m");
  if ((cell.table_size.array() <= 0.0).any()) {
    fail("table.size", "must be positive (m), not " + shown(table.at("size")));
  }
  const json& workspace = objectAt(root, "", "workspace");
  onlyKnown(workspace, "workspace", {"min", "max"});
  cell.workspace = Eigen::AlignedBox3d(vec3(workspace, "workspace", "min", kMaxMetres, "m"),
                                       vec3(workspace, "workspace", "max", kMaxMetres, "m"));
  if ((cell.workspace.min().array() >= cell.workspace.max().array()).any()) {
    fail("workspace", "min must be below max on every axis");
  }
  if (root.contains("part_area")) {
    const json& area = objectAt(root, "", "part_area");
    onlyKnown(area, "part_area", {"min", "max"});
    cell.part_area = Eigen::AlignedBox3d(vec3(area, "part_area", "min", kMaxMetres, "m"),
                                         vec3(area, "part_area", "max", kMaxMetres, "m"));
    if ((cell.part_area->min().array() >= cell.part_area->max().array()).any()) {
      fail("part_area", "min must be below max on every axis");
    }
  }
  if (root.contains("power_tool")) {
    const json& power_tool = objectAt(root, "", "power_tool");
    onlyKnown(power_tool, "power_tool", {"tool", "stand"});
    SimCellDescription::PowerTool tool;
    tool.tool = text(power_tool, "power_tool", "tool");
    std::error_code error;
    const std::filesystem::path tool_file = data_root / "data" / "tools" / (tool.tool + ".json");
    if (!std::filesystem::is_regular_file(tool_file, error)) {
      fail("power_tool.tool", "no such tool '" + tool_file.string() + "'");
    }
    const json& stand = objectAt(power_tool, "power_tool", "stand");
    onlyKnown(stand, "power_tool.stand", {"position", "rpy"});
    const Eigen::Vector3d at = vec3(stand, "power_tool.stand", "position", kMaxMetres, "m");
    const Eigen::Vector3d turn = vec3(stand, "power_tool.stand", "rpy", kMaxRadians, "rad");
    tool.stand = world::poseFromXyzRpy(at.x(), at.y(), at.z(), turn.x(), turn.y(), turn.z());
    cell.power_tool = tool;
  }
  return cell;
}

}  // namespace

std::filesystem::path simCellFile(const std::string& name, const std::filesystem::path& data_root) {
  const std::filesystem::path file = (data_root.empty() ? dataRoot() : data_root) / "workcells" / (name + ".json");
  std::error_code error;
  if (!std::filesystem::is_regular_file(file, error)) {
    // `costar perception detect -w none` said "cannot read workcell description '.../none.json'".
    std::string known;
    for (const auto& [cell, label] : simCells(data_root)) {
      known += (known.empty() ? "" : ", ") + cell;
    }
    throw std::invalid_argument("'" + name + "' is not a simulated workcell (those are: " + known + ")");
  }
  return file;
}

SimCellDescription loadSimCellDescription(const std::filesystem::path& path, const std::filesystem::path& data_root) {
  const std::string label = "workcell description '" + path.string() + "'";
  const std::string content = readFile(path, "workcell description");
  try {
    json parsed;
    try {
      parsed = core::parseJson(content);
    } catch (const core::JsonSyntaxError& e) {
      throw std::runtime_error(std::string("not valid JSON: ") + e.what());
    }
    SimCellDescription cell = parse(parsed, data_root.empty() ? dataRoot() : data_root);
    cell.file = path;
    if (cell.name != path.stem().string()) {
      fail("name", "'" + cell.name + "' must be the file's name without .json ('" + path.stem().string() + "')");
    }
    return cell;
  } catch (const std::exception& e) {
    throw std::runtime_error(label + ": " + e.what());
  }
}

std::vector<std::pair<std::string, std::string>> simCells(const std::filesystem::path& data_root) {
  std::vector<std::pair<std::string, std::string>> cells;
  const std::filesystem::path folder = (data_root.empty() ? dataRoot() : data_root) / "workcells";
  std::error_code error;
  for (const auto& entry : std::filesystem::directory_iterator(folder, error)) {
    if (entry.path().extension() != ".json") {
      continue;
    }
    std::string label;
    try {
      const json parsed = core::readJsonFile(entry.path());
      label = parsed.value("label", std::string("simulated workcell"));
    } catch (const std::exception& e) {
      label = std::string("(cannot be read: ") + e.what() + ")";
    }
    cells.emplace_back(entry.path().stem().string(), label);
  }
  std::sort(cells.begin(), cells.end());
  return cells;
}

}  // namespace costar::workcell
