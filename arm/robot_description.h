#pragma once
// A robot arm as data: one JSON file per robot (robots/NAME/NAME.json) says what the rest of
// costar needs to know about it, so that no code names a particular robot's joints or links.
// Its format is "costar-robot-description/1" (robots/README.md): robots/generate_models.py makes
// the arm's MJCF and URDF from it at build time, and the runtime reads the fields it needs:
// name, type (the arm component's type, "UR5"), label, kinematics ({"solver": KEY}: KEY picks the
// Kinematics class in makeKinematics(): "ur", "srs" or "chain", each taking its geometry from the
// joints), joints[] (name, label, limits in degrees), home_deg, base_link, tool.name (the flange,
// where the workcell mounts its gripper) and gripper_links (links that may touch a part being
// grasped). The models are the generated ones (build tree, $COSTAR_GENERATED_DIR to override),
// and a file edited after the build is refused (its fingerprint). Where the arm stands and which
// gripper it carries belong to the workcell (workcells/NAME.json). Unknown fields are refused
// (a typing error is more likely than a field meant to be ignored); "notes" is free text.

#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "arm/joints.h"
#include "arm/kinematics.h"
#include "world/pose.h"

namespace costar::arm {

struct RobotDescription {
  std::filesystem::path file;  // where it was read from (for messages)
  std::string name;
  std::string type;
  std::string label;
  /// The kinematics solver's key and its parameters (numbers lists by name).
  std::string solver;
  std::map<std::string, std::vector<double>> solver_parameters;
  std::filesystem::path mjcf;  // absolute
  std::filesystem::path urdf;  // absolute
  std::string urdf_base_link;
  std::string urdf_tool_link;
  std::vector<std::string> joint_names;
  std::vector<std::string> joint_labels;
  JointLimits limits;
  JointVector home;
  std::string base_link;
  std::string first_moving_link;
  std::vector<std::string> gripper_links;

  int jointCount() const { return static_cast<int>(joint_names.size()); }
};

/// Reads a robot description. Throws std::runtime_error "robot description 'FILE': FIELD:
/// PROBLEM" for a missing or unreadable file, bad JSON (with its line and column), a format
/// other than costar-robot-description/1, a missing, unknown or ill-typed field, a joint count
/// outside 1..kMaxJoints, limits that are not intervals, a home outside the limits, models not
/// generated, or a file edited after its models were generated.
RobotDescription loadRobotDescription(const std::filesystem::path& file);

/// The description file of a robot by name: DATA_ROOT/robots/NAME/NAME.json.
std::filesystem::path robotDescriptionFile(const std::string& name, const std::filesystem::path& data_root = {});

/// The kinematics the description names (its "kinematics.solver"), built from its parameters
/// and joint limits. One row per solver in a table (arm/kinematics_factory.cpp): a new arm
/// family adds its class and a row. Throws std::runtime_error naming the file, the field and
/// the known solvers for an unknown solver, or the solver's problem with its parameters.
std::shared_ptr<const Kinematics> makeKinematics(const RobotDescription& robot);

/// The solvers makeKinematics() knows, sorted.
std::vector<std::string> kinematicsSolvers();

}  // namespace costar::arm
