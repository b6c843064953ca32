#include "workcell/cell_simulation.h"

#include "core/paths.h"
#include "tool/power_tool.h"
#include "workcell/grippers.h"

namespace costar::workcell {

CellSimulation cellSimulation(const std::string& name) {
  return cellSimulation(loadSimCellDescription(simCellFile(name)));
}

CellSimulation cellSimulation(const SimCellDescription& cell) {
  CellSimulation result{cell, arm::loadRobotDescription(arm::robotDescriptionFile(cell.robot)), {}};
  const GripperModel& gripper = gripperModel(cell.gripper);
  sim::SimulationOptions& options = result.options;
  options.robot = result.robot;
  options.cell_model = cell.cell_model;
  options.gripper_model = dataRoot() / gripper.mjcf;
  options.adaptive_gripper = gripper.adaptive;
  options.robot_base = cell.robot_base;
  if (cell.power_tool) {
    options.power_tool = sim::PowerToolSetup{tool::loadPowerToolDescription(tool::powerToolFile(cell.power_tool->tool)),
                                             cell.power_tool->stand};
  }
  return result;
}

}  // namespace costar::workcell
