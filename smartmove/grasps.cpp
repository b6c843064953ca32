#include "smartmove/grasps.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "core/files.h"
#include "core/json_file.h"

namespace costar::smartmove {

namespace {

using Key = std::tuple<std::string, std::string, std::string>;

/// Reads `file`'s grasps into `into`; `order` (when given) gets their keys in the file's order.
/// A (gripper, class, name) given twice in the file is refused, naming both entries.
void read(const std::filesystem::path& file, std::map<Key, Grasp>& into, std::vector<Key>* order = nullptr) {
  nlohmann::json json;
  try {
    json = core::parseJson(readFile(file, "grasp file"));
  } catch (const core::JsonSyntaxError& e) {
    throw std::runtime_error("grasp file '" + file.string() + "': not valid JSON: " + e.what());
  } catch (const std::exception& e) {
    const std::string message = e.what();
    throw std::runtime_error(message.starts_with("cannot read") ? message
                                                                : "grasp file '" + file.string() + "': " + message);
  }
  std::size_t index = 0;
  try {
    std::map<Key, std::size_t> index_of;
    for (const auto& item : json.at("grasps")) {
      Grasp grasp;
      grasp.gripper = item.contains("gripper") ? item.at("gripper").get<std::string>() : kParallelGripper;
      if (grasp.gripper.empty()) {
        throw std::runtime_error("\"gripper\" must not be empty");
      }
      if (item.contains("mode")) {
        grasp.mode = item.at("mode").get<std::string>();
        if (grasp.mode.empty()) {
          throw std::runtime_error("\"mode\" must not be empty (leave it out for any mode)");
        }
      }
      grasp.object_class = item.at("class").get<std::string>();
      grasp.name = item.at("name").get<std::string>();
      const auto p = item.at("position").get<std::array<double, 3>>();
      const auto rpy = item.at("rpy_degrees").get<std::array<double, 3>>();
      for (const double value : {p[0], p[1], p[2], rpy[0], rpy[1], rpy[2]}) {
        if (!std::isfinite(value) || std::abs(value) > 1000.0) {
          throw std::runtime_error("\"position\" (m) and \"rpy_degrees\" must be numbers of magnitude at most 1000");
        }
      }
      constexpr double kDeg = M_PI / 180.0;
      grasp.tcp_in_object = world::poseFromXyzRpy(p[0], p[1], p[2], rpy[0] * kDeg, rpy[1] * kDeg, rpy[2] * kDeg);
      Key key{grasp.gripper, grasp.object_class, grasp.name};
      if (const auto [previous, added] = index_of.emplace(key, index); !added) {
        throw std::runtime_error("gripper '" + grasp.gripper + "', class '" + grasp.object_class + "', name '" +
                                 grasp.name + "' is given twice, in grasps[" + std::to_string(previous->second) +
                                 "] and here (one grasp per gripper, class and name)");
      }
      if (order != nullptr && into.count(key) == 0) {
        order->push_back(key);
      }
      into[key] = grasp;
      ++index;
    }
  } catch (const std::exception& e) {
    throw std::runtime_error("grasp file '" + file.string() + "': grasps[" + std::to_string(index) + "]: " + e.what());
  }
}

}  // namespace

GraspLibrary::GraspLibrary(const std::filesystem::path& defaults_file, std::filesystem::path taught_file,
                           std::string gripper)
    : taught_file_(std::move(taught_file)), gripper_(std::move(gripper)) {
  read(defaults_file, defaults_, &default_order_);
  if (!taught_file_.empty() && std::filesystem::exists(taught_file_)) {
    read(taught_file_, taught_);
  }
}

std::optional<Grasp> GraspLibrary::find(const std::string& object_class, const std::string& name) const {
  if (const auto it = taught_.find({gripper_, object_class, name}); it != taught_.end()) {
    return it->second;
  }
  if (const auto it = defaults_.find({gripper_, object_class, name}); it != defaults_.end()) {
    return it->second;
  }
  return std::nullopt;
}

std::optional<Grasp> GraspLibrary::defaultFor(const std::string& object_class) const {
  for (const Key& key : default_order_) {  // the class's first in the defaults file
    if (std::get<0>(key) == gripper_ && std::get<1>(key) == object_class) {
      return find(object_class, std::get<2>(key));
    }
  }
  for (const auto& [key, grasp] : taught_) {
    if (std::get<0>(key) == gripper_ && std::get<1>(key) == object_class) {
      return find(object_class, std::get<2>(key));
    }
  }
  return std::nullopt;
}

std::vector<Grasp> GraspLibrary::forClass(const std::string& object_class) const {
  std::map<std::string, Grasp> found;
  for (const auto* source : {&defaults_, &taught_}) {
    for (const auto& [key, grasp] : *source) {
      if (std::get<0>(key) == gripper_ && std::get<1>(key) == object_class) {
        found[std::get<2>(key)] = grasp;
      }
    }
  }
  std::vector<Grasp> grasps;
  for (auto& [name, grasp] : found) {
    grasps.push_back(std::move(grasp));
  }
  return grasps;
}

std::vector<std::string> GraspLibrary::names() const {
  std::vector<std::string> names;
  for (const auto* source : {&defaults_, &taught_}) {
    for (const auto& [key, grasp] : *source) {
      if (std::get<0>(key) == gripper_ && std::find(names.begin(), names.end(), std::get<2>(key)) == names.end()) {
        names.push_back(std::get<2>(key));
      }
    }
  }
  return names;
}

void GraspLibrary::teach(const Grasp& taught) {
  // A name people type and plans quote (grasp="..."); "" is SmartGrasp's "any grasp".
  const bool plain = std::all_of(taught.name.begin(), taught.name.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_' || c == '-';
  });
  if (taught.name.empty() || taught.name.size() > 64 || !plain) {
    throw std::invalid_argument("grasp name '" + taught.name +
                                "': 1 to 64 letters, digits, '_' and '-' (an empty grasp means any grasp in a plan)");
  }
  Grasp grasp = taught;
  if (grasp.gripper.empty()) {
    grasp.gripper = gripper_;
  }
  taught_[{grasp.gripper, grasp.object_class, grasp.name}] = grasp;
  if (taught_file_.empty()) {
    return;
  }
  nlohmann::json json = {{"grasps", nlohmann::json::array()}};
  for (const auto& [key, g] : taught_) {
    const Eigen::Vector3d rpy = world::rpyOf(g.tcp_in_object.linear()) * (180.0 / M_PI);
    const Eigen::Vector3d& p = g.tcp_in_object.translation();
    nlohmann::json item = {{"class", g.object_class},
                           {"name", g.name},
                           {"position", {p.x(), p.y(), p.z()}},
                           {"rpy_degrees", {rpy.x(), rpy.y(), rpy.z()}}};
    if (g.gripper != kParallelGripper) {  // files of the 2-finger gripper stay as they were
      item["gripper"] = g.gripper;
    }
    if (!g.mode.empty()) {
      item["mode"] = g.mode;
    }
    json["grasps"].push_back(item);
  }
  if (taught_file_.has_parent_path()) {
    std::filesystem::create_directories(taught_file_.parent_path());
  }
  writeFileAtomically(taught_file_, json.dump(2) + "\n");
}

world::Pose snapToCanonical(const world::Pose& tcp_in_object, const world::ObjectClass& object_class) {
  // The canonical top grasp: tool z along -object z, fingers closing along -object y.
  const Eigen::Matrix3d canonical = world::poseFromXyzRpy(0, 0, 0, M_PI, 0, 0).linear();
  world::Pose best = tcp_in_object;
  double best_angle = 1e9;
  for (const Eigen::Matrix3d& symmetry : object_class.symmetries) {
    // The object turned by a symmetry looks the same: the grasp relative to it is s^-1 * T.
    world::Pose candidate = world::Pose::Identity();
    candidate.linear() = symmetry.transpose();
    candidate = candidate * tcp_in_object;
    const double angle = Eigen::AngleAxisd(canonical.transpose() * candidate.linear()).angle();
    if (angle < best_angle - 1e-9) {
      best_angle = angle;
      best = candidate;
    }
  }
  return best;
}

}  // namespace costar::smartmove
