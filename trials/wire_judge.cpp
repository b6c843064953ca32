#include "trials/wire_judge.h"

#include <cmath>
#include <cstdio>
#include <string>

namespace costar::trials {

namespace {

std::string number(const char* format, double value) {
  char text[64];
  std::snprintf(text, sizeof text, format, value);
  return text;
}

}  // namespace

Verdict wireBending(sim::Simulation& simulation, const std::vector<sim::PartState>&) {
  const std::optional<sim::JigState> jig = simulation.jig();
  if (!jig || !jig->has_wire) {
    return {false,
            "the scene has no wire in a jig (a scene with \"jig\" and \"wire\", e.g. "
            "sim/scenes/wire_bending.json)"};
  }
  const sim::WireGrip& grip = jig->grip;
  if (grip.pulled_out > 0) {
    return {false, "the wire was pulled out of the gripper at " + number("%.1f", grip.pulled_out_at) + " s"};
  }
  if (grip.holds == 0) {
    return {false, "the gripper never held the wire"};
  }
  if (grip.holds > grip.releases) {
    return {false, "the gripper still holds the wire"};
  }
  for (const sim::PinState& pin : jig->pins) {
    if (pin.slipped > 0.0) {
      return {false, "pin " + pin.name + " was pushed " + number("%.1f", pin.slipped * 1000) +
                         " mm out of its place (with up to " + number("%.0f", pin.max_force) + " N)"};
    }
  }
  if (jig->wire_speed > kWireAtRestSpeed) {
    return {false, "the wire is still moving (" + number("%.0f", jig->wire_speed * 1000) + " mm/s)"};
  }
  std::string measured;
  for (std::size_t k = 0; k < jig->bends.size(); ++k) {
    const sim::MeasuredBend& bend = jig->bends[k];
    const std::string which = "bend " + std::to_string(k + 1);
    if (std::abs(bend.angle_deg - bend.target_deg) > kWireBendToleranceDeg) {
      return {false, which + " is " + number("%.1f", bend.angle_deg) + " degrees, the drawing's " +
                         number("%.0f", bend.target_deg) + " (within " + number("%.0f", kWireBendToleranceDeg) + ")"};
    }
    if (std::abs(bend.out_of_plane_deg) > kWireBendToleranceDeg) {
      return {false,
              which + " lifts the wire " + number("%.1f", bend.out_of_plane_deg) + " degrees out of the table's plane"};
    }
    measured += (measured.empty() ? "" : ", ") + number("%.1f", bend.angle_deg);
  }
  return {true, "bends " + measured + " degrees; the wire slid " + number("%.1f", grip.max_slip * 1000) +
                    " mm in the fingers"};
}

}  // namespace costar::trials
