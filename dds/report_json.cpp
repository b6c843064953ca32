#include "dds/report_json.h"

#include <stdexcept>
#include <string>

namespace costar::dds {
namespace {

using nlohmann::json;

json poseJson(const world::Pose& pose) {
  json entries = json::array();
  for (int row = 0; row < 3; ++row) {
    for (int column = 0; column < 4; ++column) {
      entries.push_back(pose.matrix()(row, column));
    }
  }
  return entries;
}

world::Pose poseFrom(const json& entries, const std::string& where) {
  if (!entries.is_array() || entries.size() != 12) {
    throw std::invalid_argument(where + ": a pose is 12 numbers (3 rows of the 3x4 matrix)");
  }
  world::Pose pose = world::Pose::Identity();
  for (int row = 0; row < 3; ++row) {
    for (int column = 0; column < 4; ++column) {
      const json& entry = entries[static_cast<std::size_t>(row * 4 + column)];
      if (!entry.is_number()) {
        throw std::invalid_argument(where + ": a pose entry is not a number");
      }
      pose.matrix()(row, column) = entry.get<double>();
    }
  }
  return pose;
}

json vectorJson(const Eigen::Vector3d& v) { return json::array({v.x(), v.y(), v.z()}); }

Eigen::Vector3d vectorFrom(const json& entries, const std::string& where) {
  if (!entries.is_array() || entries.size() != 3 || !entries[0].is_number() || !entries[1].is_number() ||
      !entries[2].is_number()) {
    throw std::invalid_argument(where + ": expected 3 numbers");
  }
  return {entries[0].get<double>(), entries[1].get<double>(), entries[2].get<double>()};
}

const json& field(const json& object, const char* name, const std::string& where) {
  const auto it = object.find(name);
  if (it == object.end()) {
    throw std::invalid_argument(where + ": missing '" + name + "'");
  }
  return *it;
}

template <typename T>
T get(const json& object, const char* name, const std::string& where) {
  try {
    return field(object, name, where).get<T>();
  } catch (const json::exception& error) {
    throw std::invalid_argument(where + ": '" + name + "': " + error.what());
  }
}

json symbolJson(const world::Symbol& symbol) {
  json out = {{"name", symbol.name},
              {"source", symbol.source},
              {"stamp_ns", symbol.stamp.time_since_epoch().count()},
              {"kind", world::toString(symbol.kind())}};
  if (const auto* frame = symbol.frame()) {
    out["parent"] = frame->parent;
    out["pose"] = poseJson(frame->pose);
  } else if (const auto* joints = symbol.joints()) {
    out["joint_names"] = joints->joint_names;
    out["positions"] = joints->positions;
  } else if (const auto* object_class = std::get_if<world::ObjectClassValue>(&symbol.value)) {
    out["description"] = object_class->description;
  } else if (const auto* wrench = symbol.wrench()) {
    out["frame"] = wrench->frame;
    out["force"] = vectorJson(wrench->force);
    out["torque"] = vectorJson(wrench->torque);
  } else if (const auto* number = symbol.number()) {
    out["value"] = number->value;
    out["unit"] = number->unit;
  }
  if (symbol.color) {
    out["color"] = vectorJson(*symbol.color);
  }
  return out;
}

world::Symbol symbolFrom(const json& in, std::size_t index) {
  std::string where = "report: symbols[" + std::to_string(index) + "]";
  if (!in.is_object()) {
    throw std::invalid_argument(where + ": not an object");
  }
  world::Symbol symbol;
  symbol.name = get<std::string>(in, "name", where);
  where += " ('" + symbol.name + "')";
  symbol.source = get<std::string>(in, "source", where);
  symbol.stamp = TimePoint(Duration(get<std::int64_t>(in, "stamp_ns", where)));
  const auto kind = get<std::string>(in, "kind", where);
  if (kind == world::toString(world::SymbolKind::kFrame)) {
    symbol.value = world::FrameValue{get<std::string>(in, "parent", where), poseFrom(field(in, "pose", where), where)};
  } else if (kind == world::toString(world::SymbolKind::kJoints)) {
    world::JointsValue joints{get<std::vector<std::string>>(in, "joint_names", where),
                              get<std::vector<double>>(in, "positions", where)};
    if (joints.joint_names.size() != joints.positions.size()) {
      throw std::invalid_argument(where + ": " + std::to_string(joints.joint_names.size()) + " joint names but " +
                                  std::to_string(joints.positions.size()) + " positions");
    }
    symbol.value = std::move(joints);
  } else if (kind == world::toString(world::SymbolKind::kObjectClass)) {
    symbol.value = world::ObjectClassValue{get<std::string>(in, "description", where)};
  } else if (kind == world::toString(world::SymbolKind::kWrench)) {
    symbol.value =
        world::WrenchValue{get<std::string>(in, "frame", where), vectorFrom(field(in, "force", where), where),
                           vectorFrom(field(in, "torque", where), where)};
  } else if (kind == world::toString(world::SymbolKind::kNumber)) {
    symbol.value = world::NumberValue{get<double>(in, "value", where), get<std::string>(in, "unit", where)};
  } else {
    throw std::invalid_argument(where + ": unknown kind '" + kind + "' (frame, joints, class, wrench, number)");
  }
  if (const auto color = in.find("color"); color != in.end()) {
    symbol.color = vectorFrom(*color, where + ": 'color'");
  }
  return symbol;
}

}  // namespace

json toJson(const world::Report& report) {
  json symbols = json::array();
  for (const auto& symbol : report.symbols) {
    symbols.push_back(symbolJson(symbol));
  }
  json predicates = json::array();
  for (const auto& predicate : report.predicates) {
    predicates.push_back(
        {{"name", predicate.name}, {"args", predicate.args}, {"value", predicate.value}, {"source", predicate.source}});
  }
  return {{"symbols", std::move(symbols)}, {"predicates", std::move(predicates)}};
}

world::Report reportFromJson(const json& json) {
  if (!json.is_object()) {
    throw std::invalid_argument("report: not an object");
  }
  world::Report report;
  const auto& symbols = field(json, "symbols", "report");
  const auto& predicates = field(json, "predicates", "report");
  if (!symbols.is_array() || !predicates.is_array()) {
    throw std::invalid_argument("report: 'symbols' and 'predicates' must be arrays");
  }
  for (std::size_t i = 0; i < symbols.size(); ++i) {
    report.symbols.push_back(symbolFrom(symbols[i], i));
  }
  for (std::size_t i = 0; i < predicates.size(); ++i) {
    const std::string where = "report: predicates[" + std::to_string(i) + "]";
    const auto& in = predicates[i];
    if (!in.is_object()) {
      throw std::invalid_argument(where + ": not an object");
    }
    report.predicates.push_back({get<std::string>(in, "name", where), get<std::vector<std::string>>(in, "args", where),
                                 get<bool>(in, "value", where), get<std::string>(in, "source", where)});
  }
  return report;
}

}  // namespace costar::dds
