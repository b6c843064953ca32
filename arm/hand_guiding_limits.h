#pragma once
// How hard a simulated person's hand may push and turn the tool in free-drive: the editor's drag
// (POST /api/drag) and `costar teach drag` refuse more, with the same limits. (Free-drive itself
// stops above ArmComponent::kMaxForceLimit measured on the wrist, whatever pushes.)

namespace costar::arm {

/// A firm push (N) and a firm twist (N m) of a hand on the tool.
inline constexpr double kMaxHandForce = 60.0;
inline constexpr double kMaxHandTorque = 3.0;

}  // namespace costar::arm
