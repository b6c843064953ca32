#include "gripper/parallel_gripper.h"

#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace costar::gripper {

using component::OperationResult;
using component::ParamSpec;
using component::ValueType;

namespace {

std::string millimetres(double metres) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f mm", metres * 1000.0);
  return text;
}

/// Why a finger reading cannot be trusted, or empty.
std::string problemWith(const FingerReading& reading, TimePoint now, Duration timeout) {
  if (!std::isfinite(reading.opening) || !std::isfinite(reading.opening_speed) || !std::isfinite(reading.force)) {
    return "gripper driver: the finger reading is not a number";
  }
  if (reading.stamp != TimePoint{} && now - reading.stamp > timeout) {
    char text[96];
    std::snprintf(text, sizeof text, "gripper driver: the finger reading stopped updating (%.3f s old)",
                  toSeconds(now - reading.stamp));
    return text;
  }
  return {};
}

/// Moves the fingers and waits until they settle: at the target, or stopped on something.
class FingerMotion final : public component::RunningOperation {
 public:
  FingerMotion(const ParallelGripper& gripper, GripperDriver& driver, const Clock& clock, double target, double speed,
               double force, Duration timeout, bool closing)
      : gripper_(gripper),
        driver_(driver),
        clock_(clock),
        target_(target),
        closing_(closing),
        start_(clock.now()),
        deadline_(start_ + timeout) {
    driver_.command(target, speed, force);
  }

  OperationResult poll() override {
    FingerReading reading;
    try {
      reading = gripper_.checkedRead();
    } catch (const std::exception& e) {
      cancel();
      return OperationResult::failure(e.what() + std::string("; the fingers were stopped"));
    }
    const TimePoint now = clock_.now();
    const bool still = std::abs(reading.opening_speed) < 0.002;
    // Settled once still for 50 ms, and not before the fingers had time to start moving.
    if (still && now - start_ > std::chrono::milliseconds(60)) {
      if (!still_since_) {
        still_since_ = now;
      }
    } else {
      still_since_.reset();
    }
    const bool settled = still_since_ && now - *still_since_ >= std::chrono::milliseconds(50);
    if (settled || std::abs(reading.opening - target_) < 0.0005) {
      // Opening (or narrowing to an opening): blocked when they stopped short of it.
      if (!closing_ && std::abs(reading.opening - target_) > ParallelGripper::kOpenMargin) {
        const bool fully = target_ >= driver_.maxOpening() - ParallelGripper::kOpenMargin;
        return OperationResult::failure(
            "the fingers are blocked at " + millimetres(reading.opening) +
            (fully ? std::string(": they could not open fully") : ": they could not reach " + millimetres(target_)));
      }
      const bool holding = closing_ && reading.opening > ParallelGripper::kClosedBelow;
      return OperationResult::success({{"opening", reading.opening}, {"holding", holding}});
    }
    if (now >= deadline_) {
      return OperationResult::failure(std::string("the fingers did not settle within the time limit (at ") +
                                      millimetres(reading.opening) + ")");
    }
    return OperationResult::running();
  }

  void cancel() override {
    // Stop where the fingers are; without a reading to trust, keep the last command.
    FingerReading reading;
    try {
      reading = gripper_.checkedRead();
    } catch (const std::exception&) {
      return;
    }
    driver_.command(reading.opening, 0.1, reading.force > 0 ? reading.force : 10.0);
  }

 private:
  const ParallelGripper& gripper_;
  GripperDriver& driver_;
  const Clock& clock_;
  double target_;
  bool closing_;
  TimePoint start_;
  TimePoint deadline_;
  std::optional<TimePoint> still_since_;
};

}  // namespace

