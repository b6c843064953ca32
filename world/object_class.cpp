#include "world/object_class.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "core/json_file.h"

namespace costar::world {

Eigen::AlignedBox3d ObjectClass::bounds() const {
  Eigen::AlignedBox3d box;
  for (const Box& b : boxes) {
    box.extend(b.center - b.half_size);
    box.extend(b.center + b.half_size);
  }
  return box;
}

const Eigen::Vector3d& ObjectClass::color(const std::string& wanted) const {
  for (const auto& [color_name, rgb] : colors) {
    if (color_name == wanted) {
      return rgb;
    }
  }
  std::string known;
  for (const auto& [color_name, rgb] : colors) {
    known += (known.empty() ? "" : ", ") + color_name;
  }
  throw std::out_of_range("object class '" + name + "' has no colour '" + wanted + "' (it has: " + known + ")");
}

std::vector<Eigen::Matrix3d> symmetryGroup(const std::vector<Eigen::Matrix3d>& generators) {
  std::vector<Eigen::Matrix3d> group{Eigen::Matrix3d::Identity()};
  const auto contains = [&group](const Eigen::Matrix3d& r) {
    return std::any_of(group.begin(), group.end(), [&r](const Eigen::Matrix3d& g) { return g.isApprox(r, 1e-9); });
  };
  for (std::size_t i = 0; i < group.size(); ++i) {
    for (const Eigen::Matrix3d& generator : generators) {
      const Eigen::Matrix3d product = group[i] * generator;
      if (!contains(product)) {
        group.push_back(product);
        if (group.size() > 1000) {
          throw std::runtime_error("the symmetry generators do not generate a finite group");
        }
      }
    }
  }
  return group;
}

namespace {

Eigen::Vector3d vector3(const nlohmann::json& json, const char* what) {
  if (!json.is_array() || json.size() != 3 || !json[0].is_number() || !json[1].is_number() || !json[2].is_number()) {
    throw std::runtime_error(std::string(what) + " must be an array of 3 numbers");
  }
  return {json[0].get<double>(), json[1].get<double>(), json[2].get<double>()};
}

}  // namespace

ObjectClass loadObjectClass(const std::filesystem::path& file) {
  std::ifstream stream(file);
  if (!stream) {
    throw std::runtime_error("cannot open object class file '" + file.string() + "'");
  }
  try {
    const nlohmann::json json = core::readJsonFile(file);
    ObjectClass object;
    object.name = json.at("name").get<std::string>();
    object.description = json.value("description", "");
    object.mass = json.at("mass").get<double>();
    object.rest_height = json.at("rest_height").get<double>();
    for (const auto& box : json.at("boxes")) {
      Box b{vector3(box.at("center"), "box center"), vector3(box.at("half_size"), "box half_size")};
      if ((b.half_size.array() <= 0).any()) {
        throw std::runtime_error("a box has a half size that is not positive");
      }
      object.boxes.push_back(b);
    }
    if (object.boxes.empty() || object.mass <= 0) {
      throw std::runtime_error("an object class needs at least one box and a positive mass");
    }
    for (const auto& [color_name, rgb] : json.at("colors").items()) {
      object.colors.emplace_back(color_name, vector3(rgb, "colour"));
    }
    std::vector<Eigen::Matrix3d> generators;
    const auto& symmetry = json.at("symmetry");
    for (const auto& generator : symmetry.value("generators", nlohmann::json::array())) {
      const Eigen::Vector3d axis = vector3(generator.at("axis"), "symmetry axis").normalized();
      const double degrees = generator.at("degrees").get<double>();
      generators.push_back(Eigen::AngleAxisd(degrees * M_PI / 180.0, axis).toRotationMatrix());
    }
    object.symmetries = symmetryGroup(generators);
    std::string priority;
    for (const auto& axis : symmetry.value("axis_priority", nlohmann::json::array({"z", "x", "y"}))) {
      priority += axis.get<std::string>();
    }
    std::string sorted = priority;
    std::sort(sorted.begin(), sorted.end());
    if (sorted != "xyz") {
      throw std::runtime_error("axis_priority must name x, y and z once each");
    }
    object.axis_priority = priority;
    return object;
  } catch (const std::exception& e) {
    throw std::runtime_error("object class file '" + file.string() + "': " + e.what());
  }
}

std::vector<ObjectClass> loadObjectClasses(const std::filesystem::path& dir) {
  std::vector<std::filesystem::path> files;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
    if (entry.path().extension() == ".json") {
      files.push_back(entry.path());
    }
  }
  if (ec) {
    throw std::runtime_error("cannot list object classes in '" + dir.string() + "': " + ec.message());
  }
  std::sort(files.begin(), files.end());
  std::vector<ObjectClass> classes;
  for (const auto& file : files) {
    classes.push_back(loadObjectClass(file));
  }
  return classes;
}

}  // namespace costar::world
