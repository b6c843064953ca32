#pragma once
// Numbers on the command line, read strictly: the whole text a finite decimal number within the
// option's range ("0.05junk", "nan", "inf" and 1e400 are refused), and messages that print
// numbers short (%g, never 309 digits). Every numeric option of costar and fault_campaign uses
// these.

#include <CLI/CLI.hpp>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <utility>

namespace costar::cli {

/// The whole of `text` as a finite number (decimal or exponent notation), or nothing.
inline std::optional<double> parseNumber(std::string_view text) {
  double value = 0.0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size() || !std::isfinite(value)) {
    return std::nullopt;
  }
  return value;
}

/// A number printed short: %g.
inline std::string shortNumber(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", value);
  return text;
}

/// What a person typed, cut to 40 characters for a message.
inline std::string typed(std::string_view text) {
  return text.size() <= 40 ? std::string(text) : std::string(text.substr(0, 37)) + "...";
}

/// "a number above 0 s and at most 1e+06", the accepted forms in words.
inline std::string rangeText(double low, double high, bool low_open, const std::string& unit) {
  return std::string("a number ") + (low_open ? "above " : "from ") + shortNumber(low) + unit + " and at most " +
         shortNumber(high);
}

/// A validator for a number from `low` (excluded when `low_open`) to `high`; CLI11's own Range
/// lets nan through and its conversion takes "inf".
inline CLI::Validator numberIn(double low, double high, bool low_open = false, const std::string& unit = "") {
  const std::string description = rangeText(low, high, low_open, unit);
  return CLI::Validator(
      [low, high, low_open, description](std::string& text) -> std::string {
        const std::optional<double> value = parseNumber(text);
        if (!value || !(low_open ? *value > low : *value >= low) || !(*value <= high)) {
          return "must be " + description + ", not " + typed(text);
        }
        return {};
      },
      "NUMBER " + description);
}

/// A validator for a whole number from 0 to the largest `Unsigned` (a seed): CLI11 would read
/// "-1" as the largest and let 2^64 wrap around.
template <typename Unsigned = std::uint64_t>
CLI::Validator wholeNumber() {
  const std::string description = "a whole number from 0 to " + std::to_string(std::numeric_limits<Unsigned>::max());
  return CLI::Validator(
      [description](std::string& text) -> std::string {
        Unsigned value = 0;
        const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
        if (text.empty() || error != std::errc() || end != text.data() + text.size()) {
          return "must be " + description + ", not " + typed(text);
        }
        return {};
      },
      "SEED");
}

/// --camera-move "DISTANCE_M,ANGLE_DEG" (or "DISTANCE_M": no turn), from 0 to 0.5 m and 45 degrees.
/// @throws CLI::ValidationError naming the option and the accepted forms.
inline std::pair<double, double> parseCameraMove(const std::string& text) {
  const auto comma = text.find(',');
  const std::optional<double> distance = parseNumber(std::string_view(text).substr(0, comma));
  const std::optional<double> angle =
      comma == std::string::npos ? std::optional<double>(0.0) : parseNumber(std::string_view(text).substr(comma + 1));
  if (!distance || !angle || *distance < 0 || *distance > 0.5 || *angle < 0 || *angle > 45) {
    throw CLI::ValidationError("--camera-move", "'" + typed(text) +
                                                    "' should be DISTANCE_M,ANGLE_DEG, numbers from 0 to 0.5 m and "
                                                    "45 degrees (e.g. 0.05,5)");
  }
  return {*distance, *angle};
}

}  // namespace costar::cli
