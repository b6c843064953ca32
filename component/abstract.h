#pragma once
// Abstract components (the paper, Sec. III-A): they name operations, symbols and predicates
// that every concrete component implementing them must provide. The abstract Arm requires
// Teach, Move and an `endpoint` symbol; UR5 and LBR iiwa arms implement them differently,
// so the same task plan runs on either.

#include <string>
#include <vector>

#include "component/component.h"

namespace costar::component {

struct AbstractComponent {
  std::string name;
  std::string description;
  std::vector<std::string> operations;
  std::vector<std::string> symbols;
  std::vector<std::string> predicates;
};

/// Arm: Teach, Move; symbol `endpoint`.
AbstractComponent abstractArm();
/// Gripper: Open, Close, BasicMode, PinchMode, WideMode, ScissorMode; predicates
/// gripper_open, gripper_closed, gripper_holding, gripper_mode.
AbstractComponent abstractGripper();
/// PowerTool (a sander, a polisher): ToolOn, ToolOff; predicate tool_on.
AbstractComponent abstractPowerTool();

/// What `description` lacks of `abstract`, one line each ("operation 'Teach'"); empty when
/// it provides everything.
std::vector<std::string> missingRequirements(const AbstractComponent& abstract,
                                             const ComponentDescription& description);

}  // namespace costar::component
