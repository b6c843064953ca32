#pragma once
// How a command of this executable gets its workcell. Two implementations, one per
// executable: costar-robot builds every cell (workcell_access_robot.cpp); the light costar
// builds the cells without a robot, and for a robot cell either reads its stored description
// (to validate or describe plans) or hands the command to costar-robot
// (workcell_access_light.cpp).

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "workcell/workcell.h"

namespace costar::cli {

enum class WorkcellUse {
  kRun,       // operations will run: the real cell
  kDescribe,  // node types only (validate, nodes): a description is enough
};

/// @throws std::exception with a message for the user (unknown workcell, unreadable file).
std::unique_ptr<workcell::Workcell> openWorkcellFor(const workcell::WorkcellOptions& options, WorkcellUse use);

/// The fault injector for `--inject` specs (the light costar hands the command to costar-robot,
/// which links the injector). @throws std::invalid_argument for a bad spec.
std::shared_ptr<faults::Injector> makeFaultInjector(const std::vector<std::string>& specs, std::uint64_t seed);
/// What the injector did (which faults took effect, when), for the end of a run.
std::string faultSummary(const faults::Injector& injector);

}  // namespace costar::cli
