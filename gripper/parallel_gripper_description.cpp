#include "gripper/parallel_gripper_description.h"

#include <cmath>
#include <nlohmann/json.hpp>

#include "gripper/description_fields.h"

namespace costar::gripper {

namespace {

constexpr double kLargestPart = 1.0;  // m: a hand is well under a metre across

FingerBox box(const detail::Fields& fields, const nlohmann::json& object, const std::string& field) {
  FingerBox box;
  box.size = fields.vec3(object, "size", field);
  box.centre = fields.vec3(object, "centre", field);
  if ((box.size.array() <= 0.0).any()) {
    fields.fail(field + ".size", "must be 3 positive lengths (m)");
  }
  if (box.centre.y() - box.size.y() / 2 < -1e-9) {
    fields.fail(field, "the +y finger's box must lie at y >= 0 when closed (its mirror is the other finger)");
  }
  return box;
}

}  // namespace

ParallelGripperDescription loadParallelGripperDescription(const std::filesystem::path& file) {
  const detail::Fields fields("gripper description '" + file.string() + "'");
  const nlohmann::json root = detail::readGripperDescription(file, fields, "parallel");
  ParallelGripperDescription description;
  description.name = root.at("name").get<std::string>();
  description.tcp = fields.vec3(root, "tcp", "");
  const auto& body = fields.at(root, "body", "");
  description.body_centre = fields.vec3(body, "centre", "body");
  description.body_size = fields.vec3(body, "size", "body");
  const auto& finger = fields.at(root, "finger", "");
  description.fingers.closed = {box(fields, fields.at(finger, "link", "finger"), "finger.link"),
                                box(fields, fields.at(finger, "pad", "finger"), "finger.pad")};
  const FingerBox& pad = description.fingers.closed[1];
  if (std::abs(pad.centre.y() - pad.size.y() / 2) > 1e-9) {
    fields.fail("finger.pad", "the closed pad's inner face must be on y = 0 (centre.y = size.y / 2)");
  }
  description.fingers.max_opening = fields.length(root, "stroke_m", "", 0.5);
  const auto& force = fields.at(root, "grip_force_n", "");
  description.default_force = fields.number(force, "default", "grip_force_n", 1000.0);
  description.max_force = fields.number(force, "max", "grip_force_n", 1000.0);
  if (!(description.default_force > 0.0)) {
    fields.fail("grip_force_n.default", "must be a force above 0 (N)");
  }
  if (description.default_force > description.max_force) {
    fields.fail("grip_force_n.default", "must be at most grip_force_n.max");
  }
  const auto& grasps = fields.at(root, "grasps", "");
  if (!grasps.is_string() || grasps.get<std::string>().empty()) {
    fields.fail("grasps", "must be the key of its grasps in data/grasps.json");
  }
  description.grasps = grasps.get<std::string>();
  return description;
}

}  // namespace costar::gripper
