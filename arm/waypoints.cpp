#include "arm/waypoints.h"

#include <fstream>
#include <nlohmann/json.hpp>
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

Waypoint fromJson(const nlohmann::json& json) {
  Waypoint waypoint;
  waypoint.name = json.at("name").get<std::string>();
  if (const std::string problem = checkWaypointName(waypoint.name); !problem.empty()) {
    throw std::runtime_error(problem);
  }
  if (json.contains("joints")) {
    waypoint.kind = Waypoint::Kind::kJoints;
    waypoint.joints = json.at("joints").get<JointVector>();
  } else {
    waypoint.kind = Waypoint::Kind::kPose;
    waypoint.frame = json.value("frame", "world");
    const auto p = json.at("position").get<std::array<double, 3>>();
    const auto q = json.at("orientation").get<std::array<double, 4>>();
    waypoint.pose = world::Pose::Identity();
    waypoint.pose.translation() = Eigen::Vector3d(p[0], p[1], p[2]);
    waypoint.pose.linear() = Eigen::Quaterniond(q[0], q[1], q[2], q[3]).normalized().toRotationMatrix();
  }
  return waypoint;
}

}  // namespace

WaypointStore::WaypointStore(std::filesystem::path file, bool persist) : file_(std::move(file)), persist_(persist) {
  if (file_.empty() || !std::filesystem::exists(file_)) {
    return;
  }
  std::ifstream stream(file_);
  try {
    const nlohmann::json json = nlohmann::json::parse(stream);
    for (const auto& item : json.at("waypoints")) {
      Waypoint waypoint = fromJson(item);
      waypoints_[waypoint.name] = std::move(waypoint);
    }
  } catch (const std::exception& e) {
    throw std::runtime_error("waypoint file '" + file_.string() + "': " + e.what());
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
