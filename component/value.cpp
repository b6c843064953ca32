#include "component/value.h"

#include <charconv>
#include <cmath>
#include <stdexcept>

namespace costar::component {

const char* typeName(ValueType type) {
  switch (type) {
    case ValueType::kBool:
      return "bool";
    case ValueType::kInt:
      return "int";
    case ValueType::kDouble:
      return "double";
    case ValueType::kString:
      return "std::string";
    case ValueType::kPose:
      return "costar::Pose";
    case ValueType::kStringList:
      return "std::vector<std::string>";
  }
  return "?";
}

namespace {

[[noreturn]] void mismatch(ValueType wanted, ValueType held) {
  throw std::invalid_argument(std::string("value is a ") + typeName(held) + ", not a " + typeName(wanted));
}

std::string_view trim(std::string_view text) {
  while (!text.empty() && std::isspace(static_cast<unsigned char>(text.front()))) {
    text.remove_prefix(1);
  }
  while (!text.empty() && std::isspace(static_cast<unsigned char>(text.back()))) {
    text.remove_suffix(1);
  }
  return text;
}

std::string shortest(double value) {
  char buffer[32];
  const auto [end, ec] = std::to_chars(buffer, buffer + sizeof buffer, value);
  return std::string(buffer, end);
}

}  // namespace

bool Value::asBool() const {
  if (const auto* v = std::get_if<bool>(&data_)) {
    return *v;
  }
  mismatch(ValueType::kBool, type());
}

long long Value::asInt() const {
  if (const auto* v = std::get_if<long long>(&data_)) {
    return *v;
  }
  mismatch(ValueType::kInt, type());
}

double Value::asDouble() const {
  if (const auto* v = std::get_if<double>(&data_)) {
    return *v;
  }
  if (const auto* v = std::get_if<long long>(&data_)) {
    return static_cast<double>(*v);
  }
  mismatch(ValueType::kDouble, type());
}

const std::string& Value::asString() const {
  if (const auto* v = std::get_if<std::string>(&data_)) {
    return *v;
  }
  mismatch(ValueType::kString, type());
}

const world::Pose& Value::asPose() const {
  if (const auto* v = std::get_if<world::Pose>(&data_)) {
    return *v;
  }
  mismatch(ValueType::kPose, type());
}

const Value::List& Value::asList() const {
  if (const auto* v = std::get_if<List>(&data_)) {
    return *v;
  }
  mismatch(ValueType::kStringList, type());
}

bool Value::operator==(const Value& other) const {
  if (type() != other.type()) {
    return false;
  }
  switch (type()) {
    case ValueType::kBool:
      return asBool() == other.asBool();
    case ValueType::kInt:
      return asInt() == other.asInt();
    case ValueType::kDouble:
      return asDouble() == other.asDouble();
    case ValueType::kString:
      return asString() == other.asString();
    case ValueType::kPose:
      return asPose().isApprox(other.asPose(), 1e-12);
    case ValueType::kStringList:
      return asList() == other.asList();
  }
  return false;
}

std::optional<Value> parseValue(ValueType type, std::string_view text, std::string* error) {
  const auto fail = [&](std::string message) -> std::optional<Value> {
    if (error != nullptr) {
      *error = std::move(message);
    }
    return std::nullopt;
  };
  const std::string_view trimmed = trim(text);
  switch (type) {
    case ValueType::kBool:
      if (trimmed == "true" || trimmed == "1") {
        return Value(true);
      }
      if (trimmed == "false" || trimmed == "0") {
        return Value(false);
      }
      return fail("'" + std::string(text) + "' is not true or false");
    case ValueType::kInt: {
      long long value = 0;
      const auto [end, ec] = std::from_chars(trimmed.data(), trimmed.data() + trimmed.size(), value);
      if (trimmed.empty() || ec != std::errc() || end != trimmed.data() + trimmed.size()) {
        return fail("'" + std::string(text) + "' is not an integer");
      }
      return Value(value);
    }
    case ValueType::kDouble: {
      double value = 0;
      const auto [end, ec] = std::from_chars(trimmed.data(), trimmed.data() + trimmed.size(), value);
      if (trimmed.empty() || ec != std::errc() || end != trimmed.data() + trimmed.size() || !std::isfinite(value)) {
        return fail("'" + std::string(text) + "' is not a number");
      }
      return Value(value);
    }
    case ValueType::kString:
      return Value(std::string(text));
    case ValueType::kPose: {
      std::string problem;
      const auto pose = world::parsePose(text, &problem);
      if (!pose) {
        return fail(problem);
      }
      return Value(*pose);
    }
    case ValueType::kStringList: {
      Value::List items;
      if (!trimmed.empty()) {
        std::size_t start = 0;
        while (start <= trimmed.size()) {
          const std::size_t end = std::min(trimmed.find(';', start), trimmed.size());
          items.emplace_back(trim(trimmed.substr(start, end - start)));
          start = end + 1;
        }
      }
      return Value(std::move(items));
    }
  }
  return fail("unknown type");
}

std::string formatValue(const Value& value) {
  switch (value.type()) {
    case ValueType::kBool:
      return value.asBool() ? "true" : "false";
    case ValueType::kInt:
      return std::to_string(value.asInt());
    case ValueType::kDouble:
      return shortest(value.asDouble());
    case ValueType::kString:
      return value.asString();
    case ValueType::kPose:
      return world::formatPose(value.asPose());
    case ValueType::kStringList: {
      std::string text;
      for (const auto& item : value.asList()) {
        text += (text.empty() ? "" : ";") + item;
      }
      return text;
    }
  }
  return {};
}

nlohmann::json toJson(const Value& value) {
  switch (value.type()) {
    case ValueType::kBool:
      return value.asBool();
    case ValueType::kInt:
      return value.asInt();
    case ValueType::kDouble:
      return value.asDouble();
    case ValueType::kString:
      return value.asString();
    case ValueType::kPose: {
      const auto& pose = value.asPose();
      const Eigen::Quaterniond q(pose.linear());
      return {{"position", {pose.translation().x(), pose.translation().y(), pose.translation().z()}},
              {"orientation", {q.w(), q.x(), q.y(), q.z()}}};
    }
    case ValueType::kStringList:
      return value.asList();
  }
  return nullptr;
}

Value valueFromJson(ValueType type, const nlohmann::json& json) {
  const auto wrong = [&]() -> Value {
    throw std::invalid_argument(std::string("expected ") + typeName(type) + ", got " + json.dump());
  };
  switch (type) {
    case ValueType::kBool:
      return json.is_boolean() ? Value(json.get<bool>()) : wrong();
    case ValueType::kInt:
      return json.is_number_integer() ? Value(json.get<long long>()) : wrong();
    case ValueType::kDouble:
      return json.is_number() && std::isfinite(json.get<double>()) ? Value(json.get<double>()) : wrong();
    case ValueType::kString:
      return json.is_string() ? Value(json.get<std::string>()) : wrong();
    case ValueType::kPose: {
      if (!json.is_object() || !json.contains("position") || !json.contains("orientation")) {
        return wrong();
      }
      const auto& p = json.at("position");
      const auto& o = json.at("orientation");
      if (!p.is_array() || p.size() != 3 || !o.is_array() || o.size() != 4) {
        return wrong();
      }
      for (const auto& item : p) {
        if (!item.is_number()) {
          return wrong();
        }
      }
      for (const auto& item : o) {
        if (!item.is_number()) {
          return wrong();
        }
      }
      Eigen::Quaterniond q(o[0].get<double>(), o[1].get<double>(), o[2].get<double>(), o[3].get<double>());
      if (!std::isfinite(q.norm()) || q.norm() < 1e-9) {
        return wrong();
      }
      world::Pose pose = world::Pose::Identity();
      pose.linear() = q.normalized().toRotationMatrix();
      pose.translation() = Eigen::Vector3d(p[0].get<double>(), p[1].get<double>(), p[2].get<double>());
      if (!pose.translation().allFinite()) {
        return wrong();
      }
      return Value(pose);
    }
    case ValueType::kStringList: {
      if (!json.is_array()) {
        return wrong();
      }
      Value::List items;
      for (const auto& item : json) {
        if (!item.is_string()) {
          return wrong();
        }
        items.push_back(item.get<std::string>());
      }
      return Value(std::move(items));
    }
  }
  return wrong();
}

std::string ParamSpec::check(std::string_view text) const {
  std::string error;
  const auto value = parseValue(type, text, &error);
  if (!value) {
    return error;
  }
  if (validate) {
    if (std::string problem = validate(text); !problem.empty()) {
      return problem;
    }
  }
  if (!choices.empty() && std::find(choices.begin(), choices.end(), value->asString()) == choices.end()) {
    std::string allowed;
    for (const auto& choice : choices) {
      allowed += (allowed.empty() ? "" : ", ") + choice;
    }
    return "'" + std::string(text) + "' is not one of: " + allowed;
  }
  if (type == ValueType::kInt || type == ValueType::kDouble) {
    const double number = value->asDouble();
    if ((min && number < *min) || (max && number > *max)) {
      return std::string(text) + " is out of range [" + (min ? shortest(*min) : "-inf") + ", " +
             (max ? shortest(*max) : "inf") + "]";
    }
  }
  return {};
}

nlohmann::json toJson(const ParamMap& params) {
  nlohmann::json json = nlohmann::json::object();
  for (const auto& [name, value] : params) {
    json[name] = toJson(value);
  }
  return json;
}

ParamMap paramsFromJson(const std::vector<ParamSpec>& specs, const nlohmann::json& json) {
  if (!json.is_object()) {
    throw std::invalid_argument("parameters must be a JSON object");
  }
  ParamMap params;
  for (const auto& spec : specs) {
    if (json.contains(spec.name)) {
      try {
        params[spec.name] = valueFromJson(spec.type, json.at(spec.name));
      } catch (const std::invalid_argument& e) {
        throw std::invalid_argument("parameter '" + spec.name + "': " + e.what());
      }
      if (const std::string problem = spec.check(formatValue(params[spec.name])); !problem.empty()) {
        throw std::invalid_argument("parameter '" + spec.name + "': " + problem);
      }
    } else if (spec.default_value) {
      params[spec.name] = *spec.default_value;
    } else {
      throw std::invalid_argument("missing parameter '" + spec.name + "'");
    }
  }
  for (const auto& item : json.items()) {
    const std::string& name = item.key();  // not a structured binding: clang 14 cannot capture one
    const bool known = std::any_of(specs.begin(), specs.end(), [&](const ParamSpec& s) { return s.name == name; });
    if (!known) {
      throw std::invalid_argument("unknown parameter '" + name + "'");
    }
  }
  return params;
}

nlohmann::json toJson(const ParamSpec& spec) {
  nlohmann::json json = {{"name", spec.name}, {"type", typeName(spec.type)}, {"description", spec.description}};
  if (spec.default_value) {
    json["default"] = formatValue(*spec.default_value);
  }
  if (!spec.choices.empty()) {
    json["choices"] = spec.choices;
  }
  if (spec.min) {
    json["min"] = *spec.min;
  }
  if (spec.max) {
    json["max"] = *spec.max;
  }
  if (!spec.choices_from.empty()) {
    json["choices_from"] = spec.choices_from;
  }
  if (!spec.extra_choices.empty()) {
    json["extra_choices"] = spec.extra_choices;
  }
  if (!spec.excludes.empty()) {
    json["excludes"] = spec.excludes;
  }
  if (!spec.less_than.empty()) {
    json["less_than"] = spec.less_than;
  }
  return json;
}

}  // namespace costar::component
