#pragma once
// What a power tool's hardware (an output line that switches it, an analog input that sets its
// speed, presence switches in its knob and its stand; or the simulator) offers the PowerTool
// component. A real tool on an I/O module replaces the simulated one behind this interface
// without touching plans.

#include "core/clock.h"

namespace costar::tool {

struct PowerToolReading {
  bool powered = false;  // the tool's power is switched on
  double speed = 0.0;    // what it turns (or orbits) at now, per minute
  bool held = false;     // the knob's presence switch: a gripper holds it
  bool docked = false;   // the stand's presence switch: it sits on its stand
  /// When it was measured; TimePoint{} from a driver that does not stamp its readings.
  TimePoint stamp{};
};

class PowerToolDriver {
 public:
  virtual ~PowerToolDriver() = default;
  virtual PowerToolReading read() const = 0;
  /// Switches the power on (at `speed` per minute) or off.
  virtual void command(bool on, double speed) = 0;
};

}  // namespace costar::tool
