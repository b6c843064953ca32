#include "gripper/adaptive_gripper_description.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "core/files.h"
#include "core/json_file.h"
#include "core/paths.h"
#include "gripper/description_fields.h"

namespace costar::gripper {

std::string_view toString(GripperMode mode) {
  switch (mode) {
    case GripperMode::kBasic:
      return "basic";
    case GripperMode::kPinch:
      return "pinch";
    case GripperMode::kWide:
      return "wide";
    case GripperMode::kScissor:
      return "scissor";
  }
  return "unknown";
}

std::optional<GripperMode> modeFromString(std::string_view name) {
  for (const GripperMode mode : kGripperModes) {
    if (toString(mode) == name) {
      return mode;
    }
  }
  return std::nullopt;
}

AdaptiveGripperDescription loadAdaptiveGripperDescription(const std::filesystem::path& file) {
  const detail::Fields fields("gripper description '" + file.string() + "'");
  const nlohmann::json root = detail::readGripperDescription(file, fields, "adaptive-3f");
  AdaptiveGripperDescription description;
  description.name = root.at("name").get<std::string>();
  description.tcp = fields.vec3(root, "tcp", "");
  const auto& palm = fields.at(root, "palm", "");
  description.palm_centre = fields.vec3(palm, "centre", "palm");
  description.palm_size = fields.vec3(palm, "size", "palm");
  const auto& fingers = fields.at(root, "fingers", "");
  if (!fingers.is_array() || fingers.size() != kFingerCount) {
    fields.fail("fingers", "must be a list of " + std::to_string(kFingerCount) + " fingers");
  }
  for (std::size_t i = 0; i < kFingerCount; ++i) {
    const std::string field = "fingers[" + std::to_string(i) + "]";
    AdaptiveFingerPlacement& finger = description.fingers[i];
    finger.base = fields.vec3(fingers[i], "base", field);
    finger.yaw_deg = fields.number(fingers[i], "yaw_deg", field);
    finger.scissor_sign = static_cast<int>(fields.number(fingers[i], "scissor_sign", field));
  }
  const auto& phalanges = fields.at(root, "phalanges", "");
  if (!phalanges.is_array() || phalanges.empty()) {
    fields.fail("phalanges", "must be a non-empty list");
  }
  for (std::size_t i = 0; i < phalanges.size(); ++i) {
    const std::string field = "phalanges[" + std::to_string(i) + "]";
    constexpr double kLargestPhalanx = 0.5;  // m
    description.finger_length += fields.length(phalanges[i], "length", field, kLargestPhalanx);
    description.finger_width =
        std::max(description.finger_width, fields.length(phalanges[i], "width", field, kLargestPhalanx));
    description.finger_thickness =
        std::max(description.finger_thickness, fields.length(phalanges[i], "thickness", field, kLargestPhalanx));
  }
  description.open_lean_deg = std::max(0.0, -fields.number(phalanges[0], "lower_deg", "phalanges[0]"));
  description.proximal_upper_deg = fields.number(phalanges[0], "upper_deg", "phalanges[0]");
  const auto& actuation = fields.at(root, "actuation", "");
  description.max_force = fields.number(actuation, "max_force_n", "actuation");
  description.lever = fields.number(actuation, "lever_m", "actuation");
  description.min_force = fields.number(actuation, "min_force_n", "actuation");
  if (description.min_force <= 0 || description.min_force > fields.number(actuation, "max_force_n", "actuation")) {
    fields.fail("actuation.min_force_n", "must be positive and at most max_force_n");
  }
  if (description.max_force <= 0 || description.lever <= 0) {
    fields.fail("actuation", "max_force_n and lever_m must be positive");
  }
  description.scissor_lower_deg = fields.number(actuation, "scissor_lower_deg", "actuation");
  description.scissor_upper_deg = fields.number(actuation, "scissor_upper_deg", "actuation");
  description.scissor_speed_deg_s = fields.number(actuation, "scissor_speed_deg_s", "actuation");
  if (description.scissor_speed_deg_s <= 0) {
    fields.fail("actuation.scissor_speed_deg_s", "must be positive");
  }
  const auto& modes = fields.at(root, "modes", "");
  if (!modes.is_array()) {
    fields.fail("modes", "must be a list");
  }
  for (std::size_t i = 0; i < modes.size(); ++i) {
    const std::string field = "modes[" + std::to_string(i) + "]";
    AdaptiveModeDescription mode;
    const auto& mode_name = fields.at(modes[i], "name", field);
    const auto parsed = mode_name.is_string() ? modeFromString(mode_name.get<std::string>()) : std::nullopt;
    if (!parsed) {
      fields.fail(field + ".name", "must be one of basic, pinch, wide, scissor");
    }
    if (description.modes.count(*parsed) != 0) {
      fields.fail(field + ".name", "\"" + std::string(toString(*parsed)) + "\" appears twice");
    }
    mode.mode = *parsed;
    mode.description = modes[i].value("description", "");
    mode.scissor_deg = fields.number(modes[i], "scissor_deg", field);
    if (mode.scissor_deg < description.scissor_lower_deg || mode.scissor_deg > description.scissor_upper_deg) {
      fields.fail(field + ".scissor_deg", "must be within the scissor axis' limits");
    }
    mode.grasp_centre = fields.vec3(modes[i], "grasp_centre", field);
    if (modes[i].contains("fingertip")) {
      if (!modes[i]["fingertip"].is_boolean()) {
        fields.fail(field + ".fingertip", "must be true or false");
      }
      mode.fingertip = modes[i]["fingertip"].get<bool>();
    }
    const auto& closing = fields.at(modes[i], "closing", field);
    if (!closing.is_array() || closing.empty()) {
      fields.fail(field + ".closing", "must be a non-empty list of fingers");
    }
    for (std::size_t k = 0; k < closing.size(); ++k) {
      const auto it = closing[k].is_string()
                          ? std::find(kFingerNames.begin(), kFingerNames.end(), closing[k].get<std::string>())
                          : kFingerNames.end();
      if (it == kFingerNames.end()) {
        fields.fail(field + ".closing[" + std::to_string(k) + "]", "must be one of finger_middle, finger_1, finger_2");
      }
      mode.closing[static_cast<std::size_t>(it - kFingerNames.begin())] = true;
    }
    description.modes[mode.mode] = mode;
  }
  for (const GripperMode mode : kGripperModes) {
    if (description.modes.count(mode) == 0) {
      fields.fail("modes", "mode \"" + std::string(toString(mode)) + "\" is missing");
    }
  }
  return description;
}

std::vector<OrientedBox> openFingerBoxes(const AdaptiveGripperDescription& description, GripperMode mode) {
  return fingerBoxesAt(description, mode, 0.0);
}

std::vector<OrientedBox> fingerBoxesAt(const AdaptiveGripperDescription& description, GripperMode mode,
                                       double position) {
  constexpr double kDeg = M_PI / 180.0;
  constexpr double kKnuckle = 0.012;  // the knuckle's radius, behind the finger's base
  const AdaptiveModeDescription& mode_description = description.mode(mode);
  if (!(position >= 0.0 && position <= 1.0) || (position > 0.0 && !mode_description.fingertip)) {
    throw std::invalid_argument("finger boxes at " + std::to_string(position) + " in " + std::string(toString(mode)) +
                                " mode: only a fingertip mode's fingers are modelled closed part way (0 .. 1)");
  }
  const double scissor = mode_description.scissor_deg * kDeg;
  // The proximal joint from its lower limit (open, leaning out) toward its upper one; the
  // finger straight beyond it. Leaning out is a turn about the finger's +x axis.
  const double proximal_deg =
      -description.open_lean_deg + position * (description.proximal_upper_deg + description.open_lean_deg);
  std::vector<OrientedBox> boxes;
  for (const AdaptiveFingerPlacement& finger : description.fingers) {
    // Knuckle frame, turned on the scissor axis, then the open finger leaning out (away from
    // its +y, the side it closes toward: a turn about its -x axis by -lean).
    const Eigen::Isometry3d frame = Eigen::Translation3d(finger.base) *
                                    Eigen::AngleAxisd(finger.yaw_deg * kDeg, Eigen::Vector3d::UnitZ()) *
                                    Eigen::AngleAxisd(finger.scissor_sign * scissor, Eigen::Vector3d::UnitZ()) *
                                    Eigen::AngleAxisd(-proximal_deg * kDeg, Eigen::Vector3d::UnitX());
    OrientedBox box;
    const double length = description.finger_length + kKnuckle + 0.001;
    box.pose = frame * Eigen::Translation3d(0, 0, length / 2 - kKnuckle);
    box.size = Eigen::Vector3d(std::max(description.finger_width, 2 * kKnuckle), description.finger_thickness, length);
    boxes.push_back(box);
  }
  return boxes;
}

double fingertipClearance(const AdaptiveGripperDescription& description, GripperMode mode, double position) {
  const std::vector<OrientedBox> boxes = fingerBoxesAt(description, mode, position);
  const auto& closing = description.mode(mode).closing;
  double clear = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    if (!closing[i]) {
      continue;
    }
    // The box's corners at its far end (the fingertip): the nearest one to the axis, across.
    const Eigen::Vector3d half = boxes[i].size / 2;
    for (const double x : {-half.x(), half.x()}) {
      for (const double y : {-half.y(), half.y()}) {
        clear = std::min(clear, std::abs((boxes[i].pose * Eigen::Vector3d(x, y, half.z())).y()));
      }
    }
  }
  return clear;
}

