#include "sim/scene.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
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

Region tableTop() { return {{-0.3, -0.6}, {1.1, 0.6}}; }

namespace {

using nlohmann::json;

/// A problem with one field of a scene file: "parts[2].count: must be ...".
[[noreturn]] void fail(const std::string& field, const std::string& problem) {
  throw std::runtime_error(field + ": " + problem);
}

/// The value as the file has it, shortened: for "must be ..., not VALUE".
std::string shown(const json& value) {
  std::string text = value.dump();
  return text.size() <= 40 ? text : text.substr(0, 37) + "...";
}

void onlyKnownFields(const json& object, const std::string& field, std::initializer_list<const char*> known) {
  for (const auto& item : object.items()) {
    const std::string& key = item.key();  // not a structured binding: clang 14 cannot capture one
    if (std::none_of(known.begin(), known.end(), [&key](const char* name) { return key == name; })) {
      std::string list;
      for (const char* name : known) {
        list += (list.empty() ? "" : ", ") + std::string(name);
      }
      fail(field.empty() ? key : field + "." + key, "unknown field (known: " + list + ")");
    }
  }
}

const json& object(const json& value, const std::string& field) {
  if (!value.is_object()) {
    fail(field, "must be an object {...}, not " + shown(value));
  }
  return value;
}

std::string stringField(const json& value, const std::string& field) {
  if (!value.is_string()) {
    fail(field, "must be a string, not " + shown(value));
  }
  return value.get<std::string>();
}

double number(const json& value, const std::string& field) {
  // JSON has no nan; a number too large for a double is read as infinity.
  if (!value.is_number() || !std::isfinite(value.get<double>())) {
    fail(field, "must be a finite number, not " + shown(value));
  }
  return value.get<double>();
}

/// A whole number in [low, high]; 4294967297 or 2.5 is an error, never truncated.
std::uint64_t whole(const json& value, const std::string& field, std::uint64_t low, std::uint64_t high) {
  const std::string range = "a whole number from " + std::to_string(low) + " to " + std::to_string(high);
  if (!value.is_number_unsigned() || value.get<std::uint64_t>() < low || value.get<std::uint64_t>() > high) {
    fail(field, "must be " + range + ", not " + shown(value));
  }
  return value.get<std::uint64_t>();
}

std::vector<double> numbers(const json& value, const std::string& field, std::size_t min_size, std::size_t max_size,
                            const std::string& what) {
  if (!value.is_array() || value.size() < min_size || value.size() > max_size) {
    fail(field, "must be " + what + ", not " + shown(value));
  }
  std::vector<double> out;
  for (std::size_t i = 0; i < value.size(); ++i) {
    out.push_back(number(value[i], field + "[" + std::to_string(i) + "]"));
  }
  return out;
}

bool inside(const Region& outer, const Eigen::Vector2d& point) {
  return (point.array() >= outer.min.array()).all() && (point.array() <= outer.max.array()).all();
}

std::string format(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

std::string describeTable() {
  const Region table = tableTop();
  std::ostringstream out;
  out << "x from " << table.min.x() << " to " << table.max.x() << " m, y from " << table.min.y() << " to "
      << table.max.y() << " m";
  return out.str();
}

Region parseRegion(const json& value, const std::string& field) {
  onlyKnownFields(object(value, field), field, {"x", "y"});
  Region region;
  for (int axis = 0; axis < 2; ++axis) {
    const std::string key = axis == 0 ? "x" : "y";
    if (!value.contains(key)) {
      fail(field + "." + key, "missing (a region has \"x\": [low, high] and \"y\": [low, high], in m)");
    }
    const auto range = numbers(value.at(key), field + "." + key, 2, 2, "[low, high] in m");
    if (range[0] >= range[1]) {
      fail(field + "." + key, "must be [low, high] with low < high, not " + shown(value.at(key)));
    }
    region.min[axis] = range[0];
    region.max[axis] = range[1];
  }
  if (!inside(tableTop(), region.min) || !inside(tableTop(), region.max)) {
    fail(field, "lies off the table top (" + describeTable() + ")");
  }
  return region;
}

std::string knownRegions(const std::map<std::string, Region>& regions) {
  std::string list;
  for (const auto& [name, region] : regions) {
    list += (list.empty() ? "" : ", ") + name;
  }
  return list;
}

PartRequest parsePart(const json& item, const std::string& field, const std::map<std::string, Region>& regions) {
  onlyKnownFields(object(item, field), field, {"class", "color", "count", "at", "region"});
  PartRequest request;
  if (!item.contains("class")) {
    fail(field + ".class", "missing (the object class, e.g. \"node\")");
  }
  request.object_class = stringField(item.at("class"), field + ".class");
  if (item.contains("color")) {
    request.color = stringField(item.at("color"), field + ".color");
  }
  if (item.contains("count")) {
    request.count = static_cast<int>(whole(item.at("count"), field + ".count", 1, 100));
  }
  if (item.contains("at")) {
    if (item.contains("region")) {
      fail(field, "has both \"at\" (a fixed place) and \"region\" (a random place); give one");
    }
    if (request.count != 1) {
      fail(field + ".count", "a part placed with \"at\" must have count 1");
    }
    const auto at = numbers(item.at("at"), field + ".at", 2, 3, "[x, y] or [x, y, yaw] (m, m, degrees)");
    request.at = Eigen::Vector3d(at[0], at[1], at.size() > 2 ? at[2] : 0.0);
    if (!inside(tableTop(), request.at->head<2>())) {
      fail(field + ".at", "lies off the table top (" + describeTable() + ")");
    }
  } else {
    request.region = item.contains("region") ? stringField(item.at("region"), field + ".region") : "table";
    if (!regions.contains(request.region)) {
      fail(field + ".region", "unknown region '" + request.region + "' (known: " + knownRegions(regions) + ")");
    }
  }
  return request;
}

}  // namespace

Scene parseScene(const std::string& text, const std::string& label) {
  try {
    const json file = json::parse(text);
    onlyKnownFields(object(file, "the file"), "", {"description", "seed", "min_gap", "regions", "parts"});
    Scene scene;
    scene.label = label;
    if (file.contains("description")) {
      scene.description = stringField(file.at("description"), "description");
    }
    if (file.contains("seed")) {
      scene.seed = whole(file.at("seed"), "seed", 0, std::numeric_limits<std::uint64_t>::max());
    }
    if (file.contains("min_gap")) {
      scene.min_gap = number(file.at("min_gap"), "min_gap");
      if (scene.min_gap < 0.0 || scene.min_gap > 0.5) {
        fail("min_gap", "must be from 0 to 0.5 (m), not " + shown(file.at("min_gap")));
      }
    }
    scene.regions = defaultRegions();
    if (file.contains("regions")) {
      // A named object: file.at() returns a reference into `file`, which outlives the loop.
      // (Iterating items() of a temporary, such as value("regions", {}), reads freed memory.)
      const json& regions = object(file.at("regions"), "regions");
      for (const auto& [name, region] : regions.items()) {
        if (name.empty()) {
          fail("regions", "a region needs a name");
        }
        scene.regions[name] = parseRegion(region, "regions." + name);
      }
    }
    if (!file.contains("parts")) {
      fail("parts", "missing (a list of parts: [{\"class\": \"node\", ...}, ...])");
    }
    const json& parts = file.at("parts");
    if (!parts.is_array()) {
      fail("parts", "must be a list [...], not " + shown(parts));
    }
    for (std::size_t i = 0; i < parts.size(); ++i) {
      scene.parts.push_back(parsePart(parts[i], "parts[" + std::to_string(i) + "]", scene.regions));
    }
    return scene;
  } catch (const std::exception& e) {
    throw std::runtime_error("scene '" + label + "': " + e.what());
  }
}

Scene loadScene(const std::filesystem::path& file) {
  std::error_code error;
  if (std::filesystem::is_directory(file, error)) {
    throw std::runtime_error("cannot read scene file '" + file.string() + "': it is a folder");
  }
  std::ifstream stream(file);
  if (!stream) {
    throw std::runtime_error("cannot read scene file '" + file.string() + "': " + std::strerror(errno));
  }
  std::stringstream text;
  text << stream.rdbuf();
  if (stream.bad()) {
    throw std::runtime_error("cannot read scene file '" + file.string() + "': " + std::strerror(errno));
  }
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

  const auto findClass = [&](const std::string& name, const std::string& field) -> const world::ObjectClass& {
    std::string known;
    for (const auto& object : classes) {
      if (object.name == name) {
        return object;
      }
      known += (known.empty() ? "" : ", ") + object.name;
    }
    throw std::runtime_error("scene '" + scene.label + "': " + field + ".class: unknown object class '" + name +
                             "' (known: " + known + ")");
  };

  for (std::size_t r = 0; r < scene.parts.size(); ++r) {
    const PartRequest& request = scene.parts[r];
    const std::string field = "parts[" + std::to_string(r) + "]";
    const world::ObjectClass& object = findClass(request.object_class, field);
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
        throw std::runtime_error("scene '" + scene.label + "': " + field + ".color: " + e.what());
      }
      Eigen::Vector2d xy;
      double yaw = 0.0;
      if (request.at) {
        xy = request.at->head<2>();
        yaw = request.at->z() * M_PI / 180.0;
      } else {
        const auto region = scene.regions.find(request.region);
        if (region == scene.regions.end()) {
          throw std::runtime_error("scene '" + scene.label + "': " + field + ".region: unknown region '" +
                                   request.region + "' (known: " + knownRegions(scene.regions) + ")");
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
          throw std::runtime_error("scene '" + scene.label + "': " + field + ": cannot fit " + part.name +
                                   " in region '" + request.region + "' " + format(scene.min_gap) +
                                   " m or more from every other part (fewer parts, a larger region or a smaller "
                                   "min_gap)");
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
