#pragma once
// A power tool (an orbital sander or polisher) as a CoSTAR component implementing the abstract
// PowerTool (the paper's component): it is switched on and off, reads whether a gripper holds
// it and whether it sits on its stand, and how fast it runs. Its driver is behind
// tool/power_tool_driver.h (the simulator's, or a real tool's I/O lines).
//
// Operations: ToolOn(speed) (only with the tool in the gripper; waits until it runs at the
// speed), ToolOff (waits until it has stopped). Predicates: tool_on (its power is on), tool_held,
// tool_docked, tool_in_position (held or docked: a plan can go and get it), tool_at_speed (on
// and within 5 % of its speed). Symbols: tool_speed (per minute); while it sits on its stand,
// a frame for the tool (`object_name`, at the stand) with is_a(object_name, class), so that
// SmartGrasp can pick it up with a taught grasp (data/grasps.json).
// Safety: the component switches the tool off as soon as it reads it out of the gripper (at
// every report, i.e. every tick).

#include <optional>
#include <string>

#include "component/operation_table.h"
#include "core/clock.h"
#include "tool/power_tool_description.h"
#include "tool/power_tool_driver.h"
#include "world/pose.h"

namespace costar::tool {

struct PowerToolOptions {
  std::string name = "tool";
  /// Where the tool's frame is while it sits on its stand (world); absent: no frame reported.
  std::optional<world::Pose> docked_pose;
  /// The tool's name as an object and its class (the description's name).
  std::string object_name = "power_tool";
  /// ToolOn and ToolOff fail when the tool is not at speed (or stopped) after this long.
  Duration timeout = std::chrono::seconds(3);
  /// A reading older than this (by the driver's stamp) means the driver stopped updating.
  Duration reading_timeout = std::chrono::milliseconds(50);
};

class PowerTool final : public component::TableComponent {
 public:
  /// The driver and clock must outlive the component.
  PowerTool(PowerToolDriver& driver, const Clock& clock, PowerToolDescription tool, PowerToolOptions options = {});
  world::Report report() const override;

  /// The driver's reading, checked: finite and fresh. @throws std::runtime_error naming the problem.
  PowerToolReading checkedRead() const;
  /// Within this fraction of the speed asked for: at speed.
  static constexpr double kAtSpeed = 0.05;

 private:
  std::unique_ptr<component::RunningOperation> toolOn(double speed);
  std::unique_ptr<component::RunningOperation> toolOff();

  PowerToolDriver& driver_;
  const Clock& clock_;
  PowerToolDescription tool_;
  PowerToolOptions options_;
  mutable double commanded_ = 0.0;  // the speed asked for (0: off); the interlock in report() clears it
};

}  // namespace costar::tool