ParallelGripper::ParallelGripper(GripperDriver& driver, const Clock& clock, ParallelGripperOptions options)
    : driver_(driver), clock_(clock), options_(std::move(options)) {
  component::ComponentDescription description;
  description.name = options_.name;
  description.type = "ParallelGripper2F";
  description.implements = {"Gripper"};
  description.inputs = {"finger_state"};
  description.outputs = {"finger_command"};
  ParamSpec speed{"speed", ValueType::kDouble, "finger speed (m/s)", options_.speed};
  speed.min = 0.01;
  speed.max = 0.15;
  ParamSpec force{"force", ValueType::kDouble, "grip force (N)", options_.force};
  force.min = 5.0;
  force.max = options_.max_force;
  ParamSpec opening{"opening", ValueType::kDouble, "how far apart the fingers go (m); fully open by default",
                    driver_.maxOpening()};
  opening.min = 0.005;
  opening.max = driver_.maxOpening();
  ParamSpec mode{"mode", ValueType::kString, "basic, pinch, wide or scissor (only pinch here)", std::string("pinch")};
  mode.choices = {"basic", "pinch", "wide", "scissor"};
  using Params = component::ParamMap;
  // Modes: Pinch is the only one; the others fail with the reason.
  const auto mode_change = [](const std::string& what, bool pinch) -> std::unique_ptr<component::RunningOperation> {
    return std::make_unique<component::FinishedOperation>(
        pinch ? OperationResult::success()
              : OperationResult::failure(
                    what + ": mode not supported by this gripper (a parallel 2-finger gripper has only Pinch mode)"));
  };
  component::OperationTable operations;
  operations.add({"Open", "Opens the fingers fully, or as far as `opening`.", {speed, opening}},
                 [this](const Params& params) -> std::unique_ptr<component::RunningOperation> {
                   return std::make_unique<FingerMotion>(*this, driver_, clock_, params.at("opening").asDouble(),
                                                         params.at("speed").asDouble(), options_.force,
                                                         options_.timeout, false);
                 });
  operations.add({"Close", "Closes the fingers until they stop on a part or close fully.", {speed, force}},
                 [this](const Params& params) -> std::unique_ptr<component::RunningOperation> {
                   return std::make_unique<FingerMotion>(*this, driver_, clock_, 0.0, params.at("speed").asDouble(),
                                                         params.at("force").asDouble(), options_.timeout, true);
                 });
  // Check (plan validation) refuses them before a run, with the same reason (the node's type
  // leads the message already).
  const std::string only_pinch = "a parallel 2-finger gripper has only Pinch mode (this cell's gripper)";
  operations.add({"BasicMode",
                  "Selects Basic mode (3-finger grippers only).",
                  {},
                  component::OperationKind::kRobotAction,
                  [only_pinch](const Params&) { return only_pinch; }},
                 [mode_change](const Params&) { return mode_change("BasicMode", false); });
  operations.add({"PinchMode", "Selects Pinch mode, the only mode of a parallel gripper.", {}},
                 [mode_change](const Params&) { return mode_change("PinchMode", true); });
  operations.add({"WideMode",
                  "Selects Wide mode (3-finger grippers only).",
                  {},
                  component::OperationKind::kRobotAction,
                  [only_pinch](const Params&) { return only_pinch; }},
                 [mode_change](const Params&) { return mode_change("WideMode", false); });
  operations.add({"ScissorMode",
                  "Selects Scissor mode (3-finger grippers only).",
                  {},
                  component::OperationKind::kRobotAction,
                  [only_pinch](const Params&) { return only_pinch; }},
                 [mode_change](const Params&) { return mode_change("ScissorMode", false); });
  operations.add({"SetMode",
                  "Selects a mode by name: pinch, the only mode of a parallel gripper.",
                  {mode},
                  component::OperationKind::kRobotAction,
                  [only_pinch](const Params& params) {
                    const std::string chosen = params.at("mode").asString();
                    return chosen == "pinch" ? std::string() : "mode '" + chosen + "': " + only_pinch;
                  }},
                 [mode_change](const Params& params) {
                   const std::string chosen = params.at("mode").asString();
                   return mode_change("SetMode(" + chosen + ")", chosen == "pinch");
                 });
  description.symbols = {{"gripper_fingers", world::SymbolKind::kJoints, "the fingers' reading: their opening (m)"}};
  description.predicates = {{"gripper_open", 0, "the fingers are fully open"},
                            {"gripper_closed", 0, "the fingers are fully closed, nothing between them"},
                            {"gripper_holding", 0, "the fingers stopped on something and squeeze it"},
                            {"gripper_mode", 1, "gripper_mode(m): the gripper is in mode m"}};
  declare(std::move(description), std::move(operations));
}

FingerReading ParallelGripper::checkedRead() const {
  const FingerReading reading = driver_.read();
  if (const std::string problem = problemWith(reading, clock_.now(), options_.reading_timeout); !problem.empty()) {
    throw std::runtime_error(problem);
  }
  return reading;
}

world::Report ParallelGripper::report() const {
  // A reading that cannot be trusted makes the report throw: the registry then stops the cell.
  const FingerReading reading = checkedRead();
  world::Report report;
  report.symbols.push_back(
      {"gripper_fingers", "", clock_.now(), world::JointsValue{{"opening"}, {reading.opening}}, std::nullopt});
  if (reading.opening >= driver_.maxOpening() - kOpenMargin) {
    report.predicates.push_back({"gripper_open", {}, true, ""});
  }
  if (reading.opening <= kClosedBelow) {
    report.predicates.push_back({"gripper_closed", {}, true, ""});
  }
  if (std::abs(reading.opening_speed) < kHoldingSpeed && reading.contact && reading.force > kHoldingForce &&
      reading.opening > kClosedBelow) {
    report.predicates.push_back({"gripper_holding", {}, true, ""});
  }
  report.predicates.push_back({"gripper_mode", {"pinch"}, true, ""});
  return report;
}

}  // namespace costar::gripper
