#include "sim/scene.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <stdexcept>

#include "core/files.h"
#include "core/json_file.h"
#include "sim/scene_fields.h"
#include "sim/wire_scene.h"

namespace costar::sim {

std::map<std::string, Region> defaultRegions() {
  return {{"table", {{0.3, -0.4}, {0.7, 0.4}}},
          {"right", {{0.3, -0.4}, {0.7, -0.06}}},
          {"left", {{0.3, 0.06}, {0.7, 0.4}}}};
}

Region tableTop() { return {{-0.3, -0.6}, {1.1, 0.6}}; }

namespace {

using fields::fail;
using fields::number;
using fields::numbers;
using fields::object;
using fields::onlyKnownFields;
using fields::shown;
using fields::stringField;
using fields::whole;
using nlohmann::json;

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

WorkpieceRequest parseWorkpiece(const json& value, const std::string& field) {
  onlyKnownFields(object(value, field), field, {"at", "size", "marked"});
  WorkpieceRequest workpiece;
  for (const char* key : {"at", "size", "marked"}) {
    if (!value.contains(key)) {
      fail(field + "." + key,
           "missing (a workpiece has \"at\": [x, y, yaw_deg], \"size\": [sx, sy, sz], \"marked\": [mx, my])");
    }
  }
  const auto at = numbers(value.at("at"), field + ".at", 3, 3, "[x, y, yaw_deg]");
  workpiece.at = {at[0], at[1], at[2]};
  const auto size = numbers(value.at("size"), field + ".size", 3, 3, "[sx, sy, sz] in m");
  workpiece.size = {size[0], size[1], size[2]};
  if ((workpiece.size.array() < 0.02).any() || (workpiece.size.head<2>().array() > 0.6).any() ||
      workpiece.size.z() > 0.2) {
    fail(field + ".size", "must be from 0.02 to 0.6 m across and at most 0.2 m high, not " + shown(value.at("size")));
  }
  const auto marked = numbers(value.at("marked"), field + ".marked", 2, 2, "[mx, my] in m");
  workpiece.marked = {marked[0], marked[1]};
  if ((workpiece.marked.array() <= 0.0).any() || (workpiece.marked.array() > workpiece.size.head<2>().array()).any()) {
    fail(field + ".marked", "must be above 0 and at most the workpiece's top, not " + shown(value.at("marked")));
  }
  const Footprint footprint{workpiece.at.head<2>(), workpiece.size.head<2>() / 2, workpiece.at.z() * M_PI / 180.0};
  for (const double sx : {-1.0, 1.0}) {
    for (const double sy : {-1.0, 1.0}) {
      const Eigen::Vector2d corner =
          footprint.centre + footprint.axes() * Eigen::Vector2d(sx, sy).cwiseProduct(footprint.half_size);
      if (!inside(tableTop(), corner)) {
        fail(field + ".at", "puts the workpiece off the table top (" + describeTable() + ")");
      }
    }
  }
  return workpiece;
}

std::string knownRegions(const std::map<std::string, Region>& regions) {
  std::string list;
  for (const auto& [name, region] : regions) {
    list += (list.empty() ? "" : ", ") + name;
  }
  return list;
}

PartRequest parsePart(const json& item, const std::string& field, const std::map<std::string, Region>& regions) {
  onlyKnownFields(object(item, field), field, {"class", "color", "count", "at", "height", "region"});
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
    if (item.contains("height")) {
      const double height = number(item.at("height"), field + ".height");
      if (!(height >= 0.0 && height <= 0.5)) {
        fail(field + ".height", "must be within 0 .. 0.5 m above the table, got " + format(height));
      }
      request.height = height;
    }
  } else {
    if (item.contains("height")) {
      fail(field + ".height", "only a part placed with \"at\" has a height");
    }
    request.region = item.contains("region") ? stringField(item.at("region"), field + ".region") : "table";
    if (!regions.contains(request.region)) {
      fail(field + ".region", "unknown region '" + request.region + "' (known: " + knownRegions(regions) + ")");
    }
  }
  return request;
}

/// "camera_offset": fixed {"xyz", "rpy_deg"} or random {"distance", "angle_deg", "seed"}.
CameraOffset parseCameraOffset(const json& value, const std::string& field) {
  onlyKnownFields(object(value, field), field, {"xyz", "rpy_deg", "distance", "angle_deg", "seed"});
  CameraOffset offset;
  const bool fixed = value.contains("xyz") || value.contains("rpy_deg");
  offset.random = value.contains("distance") || value.contains("angle_deg");
  if (fixed == offset.random) {
    fail(field,
         "needs either \"xyz\"/\"rpy_deg\" (a fixed offset) or \"distance\"/\"angle_deg\" (a random "
         "direction), not " +
             std::string(fixed ? "both" : "neither"));
  }
  if (value.contains("xyz")) {
    const auto xyz = numbers(value.at("xyz"), field + ".xyz", 3, 3, "[x, y, z] in m");
    offset.xyz = Eigen::Vector3d(xyz[0], xyz[1], xyz[2]);
    if (offset.xyz.norm() > 0.5) {
      fail(field + ".xyz", "the camera may move at most 0.5 m, not " + shown(value.at("xyz")));
    }
  }
  if (value.contains("rpy_deg")) {
    const auto rpy = numbers(value.at("rpy_deg"), field + ".rpy_deg", 3, 3, "[roll, pitch, yaw] in degrees");
    offset.rpy_deg = Eigen::Vector3d(rpy[0], rpy[1], rpy[2]);
    if (offset.rpy_deg.cwiseAbs().maxCoeff() > 45) {
      fail(field + ".rpy_deg",
           "the camera may turn at most 45 degrees about each axis, not " + shown(value.at("rpy_deg")));
    }
  }
  if (value.contains("distance")) {
    offset.distance = number(value.at("distance"), field + ".distance");
    if (offset.distance < 0 || offset.distance > 0.5) {
      fail(field + ".distance", "must be from 0 to 0.5 (m), not " + shown(value.at("distance")));
    }
  }
  if (value.contains("angle_deg")) {
    offset.angle_deg = number(value.at("angle_deg"), field + ".angle_deg");
    if (offset.angle_deg < 0 || offset.angle_deg > 45) {
      fail(field + ".angle_deg", "must be from 0 to 45 (degrees), not " + shown(value.at("angle_deg")));
    }
  }
  if (value.contains("seed")) {
    offset.seed = whole(value.at("seed"), field + ".seed", 0, std::numeric_limits<std::uint64_t>::max());
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
    const json file = core::parseJson(text);
    onlyKnownFields(object(file, "the file"), "",
                    {"description", "seed", "min_gap", "camera_offset", "regions", "parts", "jig", "wire", "workpiece",
                     "power_tool", "person"});
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
    if (file.contains("camera_offset")) {
      scene.camera_offset = parseCameraOffset(file.at("camera_offset"), "camera_offset");
    }
    if (file.contains("workpiece")) {
      scene.workpiece = parseWorkpiece(file.at("workpiece"), "workpiece");
    }
    if (file.contains("power_tool")) {
      if (!file.at("power_tool").is_boolean()) {
        fail("power_tool", "must be true or false, not " + shown(file.at("power_tool")));
      }
      scene.power_tool = file.at("power_tool").get<bool>();
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
    if (file.contains("jig")) {
      scene.jig = parseJig(file.at("jig"), "jig");
    }
    if (file.contains("wire")) {
      scene.wire = parseWire(file.at("wire"), "wire");
    }
    checkJigAndWire(scene.jig, scene.wire);
    if (file.contains("person")) {
      scene.person = parsePerson(file.at("person").dump(), "person");
    }
    return scene;
  } catch (const std::exception& e) {
    throw std::runtime_error("scene '" + label + "': " + e.what());
  }
}

Scene loadScene(const std::filesystem::path& file) {
  // A regular file of a sane size: not /dev/zero, not a folder.
  return parseScene(readFile(file, "scene file"), file.string());
}

Footprint Footprint::of(const world::ObjectClass& object, double x, double y, double yaw) {
  const Eigen::AlignedBox3d bounds = object.bounds();
  const Eigen::Vector2d offset = bounds.center().head<2>();  // of the box centre from the part's origin
  return {Eigen::Vector2d(x, y) + Eigen::Rotation2Dd(yaw) * offset, 0.5 * bounds.sizes().head<2>(), yaw};
}

Eigen::Matrix2d Footprint::axes() const { return Eigen::Rotation2Dd(yaw).toRotationMatrix(); }

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

  // The workpiece is fixed: random placements keep clear of it, a part placed on it is refused.
  std::optional<Footprint> workpiece;
  if (scene.workpiece) {
    workpiece = Footprint{scene.workpiece->at.head<2>(), scene.workpiece->size.head<2>() / 2,
                          scene.workpiece->at.z() * M_PI / 180.0};
    footprints.push_back(*workpiece);
  }
  // Parts placed with "at" first: two that overlap (physics would throw them apart) are refused,
  // and random placements keep clear of every one, wherever it comes in the list.
  struct Fixed {
    std::size_t request;
    Footprint footprint;
    double bottom;  // m above the table
    double top;
  };
  std::vector<Fixed> fixed;
  for (std::size_t r = 0; r < scene.parts.size(); ++r) {
    const PartRequest& request = scene.parts[r];
    if (!request.at) {
      continue;
    }
    const world::ObjectClass& object = findClass(request.object_class, "parts[" + std::to_string(r) + "]");
    const Fixed part{r, Footprint::of(object, request.at->x(), request.at->y(), request.at->z() * M_PI / 180.0),
                     request.height, request.height + object.bounds().sizes().z()};
    for (const Fixed& other : fixed) {
      // Touching is fine (the perception evaluation's scenes place parts 1 mm apart, give or take
      // 0.4 mm); more than 1 mm into each other is not. One above the other is fine too.
      const bool apart_vertically = std::min(part.top, other.top) - std::max(part.bottom, other.bottom) <= 0.001;
      if (!apart_vertically && closerThan(part.footprint, other.footprint, -0.001)) {
        const PartRequest& first = scene.parts[other.request];
        throw std::runtime_error("scene '" + scene.label + "': parts[" + std::to_string(other.request) + "] (" +
                                 first.object_class + " at " + format(first.at->x()) + ", " + format(first.at->y()) +
                                 ") and parts[" + std::to_string(r) + "] (" + request.object_class + " at " +
                                 format(request.at->x()) + ", " + format(request.at->y()) +
                                 ") overlap: the simulation would throw them apart (move one, or give it a \"height\" "
                                 "to lie on the other)");
      }
    }
    if (workpiece && closerThan(part.footprint, *workpiece, -0.001)) {
      throw std::runtime_error("scene '" + scene.label + "': parts[" + std::to_string(r) + "] (" +
                               request.object_class + " at " + format(request.at->x()) + ", " +
                               format(request.at->y()) + ") lies on the workpiece");
    }
    fixed.push_back(part);
    footprints.push_back(part.footprint);
  }

  for (std::size_t r = 0; r < scene.parts.size(); ++r) {
    const PartRequest& request = scene.parts[r];
    const std::string field = "parts[" + std::to_string(r) + "]";
    const world::ObjectClass& object = findClass(request.object_class, field);
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
          const Footprint candidate = Footprint::of(object, xy.x(), xy.y(), yaw);
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
      if (!request.at) {
        footprints.push_back(Footprint::of(object, xy.x(), xy.y(), yaw));
      }
      part.pose = world::poseFromXyzRpy(xy.x(), xy.y(), request.height + object.rest_height + 0.0005, 0, 0, yaw);
      placed.push_back(std::move(part));
    }
  }
  return placed;
}

