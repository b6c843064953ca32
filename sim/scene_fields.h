#pragma once
// Reading a scene file's fields (sim/scene.h) with errors naming the field and the problem:
// "parts[2].count: must be a whole number from 1 to 100, not 0". Shared by the scene's parts
// and its jig and wire (sim/wire.h); the caller prefixes the file ("scene 'my.json': ...").
// Internal to sim/.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace costar::sim::fields {

using nlohmann::json;

/// A problem with one field: throws "FIELD: PROBLEM".
[[noreturn]] inline void fail(const std::string& field, const std::string& problem) {
  throw std::runtime_error(field + ": " + problem);
}

/// The value as the file has it, shortened: for "must be ..., not VALUE".
inline std::string shown(const json& value) {
  std::string text = value.dump();
  return text.size() <= 40 ? text : text.substr(0, 37) + "...";
}

/// Refuses a key of `object` that is not in `known`, listing the known ones.
inline void onlyKnownFields(const json& object, const std::string& field, std::initializer_list<const char*> known) {
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

inline const json& object(const json& value, const std::string& field) {
  if (!value.is_object()) {
    fail(field, "must be an object {...}, not " + shown(value));
  }
  return value;
}

inline std::string stringField(const json& value, const std::string& field) {
  if (!value.is_string()) {
    fail(field, "must be a string, not " + shown(value));
  }
  return value.get<std::string>();
}

inline double number(const json& value, const std::string& field) {
  // JSON has no nan; a number too large for a double is read as infinity.
  if (!value.is_number() || !std::isfinite(value.get<double>())) {
    fail(field, "must be a finite number, not " + shown(value));
  }
  return value.get<double>();
}

/// A number as a person writes it: 0.05, -175, 1e+07.
inline std::string written(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

/// A finite number in [low, high] (`unit` names it in the message: "m", "degrees").
inline double numberIn(const json& value, const std::string& field, double low, double high, const std::string& unit) {
  const double x = number(value, field);
  if (x < low || x > high) {
    fail(field, "must be from " + written(low) + " to " + written(high) + (unit.empty() ? "" : " " + unit) + ", not " +
                    shown(value));
  }
  return x;
}

/// A whole number in [low, high]; 4294967297 or 2.5 is an error, never truncated.
inline std::uint64_t whole(const json& value, const std::string& field, std::uint64_t low, std::uint64_t high) {
  const std::string range = "a whole number from " + std::to_string(low) + " to " + std::to_string(high);
  if (!value.is_number_unsigned() || value.get<std::uint64_t>() < low || value.get<std::uint64_t>() > high) {
    fail(field, "must be " + range + ", not " + shown(value));
  }
  return value.get<std::uint64_t>();
}

/// A list of `min_size` to `max_size` finite numbers; `what` says what the list is.
inline std::vector<double> numbers(const json& value, const std::string& field, std::size_t min_size,
                                   std::size_t max_size, const std::string& what) {
  if (!value.is_array() || value.size() < min_size || value.size() > max_size) {
    fail(field, "must be " + what + ", not " + shown(value));
  }
  std::vector<double> out;
  for (std::size_t i = 0; i < value.size(); ++i) {
    out.push_back(number(value[i], field + "[" + std::to_string(i) + "]"));
  }
  return out;
}

/// `object[key]`, which must be there; `example` says what it should hold.
inline const json& required(const json& object, const std::string& key, const std::string& field,
                            const std::string& example) {
  if (!object.contains(key)) {
    fail(field.empty() ? key : field + "." + key, "missing (" + example + ")");
  }
  return object.at(key);
}

}  // namespace costar::sim::fields