double fingertipPositionFor(const AdaptiveGripperDescription& description, GripperMode mode, double half_width) {
  if (!description.mode(mode).fingertip) {
    return 0.0;
  }
  double best = 0.0;
  for (int step = 1; step <= 100; ++step) {
    const double position = step / 100.0;
    if (fingertipClearance(description, mode, position) < half_width) {
      break;
    }
    best = position;
  }
  return best;
}

double fingerReachAcross(const AdaptiveGripperDescription& description, GripperMode mode) {
  double reach = 0.0;
  // Open, and in a fingertip mode closed too (the only modes whose closed fingers are modelled).
  std::vector<double> positions{0.0};
  if (description.mode(mode).fingertip) {
    positions.push_back(1.0);
  }
  for (const double position : positions) {
    for (const OrientedBox& box : fingerBoxesAt(description, mode, position)) {
      // The box runs from the knuckle to past the tip along its longest side; the tip's face is
      // the end farther along the approach (the flange's z).
      int along = 0;
      box.size.maxCoeff(&along);
      const Eigen::Vector3d axis = box.pose.linear().col(along);
      const Eigen::Vector3d tip = box.pose.translation() + (axis.z() >= 0.0 ? 0.5 : -0.5) * box.size[along] * axis;
      double half = 0.0;
      for (int side = 0; side < 3; ++side) {
        if (side != along) {
          half += 0.5 * std::abs(box.pose.linear()(0, side)) * box.size[side];
        }
      }
      reach = std::max(reach, std::abs(tip.x()) + half);
    }
  }
  return reach;
}

}  // namespace costar::gripper
