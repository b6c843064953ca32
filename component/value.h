#pragma once
// Typed, serializable parameters and results of operations. A plan writes them as XML
// attributes; across a process boundary they travel as JSON.

#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "world/pose.h"

namespace costar::component {

enum class ValueType { kBool, kInt, kDouble, kString, kPose, kStringList };
/// "bool", "int", "double", "std::string", "costar::Pose", "std::vector<std::string>"
/// (BehaviorTree.CPP's names where it has one).
const char* typeName(ValueType type);

class Value {
 public:
  using List = std::vector<std::string>;

  Value() : data_(false) {}
  Value(bool value) : data_(value) {}                         // NOLINT(google-explicit-constructor)
  Value(long long value) : data_(value) {}                    // NOLINT
  Value(int value) : data_(static_cast<long long>(value)) {}  // NOLINT
  Value(double value) : data_(value) {}                       // NOLINT
  Value(std::string value) : data_(std::move(value)) {}       // NOLINT
  Value(const char* value) : data_(std::string(value)) {}     // NOLINT
  Value(const world::Pose& value) : data_(value) {}           // NOLINT
  Value(List value) : data_(std::move(value)) {}              // NOLINT

  ValueType type() const { return static_cast<ValueType>(data_.index()); }
  /// Typed access. @throws std::invalid_argument naming both types on a mismatch
  /// (asDouble() also accepts an int).
  bool asBool() const;
  long long asInt() const;
  double asDouble() const;
  const std::string& asString() const;
  const world::Pose& asPose() const;
  const List& asList() const;

  bool operator==(const Value& other) const;

 private:
  std::variant<bool, long long, double, std::string, world::Pose, List> data_;
};

/// Parses the text form of a value (as written in a plan attribute):
/// bool: true/false/1/0; numbers: decimal; pose: "x;y;z[;roll;pitch;yaw]" (m, degrees);
/// list: "a;b;c" (empty text: empty list). On failure returns nullopt and sets `error`.
std::optional<Value> parseValue(ValueType type, std::string_view text, std::string* error = nullptr);
/// The text form, such that parseValue(type, formatValue(v)) == v.
std::string formatValue(const Value& value);

nlohmann::json toJson(const Value& value);
/// @throws std::invalid_argument when `json` does not hold a `type`.
Value valueFromJson(ValueType type, const nlohmann::json& json);

/// Describes one parameter of an operation.
struct ParamSpec {
  std::string name;
  ValueType type = ValueType::kString;
  std::string description;
  /// Absent: the parameter is required.
  std::optional<Value> default_value;
  /// For strings: the allowed values, when the set is fixed.
  std::vector<std::string> choices;
  /// For numbers: the allowed range.
  std::optional<double> min;
  std::optional<double> max;
  /// For strings whose allowed values come from what the system knows at run time
  /// ("waypoint", "object_class", "predicate", "frame"): the editor offers that list.
  std::string choices_from;
  /// Values offered besides the `choices_from` list (e.g. "table" for a place, which is not a
  /// frame): the editor adds them to its list.
  std::vector<std::string> extra_choices;
  /// Parameters that cannot be given together with this one: the editor clears them when
  /// this one is set (SmartRelease's target and target_class).
  std::vector<std::string> excludes;
  /// For numbers: the name of another number of the same operation that this one must stay
  /// below (PressAndFollow's force below its max_force). Kept in stored descriptions, so that
  /// every validator checks it (OperationSpec::checkParams).
  std::string less_than;
  /// Further checks of a written value (e.g. its syntax): empty when valid, else the problem.
  std::function<std::string(std::string_view)> validate;

  /// Checks a written value: empty when valid, else the problem.
  std::string check(std::string_view text) const;
};

using ParamMap = std::map<std::string, Value, std::less<>>;

nlohmann::json toJson(const ParamMap& params);
/// Parses `json` against `specs`; unknown names and type mismatches throw
/// std::invalid_argument. Missing parameters get their defaults.
ParamMap paramsFromJson(const std::vector<ParamSpec>& specs, const nlohmann::json& json);
nlohmann::json toJson(const ParamSpec& spec);

}  // namespace costar::component
