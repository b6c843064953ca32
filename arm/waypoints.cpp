#include "arm/waypoints.h"

#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>

#include "core/files.h"

namespace costar::arm {

std::string checkWaypointName(const std::string& name) {
  if (name.empty() || name.size() > 64) {
    return "a waypoint name has 1 to 64 characters";
  }
  for (const char c : name) {
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_' && c != '-') {
      return "waypoint name '" + name + "' may contain only letters, digits, '_' and '-'";
    }
  }
  return {};
}

namespace {

nlohmann::json toJson(const Waypoint& waypoint) {
  nlohmann::json json = {{"name", waypoint.name}};
  if (waypoint.kind == Waypoint::Kind::kJoints) {
    json["joints"] = waypoint.joints;
  } else {
    const Eigen::Quaterniond q(waypoint.pose.linear());
    const Eigen::Vector3d& p = waypoint.pose.translation();
    json["frame"] = waypoint.frame;
    json["position"] = {p.x(), p.y(), p.z()};
    json["orientation"] = {q.w(), q.x(), q.y(), q.z()};
  }
  return json;
}

using nlohmann::json;

/// A problem with one field of the file: "waypoints[2].orientation: ...".
[[noreturn]] void fail(const std::string& field, const std::string& problem) {
  throw std::runtime_error(field + ": " + problem);
}

std::string shown(const json& value) {
  std::string text = value.dump();
  return text.size() <= 60 ? text : text.substr(0, 57) + "...";
}

std::vector<double> numbers(const json& value, const std::string& field, std::size_t size, const std::string& what) {
  if (!value.is_array() || value.size() != size) {
    fail(field, "must be " + what + ", not " + shown(value));
  }
  std::vector<double> out;
  for (std::size_t i = 0; i < size; ++i) {
    if (!value[i].is_number() || !std::isfinite(value[i].get<double>())) {
      fail(field + "[" + std::to_string(i) + "]", "must be a finite number, not " + shown(value[i]));
    }
    out.push_back(value[i].get<double>());
  }
  return out;
}

std::string stringField(const json& value, const std::string& field) {
  if (!value.is_string()) {
    fail(field, "must be a string, not " + shown(value));
  }
  return value.get<std::string>();
}

Waypoint fromJson(const json& item, const std::string& field) {
  if (!item.is_object()) {
    fail(field, "must be an object {\"name\": ..., ...}, not " + shown(item));
  }
  for (const auto& [key, value] : item.items()) {
    if (key != "name" && key != "joints" && key != "frame" && key != "position" && key != "orientation") {
      fail(field + "." + key, "unknown field (known: name, joints, frame, position, orientation)");
    }
  }
  Waypoint waypoint;
  if (!item.contains("name")) {
    fail(field + ".name", "missing");
  }
  waypoint.name = stringField(item.at("name"), field + ".name");
  if (const std::string problem = checkWaypointName(waypoint.name); !problem.empty()) {
    fail(field + ".name", problem);
  }
  if (item.contains("joints")) {
    for (const char* key : {"frame", "position", "orientation"}) {
      if (item.contains(key)) {
        fail(field,
             "has both \"joints\" (a joint configuration) and \"" + std::string(key) + "\" (of a pose); give one");
      }
    }
    waypoint.kind = Waypoint::Kind::kJoints;
    const auto joints =
        numbers(item.at("joints"), field + ".joints", kJointCount, std::to_string(kJointCount) + " angles (radians)");
    std::copy(joints.begin(), joints.end(), waypoint.joints.begin());
    return waypoint;
  }
  waypoint.kind = Waypoint::Kind::kPose;
  for (const char* key : {"position", "orientation"}) {
    if (!item.contains(key)) {
      fail(field + "." + key,
           "missing (a waypoint has \"joints\", or \"position\" [x, y, z] and \"orientation\" [w, x, y, z])");
    }
  }
  if (item.contains("frame")) {
    waypoint.frame = stringField(item.at("frame"), field + ".frame");
    if (waypoint.frame.empty()) {
      fail(field + ".frame", "must name a frame (\"world\", or a frame symbol such as \"table_center\")");
    }
  }
  const auto p = numbers(item.at("position"), field + ".position", 3, "[x, y, z] (m)");
  const auto q = numbers(item.at("orientation"), field + ".orientation", 4, "a unit quaternion [w, x, y, z]");
  const Eigen::Quaterniond rotation(q[0], q[1], q[2], q[3]);
  // A zero quaternion is no rotation at all (normalizing it gives nan); one far from unit
  // length is a typing error more likely than a rotation.
  if (std::abs(rotation.norm() - 1.0) > 0.01) {
    std::ostringstream norm;
    norm << rotation.norm();
    fail(field + ".orientation", "must be a unit quaternion [w, x, y, z], not " + shown(item.at("orientation")) +
                                     " (length " + norm.str() + ")");
  }
  waypoint.pose = world::Pose::Identity();
  waypoint.pose.translation() = Eigen::Vector3d(p[0], p[1], p[2]);
  waypoint.pose.linear() = rotation.normalized().toRotationMatrix();
  return waypoint;
}

}  // namespace

