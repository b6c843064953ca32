#include "tool/power_tool_description.h"

#include <cmath>
#include <cstdio>
#include <set>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "core/files.h"
#include "core/json_file.h"
#include "core/paths.h"

namespace costar::tool {

namespace {

class Fields {
 public:
  explicit Fields(std::string label) : label_(std::move(label)) {}
  [[noreturn]] void fail(const std::string& field, const std::string& problem) const {
    throw std::runtime_error(label_ + ": " + field + ": " + problem);
  }
  const nlohmann::json& object(const nlohmann::json& parent, const std::string& key, const std::string& field,
                               const std::set<std::string>& keys) const {
    const nlohmann::json& value = at(parent, key, field);
    if (!value.is_object()) {
      fail(field, "must be an object");
    }
    for (const auto& [name, item] : value.items()) {
      if (!keys.contains(name)) {
        fail(field + "." + name, "is not a field of the format");
      }
    }
    return value;
  }
  const nlohmann::json& at(const nlohmann::json& object, const std::string& key, const std::string& field) const {
    if (!object.is_object() || !object.contains(key)) {
      fail(field, "missing");
    }
    return object.at(key);
  }
  double number(const nlohmann::json& object, const std::string& key, const std::string& field, double min,
                double max) const {
    const nlohmann::json& value = at(object, key, field);
    if (!value.is_number() || !std::isfinite(value.get<double>()) || value.get<double>() < min ||
        value.get<double>() > max) {
      char problem[128];
      std::snprintf(problem, sizeof problem, "must be a number from %g to %g", min, max);
      fail(field, problem);
    }
    return value.get<double>();
  }
  Eigen::Vector3d size(const nlohmann::json& object, const std::string& key, const std::string& field) const {
    const nlohmann::json& value = at(object, key, field);
    if (!value.is_array() || value.size() != 3) {
      fail(field, "must be 3 sizes (m)");
    }
    Eigen::Vector3d result;
    for (int i = 0; i < 3; ++i) {
      if (!value[i].is_number() || !(value[i].get<double>() > 0.0) || value[i].get<double>() > 0.5) {
        fail(field, "must be 3 sizes above 0 and at most 0.5 m");
      }
      result[i] = value[i].get<double>();
    }
    return result;
  }
  std::string text(const nlohmann::json& object, const std::string& key, const std::string& field) const {
    const nlohmann::json& value = at(object, key, field);
    if (!value.is_string()) {
      fail(field, "must be a string");
    }
    return value.get<std::string>();
  }

