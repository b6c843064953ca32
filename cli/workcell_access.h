#pragma once
// How a command of this executable gets its workcell. Two implementations, one per
// executable: costar-robot builds every cell (workcell_access_robot.cpp); the light costar
// builds the cells without a robot, and for a robot cell either reads its stored description
// (to validate or describe plans) or hands the command to costar-robot
// (workcell_access_light.cpp).

#include <memory>

#include "workcell/workcell.h"

namespace costar::cli {

enum class WorkcellUse {
  kRun,       // operations will run: the real cell
  kDescribe,  // node types only (validate, nodes): a description is enough
};

/// @throws std::exception with a message for the user (unknown workcell, unreadable file).
std::unique_ptr<workcell::Workcell> openWorkcellFor(const workcell::WorkcellOptions& options, WorkcellUse use);

}  // namespace costar::cli
