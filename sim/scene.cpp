#include "sim/scene.h"

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <stdexcept>

namespace costar::sim {

std::map<std::string, Region> defaultRegions() {
  return {{"table", {{0.3, -0.4}, {0.7, 0.4}}},
          {"right", {{0.3, -0.4}, {0.7, -0.06}}},
          {"left", {{0.3, 0.06}, {0.7, 0.4}}}};
}

namespace {

Region parseRegion(const nlohmann::json& json) {
  const auto& x = json.at("x");
  const auto& y = json.at("y");
  Region region{{x.at(0).get<double>(), y.at(0).get<double>()}, {x.at(1).get<double>(), y.at(1).get<double>()}};
  if ((region.max - region.min).minCoeff() <= 0) {
    throw std::runtime_error("a region's x and y ranges must be [low, high] with low < high");
  }
  return region;
}

/// "camera_offset": fixed {"xyz", "rpy_deg"} or random {"distance", "angle_deg", "seed"}.
CameraOffset parseCameraOffset(const nlohmann::json& json) {
  if (!json.is_object()) {
    throw std::runtime_error("camera_offset must be an object: {\"xyz\": [x, y, z], \"rpy_deg\": [r, p, y]} or "
                             "{\"distance\": m, \"angle_deg\": deg}");
  }
  const auto vector3 = [&json](const char* key) {
    const auto& v = json.at(key);
    if (!v.is_array() || v.size() != 3) {
      throw std::runtime_error(std::string("camera_offset.") + key + " must be 3 numbers");
    }
    return Eigen::Vector3d(v.at(0).get<double>(), v.at(1).get<double>(), v.at(2).get<double>());
  };
  CameraOffset offset;
  const bool fixed = json.contains("xyz") || json.contains("rpy_deg");
  offset.random = json.contains("distance") || json.contains("angle_deg");
  if (fixed == offset.random) {
    throw std::runtime_error("camera_offset needs either \"xyz\"/\"rpy_deg\" (fixed) or \"distance\"/\"angle_deg\" "
                             "(random direction), not both");
  }
  for (const auto& [key, value] : json.items()) {
    if (key != "xyz" && key != "rpy_deg" && key != "distance" && key != "angle_deg" && key != "seed") {
      throw std::runtime_error("camera_offset: unknown field '" + key + "' (known: xyz, rpy_deg, distance, angle_deg, seed)");
    }
  }
  if (json.contains("xyz")) {
    offset.xyz = vector3("xyz");
  }
  if (json.contains("rpy_deg")) {
    offset.rpy_deg = vector3("rpy_deg");
  }
  offset.distance = json.value("distance", 0.0);
  offset.angle_deg = json.value("angle_deg", 0.0);
  if (json.contains("seed")) {
    offset.seed = json.at("seed").get<std::uint64_t>();
  }
  if (offset.xyz.norm() > 0.5 || offset.distance < 0 || offset.distance > 0.5) {
    throw std::runtime_error("camera_offset: the camera may move at most 0.5 m");
  }
  if (offset.rpy_deg.cwiseAbs().maxCoeff() > 45 || offset.angle_deg < 0 || offset.angle_deg > 45) {
    throw std::runtime_error("camera_offset: the camera may turn at most 45 degrees");
  }
  return offset;
}

}  // namespace

world::Pose cameraOffsetPose(const CameraOffset& offset, std::uint64_t seed) {
  world::Pose pose = world::Pose::Identity();
  if (!offset.random) {
    const Eigen::Vector3d rpy = offset.rpy_deg * M_PI / 180.0;
    pose = world::poseFromXyzRpy(offset.xyz.x(), offset.xyz.y(), offset.xyz.z(), rpy.x(), rpy.y(), rpy.z());
    return pose;
  }
  // Directions uniform on the sphere: normalized Gaussian vectors.
  std::mt19937_64 random(offset.seed.value_or(seed) ^ 0x63616d657261ULL);  // "camera": apart from placement
  std::normal_distribution<double> normal(0.0, 1.0);
  const auto direction = [&] {
    Eigen::Vector3d v;
    do {
      v = Eigen::Vector3d(normal(random), normal(random), normal(random));
    } while (v.norm() < 1e-6);
    return v.normalized();
  };
  pose.translation() = offset.distance * direction();
  pose.linear() = Eigen::AngleAxisd(offset.angle_deg * M_PI / 180.0, direction()).toRotationMatrix();
  return pose;
}

Scene parseScene(const std::string& text, const std::string& label) {
  try {
    const nlohmann::json json = nlohmann::json::parse(text);
    Scene scene;
    scene.label = label;
    scene.description = json.value("description", "");
    scene.seed = json.value("seed", std::uint64_t{0});
    scene.min_gap = json.value("min_gap", 0.02);
    scene.regions = defaultRegions();
    if (json.contains("camera_offset")) {
      scene.camera_offset = parseCameraOffset(json.at("camera_offset"));
    }
    for (const auto& [name, region] : json.value("regions", nlohmann::json::object()).items()) {
      scene.regions[name] = parseRegion(region);
    }
    for (const auto& item : json.at("parts")) {
      PartRequest request;
      request.object_class = item.at("class").get<std::string>();
      request.color = item.value("color", "");
      request.count = item.value("count", 1);
      if (request.count < 1 || request.count > 100) {
        throw std::runtime_error("part count must be between 1 and 100");
      }
      if (item.contains("at")) {
        const auto& at = item.at("at");
        request.at = Eigen::Vector3d(at.at(0).get<double>(), at.at(1).get<double>(),
                                     at.size() > 2 ? at.at(2).get<double>() : 0.0);
        if (request.count != 1) {
          throw std::runtime_error("a part placed with \"at\" must have count 1");
        }
      } else {
        request.region = item.value("region", "table");
      }
      scene.parts.push_back(std::move(request));
    }
    return scene;
  } catch (const std::exception& e) {
    throw std::runtime_error("scene '" + label + "': " + e.what());
  }
}

Scene loadScene(const std::filesystem::path& file) {
  std::ifstream stream(file);
  if (!stream) {
    throw std::runtime_error("cannot open scene file '" + file.string() + "'");
  }
  std::stringstream text;
  text << stream.rdbuf();
  return parseScene(text.str(), file.string());
}

std::vector<PartPlacement> placeParts(const Scene& scene, const std::vector<world::ObjectClass>& classes,
                                      std::optional<std::uint64_t> seed) {
  std::mt19937_64 random(seed.value_or(scene.seed));
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::map<std::string, int> counts;
  std::vector<PartPlacement> placed;
  std::vector<std::pair<Eigen::Vector2d, double>> footprints;  // centre, radius

  const auto findClass = [&](const std::string& name) -> const world::ObjectClass& {
    for (const auto& object : classes) {
      if (object.name == name) {
        return object;
      }
    }
    throw std::runtime_error("scene '" + scene.label + "': unknown object class '" + name + "'");
  };

  for (const PartRequest& request : scene.parts) {
    const world::ObjectClass& object = findClass(request.object_class);
    const Eigen::Vector3d extent = object.bounds().sizes();
    const double radius = 0.5 * std::hypot(extent.x(), extent.y());
    for (int i = 0; i < request.count; ++i) {
      PartPlacement part;
      part.object_class = object.name;
      part.name = object.name + "_" + std::to_string(counts[object.name]++);
      part.color =
          !request.color.empty() ? request.color : object.colors.at(placed.size() % object.colors.size()).first;
      try {
        object.color(part.color);
      } catch (const std::out_of_range& e) {
        throw std::runtime_error("scene '" + scene.label + "': " + e.what());
      }
      Eigen::Vector2d xy;
      double yaw = 0.0;
      if (request.at) {
        xy = request.at->head<2>();
        yaw = request.at->z() * M_PI / 180.0;
      } else {
        const auto region = scene.regions.find(request.region);
        if (region == scene.regions.end()) {
          throw std::runtime_error("scene '" + scene.label + "': unknown region '" + request.region + "'");
        }
        bool fits = false;
        for (int attempt = 0; attempt < 2000 && !fits; ++attempt) {
          xy = region->second.min +
               (region->second.max - region->second.min).cwiseProduct(Eigen::Vector2d(unit(random), unit(random)));
          yaw = 2.0 * M_PI * unit(random);
          fits = true;
          for (const auto& [centre, other_radius] : footprints) {
            if ((centre - xy).norm() < radius + other_radius + scene.min_gap) {
              fits = false;
              break;
            }
          }
        }
        if (!fits) {
          throw std::runtime_error("scene '" + scene.label + "': cannot fit " + part.name + " in region '" +
                                   request.region + "' without touching another part");
        }
      }
      footprints.emplace_back(xy, radius);
      part.pose = world::poseFromXyzRpy(xy.x(), xy.y(), object.rest_height + 0.0005, 0, 0, yaw);
      placed.push_back(std::move(part));
    }
  }
  return placed;
}

}  // namespace costar::sim
