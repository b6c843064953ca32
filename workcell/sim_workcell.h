#pragma once
// The simulated workcell, one generic cell built from a workcell description
// (workcells/NAME.json, workcell/sim_cell_description.h): a MuJoCo simulation in lockstep with
// a SimClock, with the components a real cell would have on top of its drivers: the arm of the
// robot description (its kinematics from the description's solver), the gripper the
// description names (workcell/grippers.h), the camera, perception, calibration, SmartMove, the
// predicator and the workcell's fixed frames. `ur5-sim` and `iiwa-sim` are two files, not two
// classes: a new arm needs a robot description, its kinematics class and a workcell file.

#include <memory>

#include "workcell/sim_cell_description.h"
#include "workcell/workcell.h"

namespace costar::workcell {

std::unique_ptr<Workcell> makeSimWorkcell(const SimCellDescription& cell, const WorkcellOptions& options);

}  // namespace costar::workcell
