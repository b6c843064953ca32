#pragma once
// A simulated cell's simulation without the rest of the workcell: the robot of its description,
// the gripper on its flange, where it stands, the cell model around it (the camera, the table).
// For tools that drive the simulator directly with the cell's own arm and gripper in view
// (perception's training data and its evaluation, trials/perception_*.h); the workcell itself
// (workcell/sim_workcell.h) builds its simulation from the same options.

#include <string>

#include "arm/robot_description.h"
#include "sim/simulation.h"
#include "workcell/sim_cell_description.h"

namespace costar::workcell {

struct CellSimulation {
  SimCellDescription cell;
  arm::RobotDescription robot;
  /// robot, cell_model, gripper_model, adaptive_gripper, robot_base, power_tool set; the
  /// caller adds the seed, the initial arm and the like.
  sim::SimulationOptions options;
};

/// The simulation options of workcells/NAME.json. @throws std::runtime_error naming the file and
/// the field for an unknown cell, gripper or robot, or a description that cannot be read.
CellSimulation cellSimulation(const std::string& name);
CellSimulation cellSimulation(const SimCellDescription& cell);

}  // namespace costar::workcell
