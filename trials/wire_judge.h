#pragma once
// The wire-bending task's judge (examples/iiwa/wire_bending.xml), from the simulator's true
// state of the scene's jig and wire (sim/wire.h).

#include <vector>

#include "sim/simulation.h"
#include "trials/judge.h"

namespace costar::trials {

/// Succeeds when the gripper has let go of the wire, the wire is at rest, every bend of the
/// jig's drawing is within kWireBendTolerance of its angle in the table's plane and the wire
/// stayed flat there (the change in pitch across each bend within it too), the wire never came
/// out of fingers still told to close, and no pin was pushed out of its place.
Verdict wireBending(sim::Simulation& simulation, const std::vector<sim::PartState>& initial);

inline constexpr double kWireBendToleranceDeg = 5.0;
/// The wire counts as at rest below this (m/s): after the trial's settling time.
inline constexpr double kWireAtRestSpeed = 0.005;

}  // namespace costar::trials
