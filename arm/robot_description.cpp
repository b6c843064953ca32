#include "arm/robot_description.h"

#include <cmath>
#include <cstdlib>
#include <map>
#include <nlohmann/json.hpp>
#include <numbers>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "core/files.h"
#include "core/json_fields.h"
#include "core/json_file.h"
#include "core/paths.h"

namespace costar::arm {

namespace {

using core::json_fields::fail;
using core::json_fields::onlyKnown;
using core::json_fields::shown;
using nlohmann::json;

constexpr const char* kGeneratedFormat = "costar-robot-description/1";

const json& member(const json& object, const std::string& field, const std::string& key) {
  if (!object.contains(key)) {
    fail(field.empty() ? key : field + "." + key, "missing");
  }
  return object.at(key);
}

const json& objectAt(const json& object, const std::string& field, const std::string& key) {
  const json& value = member(object, field, key);
  const std::string name = field.empty() ? key : field + "." + key;
  if (!value.is_object()) {
    fail(name, "must be an object {...}, not " + shown(value));
  }
  return value;
}

std::string text(const json& object, const std::string& field, const std::string& key) {
  const json& value = member(object, field, key);
  const std::string name = field.empty() ? key : field + "." + key;
  if (!value.is_string() || value.get<std::string>().empty()) {
    fail(name, "must be a non-empty string, not " + shown(value));
  }
  return value.get<std::string>();
}

double number(const json& value, const std::string& field) {
  if (!value.is_number() || !std::isfinite(value.get<double>())) {
    fail(field, "must be a finite number, not " + shown(value));
  }
  return value.get<double>();
}

std::vector<double> numbers(const json& value, const std::string& field) {
  if (!value.is_array()) {
    fail(field, "must be a list of numbers, not " + shown(value));
  }
  std::vector<double> out;
  for (std::size_t i = 0; i < value.size(); ++i) {
    out.push_back(number(value[i], field + "[" + std::to_string(i) + "]"));
  }
  return out;
}

std::vector<double> numbers(const json& value, const std::string& field, std::size_t size, const std::string& what) {
  if (!value.is_array() || value.size() != size) {
    fail(field, "must be " + what + ", not " + shown(value));
  }
  return numbers(value, field);
}

/// The solver's parameters (kinematics.KEY: lists of lengths in m or angles in rad): finite, and
/// at most 10 in size, as no arm is 10 m long (1e308 would reach the IK as inf).
std::map<std::string, std::vector<double>> solverParameters(const json& kinematics) {
  std::map<std::string, std::vector<double>> parameters;
  for (const auto& [key, value] : kinematics.items()) {
    if (key == "solver") {
      continue;
    }
    const std::string field = "kinematics." + key;
    std::vector<double> values = numbers(value, field);
    for (std::size_t i = 0; i < values.size(); ++i) {
      if (std::abs(values[i]) > 10.0) {
        fail(field + "[" + std::to_string(i) + "]",
             "must be from -10 to 10 (m or rad: no arm is 10 m long), not " + shown(value[i]));
      }
    }
    parameters[key] = std::move(values);
  }
  return parameters;
}

/// A joint object's fields (format costar-robot-description/1; angles in degrees).
const std::set<std::string> kJointFields = {"name",
                                            "label",
                                            "parent",
                                            "child",
                                            "origin",
                                            "rpy",
                                            "axis",
                                            "lower_deg",
                                            "upper_deg",
                                            "velocity_deg_s",
                                            "acceleration_deg_s2",
                                            "effort_nm"};
constexpr double kRadiansPerDegree = std::numbers::pi / 180.0;

/// joints[] (names, labels, limits) and the home of `root_object`, into `robot`.
void readJoints(const json& root_object, RobotDescription& robot) {
  const json& joints = member(root_object, "", "joints");
  if (!joints.is_array() || joints.empty() || joints.size() > static_cast<std::size_t>(kMaxJoints)) {
    fail("joints", "must be a list of 1 to " + std::to_string(kMaxJoints) + " joints, not " + shown(joints));
  }
  const int count = static_cast<int>(joints.size());
  robot.limits = {JointVector(count), JointVector(count), JointVector(count), JointVector(count)};
  std::set<std::string> names;
  const auto value = [](const json& joint, const std::string& field, const char* key) {
    return number(member(joint, field, key), field + "." + key) * kRadiansPerDegree;
  };
  for (int j = 0; j < count; ++j) {
    const std::string field = "joints[" + std::to_string(j) + "]";
    const json& joint = joints[j];
    if (!joint.is_object()) {
      fail(field, "must be an object {\"name\": ..., \"lower_deg\": ..., ...}, not " + shown(joint));
    }
    onlyKnown(joint, field, kJointFields);
    const std::string name = text(joint, field, "name");
    if (!names.insert(name).second) {
      fail(field + ".name", "'" + name + "' is taken already; joint names must differ");
    }
    robot.joint_names.push_back(name);
    robot.joint_labels.push_back(text(joint, field, "label"));
    robot.limits.min_position[j] = value(joint, field, "lower_deg");
    robot.limits.max_position[j] = value(joint, field, "upper_deg");
    robot.limits.max_velocity[j] = value(joint, field, "velocity_deg_s");
    robot.limits.max_acceleration[j] = value(joint, field, "acceleration_deg_s2");
    if (robot.limits.min_position[j] > robot.limits.max_position[j]) {
      fail(field, "lower_deg " + shown(joint.at("lower_deg")) + " is above upper_deg " + shown(joint.at("upper_deg")));
    }
    if (!(robot.limits.max_velocity[j] > 0.0)) {
      fail(field + ".velocity_deg_s", "must be positive, not " + shown(joint.at("velocity_deg_s")));
    }
    if (!(robot.limits.max_acceleration[j] > 0.0)) {
      fail(field + ".acceleration_deg_s2", "must be positive, not " + shown(joint.at("acceleration_deg_s2")));
    }
  }
  const std::vector<double> home = numbers(member(root_object, "", "home_deg"), "home_deg", joints.size(),
                                           std::to_string(count) + " angles (degrees), one per joint");
  robot.home = JointVector(count);
  for (int j = 0; j < count; ++j) {
    robot.home[j] = home[static_cast<std::size_t>(j)] * kRadiansPerDegree;
    if (robot.home[j] < robot.limits.min_position[j] || robot.home[j] > robot.limits.max_position[j]) {
      fail("home_deg[" + std::to_string(j) + "]", "is outside joint " + std::to_string(j + 1) + "'s limits");
    }
  }
}

/// Where the build writes generated models (robots/generate_models.py):
/// $COSTAR_GENERATED_DIR if set, else this build's tree.
std::filesystem::path generatedRoot() {
  if (const char* dir = std::getenv("COSTAR_GENERATED_DIR"); dir != nullptr && *dir != '\0') {
    return dir;
  }
  return COSTAR_GENERATED_DIR;
}

std::filesystem::path generatedModel(const std::string& name, const std::string& extension) {
  const std::filesystem::path path = generatedRoot() / "robots" / name / (name + extension);
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) {
    fail("name", "the model generated from this file, '" + path.string() + "', is missing: build the target costar_" +
                     name + "_models (robots/generate_models.py)");
  }
  return path;
}

/// Format costar-robot-description/1 (robots/README.md), the file robots/generate_models.py
/// makes the models from: the generator's fields plus those only the runtime needs (type,
/// label, kinematics, joints[].label and .acceleration_deg_s2, gripper_links). The fields of
/// the models (links' masses and shapes, joint origins) are the generator's and the solver's
/// business and are checked there; here the keys are checked against the format's.
RobotDescription parseGenerated(const json& root_object) {
  onlyKnown(root_object, "",
            {"format", "name", "model", "type", "label", "notes", "sources", "published_lengths", "rgba", "base_link",
             "links", "joints", "tool", "home_deg", "kinematics", "gripper_links"});
  RobotDescription robot;
  robot.name = text(root_object, "", "name");
  robot.type = text(root_object, "", "type");
  robot.label = text(root_object, "", "label");
  const json& kinematics = objectAt(root_object, "", "kinematics");
  robot.solver = text(kinematics, "kinematics", "solver");
  robot.solver_parameters = solverParameters(kinematics);
  readJoints(root_object, robot);
  robot.first_moving_link = text(root_object.at("joints")[0], "joints[0]", "child");
  robot.base_link = text(root_object, "", "base_link");
  const json& tool = objectAt(root_object, "", "tool");
  robot.urdf_base_link = robot.base_link;
  robot.urdf_tool_link = text(tool, "tool", "name");  // the flange
  const json& gripper = member(root_object, "", "gripper_links");
  if (!gripper.is_array()) {
    fail("gripper_links", "must be a list of link names, not " + shown(gripper));
  }
  for (std::size_t i = 0; i < gripper.size(); ++i) {
    if (!gripper[i].is_string() || gripper[i].get<std::string>().empty()) {
      fail("gripper_links[" + std::to_string(i) + "]", "must be a link name, not " + shown(gripper[i]));
    }
    robot.gripper_links.push_back(gripper[i].get<std::string>());
  }
  robot.mjcf = generatedModel(robot.name, ".xml");
  robot.urdf = generatedModel(robot.name, ".urdf");
  return robot;
}

}  // namespace