ClutteredScene clutteredScene(const std::vector<world::ObjectClass>& classes,
                              const std::vector<std::pair<std::string, int>>& counts, double touching,
                              std::mt19937_64& random, const std::string& label, double gap) {
  const auto findClass = [&classes](const std::string& name) -> const world::ObjectClass& {
    for (const auto& object : classes) {
      if (object.name == name) {
        return object;
      }
    }
    throw std::runtime_error("unknown object class '" + name + "'");
  };
  const Region table = defaultRegions().at("table");
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  ClutteredScene out;
  out.scene.label = label;
  out.scene.regions = defaultRegions();
  out.scene.min_gap = 0.0;
  std::vector<Footprint> placed;
  std::vector<std::string> order;
  for (const auto& [name, count] : counts) {
    order.insert(order.end(), static_cast<std::size_t>(std::max(count, 0)), name);
  }
  std::shuffle(order.begin(), order.end(), random);
  for (const std::string& name : order) {
    const world::ObjectClass& object = findClass(name);
    for (int attempt = 0; attempt < 400; ++attempt) {
      Footprint candidate;
      Eigen::Vector2d origin;
      bool touches = false;
      if (!placed.empty() && unit(random) < touching && attempt < 200) {
        // Against a side of an earlier part, turned like it give or take 12 degrees.
        const Footprint& other = placed[static_cast<std::size_t>(unit(random) * placed.size()) % placed.size()];
        const double quarter = unit(random) < 0.5 ? 0.0 : M_PI / 2;  // draws one at a time, in this order
        const double yaw = other.yaw + quarter + (unit(random) - 0.5) * 0.42;
        candidate = Footprint::of(object, 0, 0, yaw);
        const double side_angle = other.yaw + std::floor(unit(random) * 4.0) * M_PI / 2;
        const Eigen::Vector2d normal(std::cos(side_angle), std::sin(side_angle));
        const Eigen::Vector2d tangent(-normal.y(), normal.x());
        const auto support = [&normal](const Footprint& f) {
          const Eigen::Matrix2d axes = f.axes();
          return f.half_size.x() * std::abs(axes.col(0).dot(normal)) +
                 f.half_size.y() * std::abs(axes.col(1).dot(normal));
        };
        const double side_half =
            std::abs(other.axes().col(0).dot(tangent)) > 0.5 ? other.half_size.x() : other.half_size.y();
        const double slide = (unit(random) - 0.5) * 1.2 * side_half;
        // The footprint's centre there; the part's origin lies off it by the bounds' offset.
        const Eigen::Vector2d centre =
            other.centre + normal * (support(other) + support(candidate) + 0.001) + tangent * slide;
        origin = centre - Eigen::Rotation2Dd(yaw) * object.bounds().center().head<2>();
        candidate = Footprint::of(object, origin.x(), origin.y(), yaw);
        touches = true;
      } else {
        // Drawn one at a time: the order of a constructor's arguments is the compiler's.
        const double x = unit(random);
        const double y = unit(random);
        const double yaw = 2 * M_PI * unit(random);
        origin = table.min + (table.max - table.min).cwiseProduct(Eigen::Vector2d(x, y));
        candidate = Footprint::of(object, origin.x(), origin.y(), yaw);
      }
      if ((candidate.centre.array() < table.min.array()).any() ||
          (candidate.centre.array() > table.max.array()).any()) {
        continue;
      }
      // Touching parts may meet their neighbour (0.4 mm into it: the test's rounding), nothing else.
      if (std::any_of(placed.begin(), placed.end(),
                      [&](const Footprint& other) { return closerThan(candidate, other, touches ? -0.0004 : gap); })) {
        continue;
      }
      placed.push_back(candidate);
      PartRequest request;
      request.object_class = name;
      request.at = Eigen::Vector3d(origin.x(), origin.y(), candidate.yaw * 180.0 / M_PI);
      out.scene.parts.push_back(request);
      out.touching_parts += touches ? 1 : 0;
      break;
    }
  }
  return out;
}

