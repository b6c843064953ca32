#include "arm/motion_service.h"

#include <cmath>
#include <nlohmann/json.hpp>
#include <stdexcept>

namespace costar::arm {

std::string pathParam(const std::vector<JointVector>& path) {
  nlohmann::json json = nlohmann::json::array();
  for (const JointVector& q : path) {
    json.push_back(std::vector<double>(q.begin(), q.end()));
  }
  return json.dump();  // shortest text that reads back to the same doubles
}

std::vector<JointVector> pathFromParam(std::string_view text, int joint_count) {
  const nlohmann::json json = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (json.is_discarded() || !json.is_array()) {
    throw std::invalid_argument("the path is not a JSON array of joint configurations");
  }
  if (json.size() < 2) {
    throw std::invalid_argument("the path has " + std::to_string(json.size()) +
                                " point(s); it needs a start and a goal");
  }
  std::vector<JointVector> path;
  path.reserve(json.size());
  for (std::size_t i = 0; i < json.size(); ++i) {
    const nlohmann::json& point = json[i];
    const std::string where = "path point " + std::to_string(i + 1);
    if (!point.is_array() || static_cast<int>(point.size()) != joint_count) {
      throw std::invalid_argument(where + " is not a list of " + std::to_string(joint_count) + " angles");
    }
    JointVector q(joint_count);
    for (int j = 0; j < joint_count; ++j) {
      if (!point[j].is_number() || !std::isfinite(point[j].get<double>())) {
        throw std::invalid_argument(where + ": joint " + std::to_string(j + 1) + " is not a finite number");
      }
      q[j] = point[j].get<double>();
    }
    path.push_back(q);
  }
  return path;
}

component::ParamMap followParams(const MotionPlan& plan, const std::string& label) {
  return {{"path", pathParam(plan.path)}, {"speed", plan.speed}, {"label", label}};
}

}  // namespace costar::arm
