#pragma once
// A power tool a gripper picks up (data/tools/NAME.json, format costar-power-tool/1): its shape
// (pad, motor housing, the knob a gripper holds), mass, speed range and stand. Read by the
// PowerTool component (its speed range, its shape as an object class for SmartMove), the
// simulator (its body, stand and pad) and the workcell.

#include <filesystem>
#include <string>

#include <Eigen/Core>

#include "world/object_class.h"

namespace costar::tool {

struct PowerToolDescription {
  std::filesystem::path file;
  std::string name;
  std::string label;
  std::string description;
  /// Tool frame: origin at the pad's working face's centre, z up through the knob.
  Eigen::Vector3d pad_size = Eigen::Vector3d::Zero();  // full sizes, m
  double pad_mass = 0.0;
  double pad_friction = 0.4;
  double body_radius = 0.0;
  double body_height = 0.0;
  double body_mass = 0.0;
  Eigen::Vector3d handle_size = Eigen::Vector3d::Zero();
  double handle_mass = 0.0;
  double min_speed = 0.0;  // orbits (or turns) per minute
  double max_speed = 0.0;
  double default_speed = 0.0;
  std::string speed_unit;
  double time_constant = 0.25;  // s, of the motor's speed
  double orbit_diameter = 0.0;  // m: how far the pad's centre swings
  Eigen::Vector3d stand_size = Eigen::Vector3d::Zero();
  double stand_rim_height = 0.0;

  double mass() const { return pad_mass + body_mass + handle_mass; }
  /// The knob's centre in the tool frame (where a gripper holds it).
  Eigen::Vector3d handleCentre() const;
  /// The tool's shape as an object class (pad, housing and knob as boxes; turning a quarter
  /// turn about z maps it onto itself), for SmartMove and the predicator.
  world::ObjectClass objectClass() const;
};

/// DATA_ROOT/data/tools/NAME.json.
std::filesystem::path powerToolFile(const std::string& name, const std::filesystem::path& data_root = {});

/// @throws std::runtime_error "power tool 'FILE': FIELD: PROBLEM" for a missing or unreadable
/// file, a key given twice, a missing or ill-typed field, a size that is not positive or beyond
/// half a metre, a mass beyond 20 kg, a speed range that is not 0 < min <= default <= max.
PowerToolDescription loadPowerToolDescription(const std::filesystem::path& file);

}  // namespace costar::tool
