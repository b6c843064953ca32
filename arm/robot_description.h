#pragma once
// A robot arm as data: one JSON file per robot (robots/NAME/NAME.json) says what the rest of
// costar needs to know about it, so that no code names a particular robot's joints or links.
// Two formats, told apart by the "format" field:
//
// 1. "format": "costar-robot-description/1" (robots/README.md; the LBR iiwa 14): the file
//    robots/generate_models.py makes the arm's MJCF and URDF from at build time, with the
//    fields only the runtime needs: type, label, kinematics, joints[].label,
//    joints[].acceleration_deg_s2 and gripper_links. Angles in degrees; the models are the
//    generated ones (build tree, $COSTAR_GENERATED_DIR to override); the flange is tool.name.
// 2. No "format" (the UR5, whose models are hand-written): the fields below, SI units.
//
//   name, type, label      the robot's id ("ur5"), its component type ("UR5"), a readable name
//   kinematics             {"solver": KEY, ...parameters}: KEY picks the Kinematics class in
//                          makeKinematics() (e.g. "ur": the UR closed form, with its DH table
//                          d, a, alpha; "srs": 7-joint S-R-S arms, geometry from the joints of
//                          a format-1 file); the other fields are that solver's numbers
//   models                 mjcf (MuJoCo model of the arm alone), urdf (the same chain for the
//                          planner), and the URDF's base link and flange link (urdf_tool_link,
//                          also the flange body in the MJCF, where a gripper is mounted); paths
//                          relative to the data root (core/paths.h)
//   joints                 [{name, label, min, max, max_velocity, max_acceleration}, ...], base
//                          first; name as in the models, label for people ("wrist 3")
//   home                   the home configuration, one angle per joint
//   tool                   optional: a fixed tool frame in the flange frame (an adapter plate):
//                          {position [x, y, z], orientation [w, x, y, z]}; the gripper's tool
//                          centre point is the workcell's (workcells/NAME.json)
//   links                  base (the link standing on the table), first_moving (the first link
//                          that moves: it and its children are the arm in the simulator's
//                          contacts), gripper (links that may touch a part being grasped)
//
// Units: m, rad, rad/s, rad/s^2. Unknown fields are refused (a typing error is more likely
// than a field meant to be ignored); "notes" is free text.

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
  world::Pose tool_in_flange = world::Pose::Identity();
  std::string base_link;
  std::string first_moving_link;
  std::vector<std::string> gripper_links;

  int jointCount() const { return static_cast<int>(joint_names.size()); }
};

/// Reads a robot description. Model paths are resolved against `data_root` (default:
/// dataRoot()). Throws std::runtime_error "robot description 'FILE': FIELD: PROBLEM" for a
/// missing or unreadable file, bad JSON (with its line and column), a missing, unknown or
/// ill-typed field, a joint count outside 1..kMaxJoints, limits that are not intervals, a home
/// outside the limits, or a model file that does not exist.
RobotDescription loadRobotDescription(const std::filesystem::path& file, const std::filesystem::path& data_root = {});

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