std::string sceneFileText(const Scene& scene) {
  json file = json::object();
  if (!scene.description.empty()) {
    file["description"] = scene.description;
  }
  file["seed"] = scene.seed;
  file["min_gap"] = scene.min_gap;
  const auto defaults = defaultRegions();
  for (const auto& [name, region] : scene.regions) {
    const auto known = defaults.find(name);
    if (known == defaults.end() || known->second.min != region.min || known->second.max != region.max) {
      file["regions"][name] = {{"x", {region.min.x(), region.max.x()}}, {"y", {region.min.y(), region.max.y()}}};
    }
  }
  if (scene.camera_offset) {
    const CameraOffset& offset = *scene.camera_offset;
    json value = json::object();
    if (offset.random) {
      value["distance"] = offset.distance;
      value["angle_deg"] = offset.angle_deg;
      if (offset.seed) {
        value["seed"] = *offset.seed;
      }
    } else {
      value["xyz"] = {offset.xyz.x(), offset.xyz.y(), offset.xyz.z()};
      value["rpy_deg"] = {offset.rpy_deg.x(), offset.rpy_deg.y(), offset.rpy_deg.z()};
    }
    file["camera_offset"] = value;
  }
  if (scene.workpiece) {
    const WorkpieceRequest& workpiece = *scene.workpiece;
    file["workpiece"] = {{"at", {workpiece.at.x(), workpiece.at.y(), workpiece.at.z()}},
                         {"size", {workpiece.size.x(), workpiece.size.y(), workpiece.size.z()}},
                         {"marked", {workpiece.marked.x(), workpiece.marked.y()}}};
  }
  if (scene.power_tool) {
    file["power_tool"] = true;
  }
  json parts = json::array();
  for (const PartRequest& part : scene.parts) {
    json item = {{"class", part.object_class}};
    if (!part.color.empty()) {
      item["color"] = part.color;
    }
    if (part.at) {
      item["at"] = {part.at->x(), part.at->y(), part.at->z()};
      if (part.height != 0.0) {
        item["height"] = part.height;
      }
    } else {
      if (part.count != 1) {
        item["count"] = part.count;
      }
      item["region"] = part.region;
    }
    parts.push_back(item);
  }
  file["parts"] = parts;
  if (scene.jig) {
    file["jig"] = jigJson(*scene.jig);
  }
  if (scene.wire) {
    file["wire"] = wireJson(*scene.wire);
  }
  if (scene.person) {
    file["person"] = core::parseJson(scene.person->source);
  }
  return file.dump(1) + "\n";
}

}  // namespace costar::sim
