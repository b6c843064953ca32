#pragma once
// The MuJoCo model of a simulated workcell, composed from pieces so that no cell is a copy of
// another: the cell (table, camera, lights: sim/models/table_cell.xml), the robot arm (its
// robot description's MJCF: hand-written for the UR5, generated for the LBR iiwa 14) and the
// gripper (e.g. parallel-2f_mount.xml, generated from robots/grippers/parallel-2f.json), mounted on the arm's flange.
//
// Each piece is an MJCF document (<mujoco>). Composition:
// - the robot's and the gripper's <default>, <asset>, <equality>, <contact>, <tendon>,
//   <actuator> and <sensor> children are appended to the cell's sections of the same name
//   (robot first, so that the robot's motors are the first actuators, in joint order);
// - the robot's <worldbody> children go to the cell's worldbody at its <!--ROBOT--> marker; a
//   robot base body without pos and quat (a generated model) is put at `robot_base`, one that
//   has them keeps them (Simulation checks that they agree with the workcell);
// - the children of the gripper's body "mount" become children of the robot's flange body;
// - a wrist force/torque sensor at the flange (force_torque_site): a site of that name at the
//   flange body's origin and a force and a torque sensor on it (sim/force_torque.h), which
//   read the interaction between the flange body (the gripper and what it touches) and its parent;
// - everything else in the robot's and gripper's documents (compiler, option, keyframe ...) is
//   the cell's business and is ignored.
// Textures and meshes are read from the cell model's folder. Element order is kept, so a model composed from the pieces
// of a former single file compiles to the same model.

#include <filesystem>
#include <optional>
#include <string>

#include "world/pose.h"

namespace costar::sim {

struct CellModelPieces {
  std::filesystem::path cell;
  std::filesystem::path robot;
  std::filesystem::path gripper;
  /// The robot's body the gripper is mounted on (its flange).
  std::string flange_body;
  /// Where the robot's base stands in the world (see above).
  std::optional<world::Pose> robot_base;
  /// The flange's force/torque site's name; empty: no sensor. Its sensors are named
  /// `force_sensor` and `torque_sensor`.
  std::string force_torque_site;
  std::string force_sensor;
  std::string torque_sensor;
};

/// The composed MJCF text. @throws std::runtime_error naming the file and the problem (a file
/// that cannot be read or parsed, no ROBOT marker, no flange body, no gripper mount body).
std::string composeCellModel(const CellModelPieces& pieces);

/// The physics time step a model's text sets (<option timestep>), MuJoCo's 0.002 s when it sets
/// none: what bodies added to it are made stable for (sim/wire_sim.h).
/// @throws std::runtime_error when the text is not XML or the value not a positive number.
double modelTimestep(const std::string& mjcf);

}  // namespace costar::sim
