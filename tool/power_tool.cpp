#include "tool/power_tool.h"

#include <cmath>
#include <cstdio>
#include <stdexcept>

#include <spdlog/spdlog.h>

namespace costar::tool {

using component::OperationResult;
using component::ParamSpec;
using component::ValueType;

namespace {

std::string perMinute(double speed, const std::string& unit) {
  char text[64];
  std::snprintf(text, sizeof text, "%.0f %s", speed, unit.c_str());
  return text;
}

/// Waits until the tool runs at (or has stopped from) its commanded speed.
class SpeedChange final : public component::RunningOperation {
 public:
  SpeedChange(const PowerTool& tool, PowerToolDriver& driver, const Clock& clock, bool on, double speed,
              Duration timeout, std::string unit)
      : tool_(tool),
        driver_(driver),
        clock_(clock),
        on_(on),
        speed_(speed),
        deadline_(clock.now() + timeout),
        unit_(std::move(unit)) {}

  OperationResult poll() override {
    PowerToolReading reading;
    try {
      reading = tool_.checkedRead();
    } catch (const std::exception& e) {
      driver_.command(false, 0.0);
      return OperationResult::failure(std::string(e.what()) + "; the tool was switched off");
    }
    const char* what = on_ ? "ToolOn" : "ToolOff";
    if (on_ && !reading.held) {
      driver_.command(false, 0.0);
      return OperationResult::failure("ToolOn: the tool left the gripper while it started; it was switched off");
    }
    const bool done = on_ ? reading.powered && std::abs(reading.speed - speed_) <= PowerTool::kAtSpeed * speed_
                          : !reading.powered && reading.speed <= PowerTool::kAtSpeed * speed_;
    if (done) {
      return OperationResult::success({{"speed", reading.speed}});
    }
    if (clock_.now() > deadline_) {
      return OperationResult::failure(std::string(what) + ": the tool runs at " + perMinute(reading.speed, unit_) +
                                      ", not " + perMinute(on_ ? speed_ : 0.0, unit_) + ", after the time allowed");
    }
    return OperationResult::running();
  }
  void cancel() override {
    if (on_) {
      driver_.command(false, 0.0);
    }
  }

 private:
  const PowerTool& tool_;
  PowerToolDriver& driver_;
  const Clock& clock_;
  bool on_;
  double speed_;
  TimePoint deadline_;
  std::string unit_;
};

}  // namespace

PowerTool::PowerTool(PowerToolDriver& driver, const Clock& clock, PowerToolDescription tool, PowerToolOptions options)
    : driver_(driver), clock_(clock), tool_(std::move(tool)), options_(std::move(options)) {
  component::ComponentDescription description;
  description.name = options_.name;
  description.type = "PowerTool(" + tool_.name + ")";
  description.implements = {"PowerTool"};
  description.inputs = {"tool_state"};
  description.outputs = {"tool_power", "tool_speed_setpoint"};
  ParamSpec speed{"speed", ValueType::kDouble, "how fast it runs (" + tool_.speed_unit + ", " + tool_.label + ")",
                  tool_.default_speed};
  speed.min = tool_.min_speed;
  speed.max = tool_.max_speed;
  component::OperationTable operations;
  operations.add({"ToolOn", "Switches the tool in the gripper on and waits until it runs at the speed.", {speed}},
                 [this](const component::ParamMap& params) { return toolOn(params.at("speed").asDouble()); });
  operations.add({"ToolOff", "Switches the tool off and waits until it has stopped.", {}},
                 [this](const component::ParamMap&) { return toolOff(); });
  description.symbols = {{"tool_speed", world::SymbolKind::kNumber, "how fast the tool runs now"}};
  if (options_.docked_pose) {
    description.symbols.push_back(
        {options_.object_name, world::SymbolKind::kFrame, "the tool (its pad's centre), while it sits on its stand"});
  }
  description.predicates = {
      {"tool_on", 0, "the tool's power is on"},
      {"tool_held", 0, "the gripper holds the tool (the knob's presence switch)"},
      {"tool_docked", 0, "the tool sits on its stand"},
      {"tool_in_position", 0, "the tool is in the gripper or on its stand"},
      {"tool_at_speed", 0, "the tool is on and runs within 5 % of its speed"},
      {"is_a", 2, "is_a(o, class): o is an object of the class"},
  };
  declare(std::move(description), std::move(operations));
}

PowerToolReading PowerTool::checkedRead() const {
  const PowerToolReading reading = driver_.read();
  if (!std::isfinite(reading.speed)) {
    throw std::runtime_error("power tool driver: the speed reading is not a number");
  }
  if (reading.stamp != TimePoint{} && clock_.now() - reading.stamp > options_.reading_timeout) {
    char text[96];
    std::snprintf(text, sizeof text, "power tool driver: the reading stopped updating (%.3f s old)",
                  toSeconds(clock_.now() - reading.stamp));
    throw std::runtime_error(text);
  }
  return reading;
}

std::unique_ptr<component::RunningOperation> PowerTool::toolOn(double speed) {
  const PowerToolReading reading = checkedRead();
  if (!reading.held) {
    return std::make_unique<component::FinishedOperation>(
        OperationResult::failure(std::string("ToolOn: the tool is not in the gripper") +
                                 (reading.docked ? " (it is on its stand: pick it up first)" : " (nor on its stand)")));
  }
  commanded_ = speed;
  driver_.command(true, speed);
  return std::make_unique<SpeedChange>(*this, driver_, clock_, true, speed, options_.timeout, tool_.speed_unit);
}

std::unique_ptr<component::RunningOperation> PowerTool::toolOff() {
  const double was = commanded_ > 0.0 ? commanded_ : tool_.default_speed;
  commanded_ = 0.0;
  driver_.command(false, 0.0);
  return std::make_unique<SpeedChange>(*this, driver_, clock_, false, was, options_.timeout, tool_.speed_unit);
}

world::Report PowerTool::report() const {
  PowerToolReading reading = checkedRead();
  if (reading.powered && !reading.held) {
    // The interlock: a running tool out of the gripper is switched off at once.
    driver_.command(false, 0.0);
    commanded_ = 0.0;
    spdlog::warn("power tool '{}': out of the gripper while on: switched off", options_.name);
    reading = checkedRead();
  }
  world::Report report;
  const TimePoint now = clock_.now();
  report.symbols.push_back({"tool_speed", "", now, world::NumberValue{reading.speed, tool_.speed_unit}});
  const auto fact = [&report](const char* name, bool value) {
    if (value) {
      report.predicates.push_back({name, {}, true, ""});
    }
  };
  fact("tool_on", reading.powered);
  fact("tool_held", reading.held);
  fact("tool_docked", reading.docked);
  fact("tool_in_position", reading.held || reading.docked);
  fact("tool_at_speed",
       reading.powered && commanded_ > 0.0 && std::abs(reading.speed - commanded_) <= kAtSpeed * commanded_);
  if (options_.docked_pose && reading.docked && !reading.held) {
    report.symbols.push_back({options_.object_name, "", now, world::FrameValue{"world", *options_.docked_pose}});
    report.predicates.push_back({"is_a", {options_.object_name, tool_.name}, true, ""});
  }
  return report;
}

}  // namespace costar::tool