 private:
  std::string label_;
};

constexpr double kMaxSize = 0.5;   // m
constexpr double kMaxMass = 20.0;  // kg

}  // namespace

std::filesystem::path powerToolFile(const std::string& name, const std::filesystem::path& data_root) {
  const std::filesystem::path root = data_root.empty() ? dataRoot() : data_root;
  return root / "data" / "tools" / (name + ".json");
}

Eigen::Vector3d PowerToolDescription::handleCentre() const {
  return {0.0, 0.0, pad_size.z() + body_height + handle_size.z() / 2};
}

world::ObjectClass PowerToolDescription::objectClass() const {
  world::ObjectClass object;
  object.name = name;
  object.description = label;
  object.mass = mass();
  object.boxes.push_back({Eigen::Vector3d(0, 0, pad_size.z() / 2), pad_size / 2});
  object.boxes.push_back({Eigen::Vector3d(0, 0, pad_size.z() + body_height / 2),
                          Eigen::Vector3d(body_radius, body_radius, body_height / 2)});
  object.boxes.push_back({handleCentre(), handle_size / 2});
  object.rest_height = 0.0;
  object.colors = {{"orange", Eigen::Vector3d(0.9, 0.45, 0.1)}};
  object.symmetries = world::symmetryGroup({Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix()});
  object.axis_priority = "zxy";
  return object;
}

PowerToolDescription loadPowerToolDescription(const std::filesystem::path& file) {
  const Fields fields("power tool '" + file.string() + "'");
  nlohmann::json root;
  try {
    root = core::parseJson(readFile(file, "power tool"));
  } catch (const core::JsonSyntaxError& e) {
    fields.fail("(syntax)", e.what());
  } catch (const std::runtime_error& e) {
    throw std::runtime_error("power tool '" + file.string() + "': " + e.what());
  }
  const std::set<std::string> top = {"format", "name",   "label", "description",    "frame", "pad",
                                     "body",   "handle", "speed", "orbit_diameter", "stand"};
  if (!root.is_object()) {
    fields.fail("(top level)", "must be an object");
  }
  for (const auto& [key, value] : root.items()) {
    if (!top.contains(key)) {
      fields.fail(key, "is not a field of the format");
    }
  }
  if (root.value("format", "") != "costar-power-tool/1") {
    fields.fail("format", "must be \"costar-power-tool/1\"");
  }
  PowerToolDescription tool;
  tool.file = file;
  tool.name = fields.text(root, "name", "name");
  if (tool.name.empty() || tool.name.find_first_of(" ;?()") != std::string::npos) {
    fields.fail("name", "must be a name without spaces, ';', '?' or brackets");
  }
  tool.label = fields.text(root, "label", "label");
  tool.description = root.contains("description") ? fields.text(root, "description", "description") : "";
  const nlohmann::json& pad = fields.object(root, "pad", "pad", {"size", "mass", "friction"});
  tool.pad_size = fields.size(pad, "size", "pad.size");
  tool.pad_mass = fields.number(pad, "mass", "pad.mass", 0.001, kMaxMass);
  tool.pad_friction = fields.number(pad, "friction", "pad.friction", 0.01, 2.0);
  const nlohmann::json& body = fields.object(root, "body", "body", {"radius", "height", "mass"});
  tool.body_radius = fields.number(body, "radius", "body.radius", 0.005, kMaxSize);
  tool.body_height = fields.number(body, "height", "body.height", 0.005, kMaxSize);
  tool.body_mass = fields.number(body, "mass", "body.mass", 0.001, kMaxMass);
  const nlohmann::json& handle = fields.object(root, "handle", "handle", {"size", "mass"});
  tool.handle_size = fields.size(handle, "size", "handle.size");
  tool.handle_mass = fields.number(handle, "mass", "handle.mass", 0.001, kMaxMass);
  const nlohmann::json& speed =
      fields.object(root, "speed", "speed", {"min", "max", "default", "unit", "time_constant_s"});
  tool.min_speed = fields.number(speed, "min", "speed.min", 1.0, 1e6);
  tool.max_speed = fields.number(speed, "max", "speed.max", 1.0, 1e6);
  tool.default_speed = fields.number(speed, "default", "speed.default", 1.0, 1e6);
  if (!(tool.min_speed <= tool.default_speed && tool.default_speed <= tool.max_speed)) {
    fields.fail("speed", "needs min <= default <= max");
  }
  tool.speed_unit = fields.text(speed, "unit", "speed.unit");
  tool.time_constant = fields.number(speed, "time_constant_s", "speed.time_constant_s", 0.01, 10.0);
  tool.orbit_diameter = fields.number(root, "orbit_diameter", "orbit_diameter", 0.0, 0.02);
  const nlohmann::json& stand = fields.object(root, "stand", "stand", {"size", "rim_height"});
  tool.stand_size = fields.size(stand, "size", "stand.size");
  tool.stand_rim_height = fields.number(stand, "rim_height", "stand.rim_height", 0.0, 0.1);
  if (tool.stand_size.x() <= tool.pad_size.x() || tool.stand_size.y() <= tool.pad_size.y()) {
    fields.fail("stand.size", "must be wider than the pad, which rests on it");
  }
  if (tool.mass() > kMaxMass) {
    fields.fail("(masses)", "the tool weighs more than 20 kg");
  }
  return tool;
}

}  // namespace costar::tool