WaypointStore::WaypointStore(std::filesystem::path file, bool persist) : file_(std::move(file)), persist_(persist) {
  if (file_.empty()) {
    return;
  }
  const std::string label = "waypoint file '" + file_.string() + "'";
  std::error_code error;
  const bool exists = std::filesystem::exists(file_, error);
  if (error) {  // e.g. a loop of symbolic links, or a folder on the way that is a file
    throw std::runtime_error("cannot read " + label + ": " + error.message());
  }
  if (!exists) {
    return;
  }
  if (std::filesystem::is_directory(file_, error)) {
    throw std::runtime_error("cannot read " + label + ": it is a folder");
  }
  std::ifstream stream(file_);
  if (!stream) {
    throw std::runtime_error("cannot read " + label + ": " + std::strerror(errno));
  }
  std::stringstream text;
  text << stream.rdbuf();
  if (stream.bad()) {
    throw std::runtime_error("cannot read " + label + ": " + std::strerror(errno));
  }
  try {
    const json document = json::parse(text.str());
    if (!document.is_object() || !document.contains("waypoints") || !document.at("waypoints").is_array()) {
      fail("waypoints", "missing: the file is {\"waypoints\": [...]}");
    }
    for (const auto& [key, value] : document.items()) {
      if (key != "waypoints") {
        fail(key, "unknown field (known: waypoints)");
      }
    }
    const json& list = document.at("waypoints");
    std::map<std::string, std::size_t> index_of;
    for (std::size_t i = 0; i < list.size(); ++i) {
      const std::string field = "waypoints[" + std::to_string(i) + "]";
      Waypoint waypoint = fromJson(list[i], field);
      if (const auto [previous, added] = index_of.emplace(waypoint.name, i); !added) {
        fail(field + ".name", "'" + waypoint.name + "' is taken already (by waypoints[" +
                                  std::to_string(previous->second) + "]); names must differ");
      }
      waypoints_[waypoint.name] = std::move(waypoint);
    }
  } catch (const std::exception& e) {
    throw std::runtime_error(label + ": " + e.what());
  }
}

std::optional<Waypoint> WaypointStore::find(const std::string& name) const {
  const auto it = waypoints_.find(name);
  return it == waypoints_.end() ? std::nullopt : std::optional<Waypoint>(it->second);
}

std::vector<Waypoint> WaypointStore::all() const {
  std::vector<Waypoint> all;
  for (const auto& [name, waypoint] : waypoints_) {
    all.push_back(waypoint);
  }
  return all;
}

void WaypointStore::put(const Waypoint& waypoint) {
  if (const std::string problem = checkWaypointName(waypoint.name); !problem.empty()) {
    throw std::invalid_argument(problem);
  }
  auto previous = waypoints_;
  waypoints_[waypoint.name] = waypoint;
  try {
    save();
  } catch (...) {
    waypoints_ = std::move(previous);
    throw;
  }
}

bool WaypointStore::remove(const std::string& name) {
  const auto it = waypoints_.find(name);
  if (it == waypoints_.end()) {
    return false;
  }
  const Waypoint removed = it->second;
  waypoints_.erase(it);
  try {
    save();
  } catch (...) {
    waypoints_[name] = removed;
    throw;
  }
  return true;
}

void WaypointStore::rename(const std::string& from, const std::string& to) {
  if (const std::string problem = checkWaypointName(to); !problem.empty()) {
    throw std::invalid_argument(problem);
  }
  const auto it = waypoints_.find(from);
  if (it == waypoints_.end()) {
    throw std::invalid_argument("unknown waypoint '" + from + "'");
  }
  if (waypoints_.contains(to)) {
    throw std::invalid_argument("a waypoint named '" + to + "' exists already");
  }
  auto previous = waypoints_;
  Waypoint waypoint = it->second;
  waypoints_.erase(it);
  waypoint.name = to;
  waypoints_[to] = waypoint;
  try {
    save();
  } catch (...) {
    waypoints_ = std::move(previous);
    throw;
  }
}

void WaypointStore::save() const {
  if (file_.empty() || !persist_) {
    return;
  }
  nlohmann::json json = {{"waypoints", nlohmann::json::array()}};
  for (const auto& [name, waypoint] : waypoints_) {
    json["waypoints"].push_back(toJson(waypoint));
  }
  if (file_.has_parent_path()) {
    std::filesystem::create_directories(file_.parent_path());
  }
  writeFileAtomically(file_, json.dump(2) + "\n");
}

}  // namespace costar::arm
