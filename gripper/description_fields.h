#pragma once
// Typed access to a gripper description's JSON fields (robots/grippers/NAME.json), with errors
// that name the file, the field and the problem: the readers of both kinds of gripper share it.
// Internal to gripper/.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>

namespace costar::gripper::detail {

/// Typed access that names the field in its errors.
class Fields {
 public:
  explicit Fields(std::string label) : label_(std::move(label)) {}
  [[noreturn]] void fail(const std::string& field, const std::string& problem) const {
    throw std::runtime_error(label_ + ": " + field + ": " + problem);
  }
  const nlohmann::json& at(const nlohmann::json& object, const std::string& key, const std::string& field) const {
    if (!object.is_object() || !object.contains(key)) {
      fail(field.empty() ? key : field + "." + key, "missing");
    }
    return object.at(key);
  }
  /// A finite number of magnitude at most `at_most` (1e308 is a typing error).
  double number(const nlohmann::json& object, const std::string& key, const std::string& field,
                double at_most = 1e6) const {
    const auto& value = at(object, key, field);
    if (!value.is_number() || !std::isfinite(value.get<double>())) {
      fail(field.empty() ? key : field + "." + key, "must be a finite number");
    }
    if (std::abs(value.get<double>()) > at_most) {
      char problem[96];
      std::snprintf(problem, sizeof problem, "must be at most %g in magnitude, not %g", at_most, value.get<double>());
      fail(field.empty() ? key : field + "." + key, problem);
    }
    return value.get<double>();
  }
  /// A length (m) above 0 and at most `at_most`.
  double length(const nlohmann::json& object, const std::string& key, const std::string& field, double at_most) const {
    const double value = number(object, key, field, at_most);
    if (!(value > 0.0)) {
      char problem[96];
      std::snprintf(problem, sizeof problem, "must be a length above 0 and at most %g m, not %g", at_most, value);
      fail(field.empty() ? key : field + "." + key, problem);
    }
    return value;
  }
  /// 3 finite numbers, each of magnitude at most 1 (m: a hand is well under a metre across).
  Eigen::Vector3d vec3(const nlohmann::json& object, const std::string& key, const std::string& field) const {
    const auto& value = at(object, key, field);
    if (!value.is_array() || value.size() != 3 || !std::all_of(value.begin(), value.end(), [](const auto& x) {
          return x.is_number() && std::isfinite(x.template get<double>()) && std::abs(x.template get<double>()) <= 1.0;
        })) {
      fail(field.empty() ? key : field + "." + key, "must be 3 numbers from -1 to 1 (m)");
    }
    return {value[0].get<double>(), value[1].get<double>(), value[2].get<double>()};
  }

 private:
  std::string label_;
};

/// The description's JSON, checked to be of format costar-gripper-description/1 and of `kind`
/// ("parallel" or "adaptive-3f"). @throws std::runtime_error naming the file and the problem.
nlohmann::json readGripperDescription(const std::filesystem::path& file, const Fields& fields, const std::string& kind);

}  // namespace costar::gripper::detail
