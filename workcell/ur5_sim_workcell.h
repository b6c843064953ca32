#pragma once
// The simulated UR5 workcell: the embedded default robot. A MuJoCo simulation in lockstep with
// a SimClock, with the components a real cell would have on top of its drivers: the UR5 arm,
// the 2-finger gripper, and the workcell's fixed frames.

#include <memory>

#include "workcell/workcell.h"

namespace costar::workcell {

std::unique_ptr<Workcell> makeUr5SimWorkcell(const WorkcellOptions& options);

}  // namespace costar::workcell
