#include "sim/wire.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>

#include "core/json_file.h"
#include "core/paths.h"
#include "sim/scene.h"
#include "sim/scene_fields.h"
#include "sim/wire_scene.h"

namespace costar::sim {

namespace {

using fields::fail;
using fields::numberIn;
using fields::object;
using fields::onlyKnownFields;
using fields::required;
using fields::shown;
using fields::stringField;
using nlohmann::json;

constexpr double kDeg = M_PI / 180.0;

/// A number or [low, high] within [min, max].
ValueRange range(const json& value, const std::string& field, double min, double max, const std::string& unit) {
  if (value.is_array()) {
    const auto pair = fields::numbers(value, field, 2, 2, "a number or [low, high] in " + unit);
    if (pair[0] > pair[1] || pair[0] < min || pair[1] > max) {
      fail(field, "must be [low, high] with " + fields::written(min) + " <= low <= high <= " + fields::written(max) +
                      " " + unit + ", not " + shown(value));
    }
    return {pair[0], pair[1]};
  }
  const double x = numberIn(value, field, min, max, unit);
  return {x, x};
}

WireMaterial parseMaterial(const json& value, const std::string& field) {
  onlyKnownFields(object(value, field), field,
                  {"name", "description", "youngs_modulus_gpa", "yield_strength_mpa", "density_kg_m3", "friction"});
  WireMaterial material;
  material.name = stringField(required(value, "name", field, "the name a scene uses"), field + ".name");
  if (value.contains("description")) {
    material.description = stringField(value.at("description"), field + ".description");
  }
  material.youngs_modulus_gpa = range(required(value, "youngs_modulus_gpa", field, "GPa, e.g. [195, 210]"),
                                      field + ".youngs_modulus_gpa", 1, 500, "GPa");
  material.yield_strength_mpa = range(required(value, "yield_strength_mpa", field, "MPa, e.g. [230, 290]"),
                                      field + ".yield_strength_mpa", 1, 3000, "MPa");
  material.density = numberIn(required(value, "density_kg_m3", field, "kg/m^3, e.g. 7850"), field + ".density_kg_m3",
                              500, 25000, "kg/m^3");
  material.friction = numberIn(required(value, "friction", field, "sliding friction against steel, e.g. 0.3"),
                               field + ".friction", 0.01, 2, "");
  return material;
}

/// A pin: name, where, how big, how firmly it is pressed in.
PinSpec parsePin(const json& value, const std::string& field) {
  onlyKnownFields(object(value, field), field, {"name", "at", "radius", "height", "hold_force", "stiffness"});
  PinSpec pin;
  pin.name = stringField(required(value, "name", field, "e.g. \"A\""), field + ".name");
  if (pin.name.empty() || pin.name.find_first_not_of(
                              "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_") != std::string::npos) {
    fail(field + ".name", "must be letters, digits and _, not " + shown(value.at("name")));
  }
  const auto at = fields::numbers(required(value, "at", field, "[x, y] in the jig's frame, m"), field + ".at", 2, 2,
                                  "[x, y] in the jig's frame (m)");
  pin.at = Eigen::Vector2d(at[0], at[1]);
  if (pin.at.norm() > 0.5) {
    fail(field + ".at", "lies more than 0.5 m from the clamp, not " + shown(value.at("at")));
  }
  if (value.contains("radius")) {
    pin.radius = numberIn(value.at("radius"), field + ".radius", 0.001, 0.05, "m");
  }
  if (value.contains("height")) {
    pin.height = numberIn(value.at("height"), field + ".height", 0.005, 0.3, "m");
  }
  if (value.contains("hold_force")) {
    pin.hold_force = numberIn(value.at("hold_force"), field + ".hold_force", 1, 10000, "N");
  }
  if (value.contains("stiffness")) {
    pin.stiffness = numberIn(value.at("stiffness"), field + ".stiffness", 1e3, 1e7, "N/m");
  }
  return pin;
}

BendTarget parseBend(const json& value, const std::string& field) {
  onlyKnownFields(object(value, field), field, {"at", "angle_deg"});
  BendTarget bend;
  bend.at =
      numberIn(required(value, "at", field, "arc length from the clamp's mouth, m"), field + ".at", 0.0, 1.0, "m");
  bend.angle_deg = numberIn(required(value, "angle_deg", field, "+ to the left, degrees"), field + ".angle_deg", -175,
                            175, "degrees");
  if (std::abs(bend.angle_deg) < 1.0) {
    fail(field + ".angle_deg", "a bend of less than 1 degree is no bend, not " + shown(value.at("angle_deg")));
  }
  return bend;
}

double uniform(std::mt19937_64& random, const ValueRange& range) {
  return range.low + (range.high - range.low) * std::uniform_real_distribution<double>(0.0, 1.0)(random);
}

double symmetric(std::mt19937_64& random, double half_width) {
  return half_width * std::uniform_real_distribution<double>(-1.0, 1.0)(random);
}

/// The point at arc length `s` along a polyline whose points are `step` apart.
Eigen::Vector3d pointAt(const std::vector<Eigen::Vector3d>& points, double step, double s) {
  const double position = std::clamp(s / step, 0.0, static_cast<double>(points.size() - 1));
  const auto i = std::min(static_cast<std::size_t>(position), points.size() - 2);
  const double t = position - static_cast<double>(i);
  return (1.0 - t) * points[i] + t * points[i + 1];
}

}  // namespace

std::vector<WireMaterial> loadWireMaterials(const std::filesystem::path& file_given) {
  const std::filesystem::path file = file_given.empty() ? dataRoot() / "data/wire_materials.json" : file_given;
  try {
    const json file_json = core::readJsonFile(file);
    onlyKnownFields(object(file_json, "the file"), "", {"format", "description", "materials"});
    if (stringField(required(file_json, "format", "", "\"costar-wire-materials/1\""), "format") !=
        "costar-wire-materials/1") {
      fail("format", "must be \"costar-wire-materials/1\", not " + shown(file_json.at("format")));
    }
    const json& list = required(file_json, "materials", "", "a list of materials");
    if (!list.is_array() || list.empty()) {
      fail("materials", "must be a non-empty list [...], not " + shown(list));
    }
    std::vector<WireMaterial> materials;
    for (std::size_t i = 0; i < list.size(); ++i) {
      const std::string field = "materials[" + std::to_string(i) + "]";
      WireMaterial material = parseMaterial(list[i], field);
      for (const WireMaterial& other : materials) {
        if (other.name == material.name) {
          fail(field + ".name", "'" + material.name + "' is given twice");
        }
      }
      materials.push_back(std::move(material));
    }
    return materials;
  } catch (const std::exception& e) {
    throw std::runtime_error("wire materials '" + file.string() + "': " + e.what());
  }
}

JigSpec parseJig(const json& value, const std::string& field) {
  onlyKnownFields(object(value, field), field,
                  {"at", "placement_error", "height", "clamp_tolerance", "pins", "target"});
  JigSpec jig;
  const auto at = fields::numbers(required(value, "at", field,
                                           "[x, y, yaw]: the clamp's mouth (m) and the wire's "
                                           "heading (degrees)"),
                                  field + ".at", 3, 3, "[x, y, yaw] (m, m, degrees)");
  jig.at = Eigen::Vector3d(at[0], at[1], at[2]);
  const Region table = tableTop();
  if (jig.at.x() < table.min.x() || jig.at.x() > table.max.x() || jig.at.y() < table.min.y() ||
      jig.at.y() > table.max.y()) {
    fail(field + ".at", "lies off the table top");
  }
  if (std::abs(jig.at.z()) > 180) {
    fail(field + ".at[2]", "the yaw must be from -180 to 180 degrees, not " + shown(value.at("at")[2]));
  }
  if (value.contains("placement_error")) {
    const std::string error_field = field + ".placement_error";
    const json& error = object(value.at("placement_error"), error_field);
    onlyKnownFields(error, error_field, {"xy", "yaw_deg"});
    if (error.contains("xy")) {
      jig.xy_error = numberIn(error.at("xy"), error_field + ".xy", 0, 0.02, "m");
    }
    if (error.contains("yaw_deg")) {
      jig.yaw_error_deg = numberIn(error.at("yaw_deg"), error_field + ".yaw_deg", 0, 5, "degrees");
    }
  }
  if (value.contains("height")) {
    jig.height = numberIn(value.at("height"), field + ".height", 0.005, 0.2, "m");
  }
  if (value.contains("clamp_tolerance")) {
    jig.clamp_tolerance = numberIn(value.at("clamp_tolerance"), field + ".clamp_tolerance", 0, 0.01, "m");
  }
  const json& pins = required(value, "pins", field, "a list of pins: [{\"name\": \"A\", \"at\": [x, y]}, ...]");
  if (!pins.is_array()) {
    fail(field + ".pins", "must be a list [...], not " + shown(pins));
  }
  for (std::size_t i = 0; i < pins.size(); ++i) {
    const std::string pin_field = field + ".pins[" + std::to_string(i) + "]";
    PinSpec pin = parsePin(pins[i], pin_field);
    if (pin.height < jig.height + 0.01) {
      fail(pin_field + ".height", "the pin must stand at least 1 cm above the wire (at " + fields::written(jig.height) +
                                      " m), or the wire slips over it; not " + fields::written(pin.height));
    }
    for (std::size_t j = 0; j < jig.pins.size(); ++j) {
      const PinSpec& other = jig.pins[j];
      if (other.name == pin.name) {
        fail(pin_field + ".name", "'" + pin.name + "' is the name of pins[" + std::to_string(j) + "] too");
      }
      if ((other.at - pin.at).norm() < other.radius + pin.radius) {
        fail(pin_field + ".at", "overlaps pins[" + std::to_string(j) + "] ('" + other.name + "')");
      }
    }
    jig.pins.push_back(std::move(pin));
  }
  if (value.contains("target")) {
    const json& target = value.at("target");
    if (!target.is_array()) {
      fail(field + ".target",
           "must be a list of bends [{\"at\": m, \"angle_deg\": degrees}, ...], not " + shown(target));
    }
    for (std::size_t i = 0; i < target.size(); ++i) {
      const std::string bend_field = field + ".target[" + std::to_string(i) + "]";
      BendTarget bend = parseBend(target[i], bend_field);
      const double previous = jig.target.empty() ? 0.0 : jig.target.back().at;
      if (bend.at < previous + 0.02) {
        fail(bend_field + ".at", "must be at least 2 cm further along the wire than " +
                                     std::string(jig.target.empty() ? "the clamp's mouth" : "the bend before") +
                                     " (at " + fields::written(previous) + " m), not " + fields::written(bend.at));
      }
      jig.target.push_back(bend);
    }
  }
  return jig;
}

WireSpec parseWire(const json& value, const std::string& field) {
  onlyKnownFields(object(value, field), field, {"material", "diameter", "length", "segments"});
  WireSpec wire;
  wire.material =
      stringField(required(value, "material", field, "a name in data/wire_materials.json"), field + ".material");
  if (value.contains("diameter")) {
    wire.diameter = numberIn(value.at("diameter"), field + ".diameter", 0.0005, 0.008, "m");
  }
  if (value.contains("length")) {
    wire.length = numberIn(value.at("length"), field + ".length", 0.05, 0.6, "m");
  }
  if (value.contains("segments")) {
    wire.segments = static_cast<int>(fields::whole(value.at("segments"), field + ".segments", 4, 60));
  }
  if (wire.length / wire.segments < 2.0 * wire.diameter) {
    fail(field + ".segments", "segments of " + fields::written(wire.length / wire.segments) +
                                  " m are shorter than twice the diameter: fewer segments");
  }
  return wire;
}

void checkJigAndWire(const std::optional<JigSpec>& jig, const std::optional<WireSpec>& wire) {
  if (!wire) {
    return;
  }
  if (!jig) {
    fail("wire", "needs a \"jig\" (its clamp holds the wire's start)");
  }
  // The wire starts straight along the jig's x axis: no pin may stand in its way.
  const double radius = wire->diameter / 2;
  for (std::size_t i = 0; i < jig->pins.size(); ++i) {
    const PinSpec& pin = jig->pins[i];
    const double along = std::clamp(pin.at.x(), 0.0, wire->length + jig->clamp_tolerance);
    if ((pin.at - Eigen::Vector2d(along, 0.0)).norm() < pin.radius + radius) {
      fail("jig.pins[" + std::to_string(i) + "].at", "pin '" + pin.name +
                                                         "' stands in the straight wire's way (the wire leaves the "
                                                         "clamp along the jig's x axis)");
    }
  }
  for (std::size_t i = 0; i < jig->target.size(); ++i) {
    if (jig->target[i].at > wire->length - 0.02) {
      fail("jig.target[" + std::to_string(i) + "].at",
           "lies within 2 cm of the wire's end (the wire is " + fields::written(wire->length) + " m long)");
    }
  }
}

json jigJson(const JigSpec& jig) {
  json value = {{"at", {jig.at.x(), jig.at.y(), jig.at.z()}},
                {"placement_error", {{"xy", jig.xy_error}, {"yaw_deg", jig.yaw_error_deg}}},
                {"height", jig.height},
                {"clamp_tolerance", jig.clamp_tolerance}};
  json pins = json::array();
  for (const PinSpec& pin : jig.pins) {
    pins.push_back({{"name", pin.name},
                    {"at", {pin.at.x(), pin.at.y()}},
                    {"radius", pin.radius},
                    {"height", pin.height},
                    {"hold_force", pin.hold_force},
                    {"stiffness", pin.stiffness}});
  }
  value["pins"] = pins;
  json target = json::array();
  for (const BendTarget& bend : jig.target) {
    target.push_back({{"at", bend.at}, {"angle_deg", bend.angle_deg}});
  }
  value["target"] = target;
  return value;
}

json wireJson(const WireSpec& wire) {
  return {
      {"material", wire.material}, {"diameter", wire.diameter}, {"length", wire.length}, {"segments", wire.segments}};
}

JigDraw drawJig(const JigSpec& jig, const std::optional<WireSpec>& wire, const WireMaterial* material,
                std::uint64_t seed) {
  std::mt19937_64 random(seed ^ 0x77697265ULL);  // "wire": a stream apart from the part placement
  JigDraw draw;
  // Drawn one at a time, in this order: the order of a constructor's arguments is the compiler's.
  const double dx = symmetric(random, jig.xy_error);
  const double dy = symmetric(random, jig.xy_error);
  const double yaw = (jig.at.z() + symmetric(random, jig.yaw_error_deg)) * kDeg;
  draw.pose = world::poseFromXyzRpy(jig.at.x() + dx, jig.at.y() + dy, 0.0, 0.0, 0.0, yaw);
  const double start = symmetric(random, jig.clamp_tolerance);
  if (wire) {
    draw.wire_length = wire->length - start;  // pushed further in: less of it out of the clamp
  }
  if (material != nullptr) {
    draw.youngs_modulus_gpa = uniform(random, material->youngs_modulus_gpa);
    draw.yield_strength_mpa = uniform(random, material->yield_strength_mpa);
  }
  return draw;
}

WireJoints wireJoints(const WireSpec& wire, double length, double youngs_modulus_gpa, double yield_strength_mpa) {
  WireJoints joints;
  joints.segment = length / wire.segments;
  const double d = wire.diameter;
  const double second_moment = M_PI * std::pow(d, 4) / 64.0;                 // I, m^4
  const double plastic_moment = yield_strength_mpa * 1e6 * d * d * d / 6.0;  // N m, the whole section yielded
  joints.stiffness = youngs_modulus_gpa * 1e9 * second_moment / joints.segment;
  joints.yield_angle = plastic_moment / joints.stiffness;
  return joints;
}

std::vector<Eigen::Vector2d> targetPolyline(const std::vector<BendTarget>& target, double length) {
  std::vector<Eigen::Vector2d> points{Eigen::Vector2d::Zero()};
  double heading = 0.0;
  double along = 0.0;
  for (const BendTarget& bend : target) {
    points.push_back(points.back() + (bend.at - along) * Eigen::Vector2d(std::cos(heading), std::sin(heading)));
    heading += bend.angle_deg * kDeg;
    along = bend.at;
  }
  points.push_back(points.back() + (length - along) * Eigen::Vector2d(std::cos(heading), std::sin(heading)));
  return points;
}

std::vector<MeasuredBend> measureBends(const std::vector<Eigen::Vector3d>& centreline,
                                       const std::vector<BendTarget>& target) {
  std::vector<MeasuredBend> bends;
  if (centreline.size() < 2 || target.empty()) {
    return bends;
  }
  double length = 0.0;
  for (std::size_t i = 1; i < centreline.size(); ++i) {
    length += (centreline[i] - centreline[i - 1]).norm();
  }
  const double step = length / static_cast<double>(centreline.size() - 1);
  // The straight stretches: from the clamp to the first bend, between bends, to the end.
  std::vector<double> cuts{0.0};
  for (const BendTarget& bend : target) {
    cuts.push_back(bend.at);
  }
  cuts.push_back(length);
  std::vector<Eigen::Vector3d> directions;
  for (std::size_t k = 0; k + 1 < cuts.size(); ++k) {
    const double a = cuts[k];
    const double b = std::max(cuts[k + 1], a);
    directions.push_back(pointAt(centreline, step, a + 0.75 * (b - a)) - pointAt(centreline, step, a + 0.25 * (b - a)));
  }
  const auto heading = [](const Eigen::Vector3d& v) { return std::atan2(v.y(), v.x()); };
  const auto pitch = [](const Eigen::Vector3d& v) { return std::atan2(v.z(), v.head<2>().norm()); };
  for (std::size_t k = 0; k < target.size(); ++k) {
    MeasuredBend bend;
    bend.target_deg = target[k].angle_deg;
    const double turn = heading(directions[k + 1]) - heading(directions[k]);
    bend.angle_deg = std::remainder(turn, 2.0 * M_PI) / kDeg;
    bend.out_of_plane_deg = (pitch(directions[k + 1]) - pitch(directions[k])) / kDeg;
    bends.push_back(bend);
  }
  return bends;
}

}  // namespace costar::sim