std::filesystem::path robotDescriptionFile(const std::string& name, const std::filesystem::path& data_root) {
  const std::filesystem::path root = data_root.empty() ? dataRoot() : data_root;
  return root / "robots" / name / (name + ".json");
}

RobotDescription loadRobotDescription(const std::filesystem::path& file) {
  const std::string label = "robot description '" + file.string() + "'";
  const std::string content = readFile(file, "robot description");
  RobotDescription robot;
  try {
    json parsed;
    try {
      parsed = core::parseJson(content);
    } catch (const core::JsonSyntaxError& e) {
      throw std::runtime_error(std::string("not valid JSON: ") + e.what());
    }
    if (!parsed.is_object()) {
      fail("(top level)",
           "must be an object {\"format\": ..., \"name\": ..., \"joints\": [...], ...}, not " + shown(parsed));
    }
    if (parsed.value("format", json()) != kGeneratedFormat) {
      fail("format", "must be \"" + std::string(kGeneratedFormat) + "\", not " +
                         (parsed.contains("format") ? shown(parsed.at("format")) : std::string("missing")));
    }
    robot = parseGenerated(parsed);
    robot.file = file;
  } catch (const std::exception& e) {
    throw std::runtime_error(label + ": " + e.what());
  }
  // The simulator and the planner use the models generated from this file at build time: the
  // file must be the one they came from.
  checkGeneratedFrom(file, generatedRoot() / "robots" / robot.name / (robot.name + ".fingerprint"));
  return robot;
}

}  // namespace costar::arm
