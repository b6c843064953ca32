#include "sim/scene.h"

#include <Eigen/Geometry>
#include <algorithm>
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

}  // namespace

Scene parseScene(const std::string& text, const std::string& label) {
  try {
    const nlohmann::json json = nlohmann::json::parse(text);
    Scene scene;
    scene.label = label;
    scene.description = json.value("description", "");
    scene.seed = json.value("seed", std::uint64_t{0});
    scene.min_gap = json.value("min_gap", 0.02);
    scene.regions = defaultRegions();
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

namespace {

/// A part's footprint on the table: the rectangle of its bounding box, turned by its yaw.
struct Footprint {
  Eigen::Vector2d centre;
  Eigen::Vector2d half_size;  // along the part's own x and y
  double yaw = 0.0;

  Eigen::Matrix2d axes() const { return Eigen::Rotation2Dd(yaw).toRotationMatrix(); }
};

/// True when the two rectangles, each grown by `gap` / 2 on every side, overlap (separating
/// axis test over the four edge normals).
bool closerThan(const Footprint& a, const Footprint& b, double gap) {
  const Eigen::Matrix2d axes_a = a.axes();
  const Eigen::Matrix2d axes_b = b.axes();
  const Eigen::Vector2d half_a = a.half_size.array() + 0.5 * gap;
  const Eigen::Vector2d half_b = b.half_size.array() + 0.5 * gap;
  const Eigen::Vector2d between = b.centre - a.centre;
  for (const Eigen::Matrix2d* axes : {&axes_a, &axes_b}) {
    for (int k = 0; k < 2; ++k) {
      const Eigen::Vector2d axis = axes->col(k);
      const double reach_a =
          half_a.x() * std::abs(axis.dot(axes_a.col(0))) + half_a.y() * std::abs(axis.dot(axes_a.col(1)));
      const double reach_b =
          half_b.x() * std::abs(axis.dot(axes_b.col(0))) + half_b.y() * std::abs(axis.dot(axes_b.col(1)));
      if (std::abs(between.dot(axis)) >= reach_a + reach_b) {
        return false;
      }
    }
  }
  return true;
}

}  // namespace

std::vector<PartPlacement> placeParts(const Scene& scene, const std::vector<world::ObjectClass>& classes,
                                      std::optional<std::uint64_t> seed) {
  std::mt19937_64 random(seed.value_or(scene.seed));
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::map<std::string, int> counts;
  std::vector<PartPlacement> placed;
  std::vector<Footprint> footprints;

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
    const Eigen::AlignedBox3d bounds = object.bounds();
    const Eigen::Vector2d half_size = 0.5 * bounds.sizes().head<2>();
    const Eigen::Vector2d offset = bounds.center().head<2>();  // of the box centre from the part's origin
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
          const Footprint candidate{xy + Eigen::Rotation2Dd(yaw) * offset, half_size, yaw};
          fits = std::none_of(footprints.begin(), footprints.end(),
                              [&](const Footprint& other) { return closerThan(candidate, other, scene.min_gap); });
        }
        if (!fits) {
          throw std::runtime_error("scene '" + scene.label + "': cannot fit " + part.name + " in region '" +
                                   request.region + "' without touching another part");
        }
      }
      footprints.push_back({xy + Eigen::Rotation2Dd(yaw) * offset, half_size, yaw});
      part.pose = world::poseFromXyzRpy(xy.x(), xy.y(), object.rest_height + 0.0005, 0, 0, yaw);
      placed.push_back(std::move(part));
    }
  }
  return placed;
}

}  // namespace costar::sim
