#include "gripper/adaptive_gripper.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <stdexcept>

namespace costar::gripper {

using component::OperationResult;
using component::ParamSpec;
using component::ValueType;

namespace {

std::string problemWith(const AdaptiveGripperReading& reading, TimePoint now, Duration timeout) {
  for (std::size_t i = 0; i < reading.fingers.size(); ++i) {
    const auto& finger = reading.fingers[i];
    if (!std::isfinite(finger.position) || !std::isfinite(finger.speed) || !std::isfinite(finger.force)) {
      return "gripper driver: the reading of " + std::string(kFingerNames[i]) + " is not a number";
    }
  }
  if (reading.stamp != TimePoint{} && now - reading.stamp > timeout) {
    char text[96];
    std::snprintf(text, sizeof text, "gripper driver: the finger reading stopped updating (%.3f s old)",
                  toSeconds(now - reading.stamp));
    return text;
  }
  return {};
}

std::string percent(double position) {
  char text[16];
  std::snprintf(text, sizeof text, "%.0f %%", 100.0 * position);
  return text;
}

nlohmann::json fingersJson(const AdaptiveGripperReading& reading) {
  nlohmann::json fingers = nlohmann::json::object();
  for (std::size_t i = 0; i < reading.fingers.size(); ++i) {
    const auto& finger = reading.fingers[i];
    fingers[std::string(kFingerNames[i])] = {
        {"position", finger.position}, {"force", finger.force}, {"contact", finger.contact}};
  }
  return fingers;
}

/// Moves the fingers and waits until they settle: at their targets, or stopped on something.
class FingerMotion final : public component::RunningOperation {
 public:
  FingerMotion(const AdaptiveGripper& gripper, AdaptiveGripperDriver& driver, const Clock& clock,
               std::array<double, kFingerCount> targets, double speed, double force, Duration timeout, bool closing)
      : gripper_(gripper),
        driver_(driver),
        clock_(clock),
        targets_(targets),
        closing_(closing),
        start_(clock.now()),
        deadline_(start_ + timeout) {
    driver_.commandFingers(targets_, speed, force);
  }

  OperationResult poll() override {
    AdaptiveGripperReading reading;
    try {
      reading = gripper_.checkedRead();
    } catch (const std::exception& e) {
      cancel();
      return OperationResult::failure(e.what() + std::string("; the fingers were stopped"));
    }
    const TimePoint now = clock_.now();
    bool still = true;
    bool at_targets = true;
    for (std::size_t i = 0; i < reading.fingers.size(); ++i) {
      still = still && std::abs(reading.fingers[i].speed) < 0.02;
      at_targets = at_targets && std::abs(reading.fingers[i].position - targets_[i]) < 0.01;
    }
    // Settled once still for 60 ms, and not before the fingers had time to start moving.
    if (still && now - start_ > std::chrono::milliseconds(80)) {
      if (!still_since_) {
        still_since_ = now;
      }
    } else {
      still_since_.reset();
    }
    const bool settled = still_since_ && now - *still_since_ >= std::chrono::milliseconds(60);
    if (settled || at_targets) {
      nlohmann::json data = {{"fingers", fingersJson(reading)}};
      if (!closing_) {
        for (std::size_t i = 0; i < reading.fingers.size(); ++i) {
          if (reading.fingers[i].position > targets_[i] + AdaptiveGripper::kOpenBelow) {
            return OperationResult::failure(std::string(kFingerNames[i]) + " is blocked at " +
                                                percent(reading.fingers[i].position) + " closed: it could not open",
                                            data);
          }
        }
        return OperationResult::success(data);
      }
      data["holding"] = gripper_.holdingFingers(reading) >= 2;
      return OperationResult::success(data);
    }
    if (now >= deadline_) {
      return OperationResult::failure("the fingers did not settle within the time limit",
                                      {{"fingers", fingersJson(reading)}});
    }
    return OperationResult::running();
  }

  void cancel() override {
    // Stop where the fingers are; without a reading to trust, keep the last command.
    AdaptiveGripperReading reading;
    try {
      reading = gripper_.checkedRead();
    } catch (const std::exception&) {
      return;
    }
    std::array<double, kFingerCount> here{};
    double force = 10.0;
    for (std::size_t i = 0; i < reading.fingers.size(); ++i) {
      here[i] = reading.fingers[i].position;
      force = std::max(force, reading.fingers[i].force);
    }
    driver_.commandFingers(here, 1.0, force);
  }

 private:
  const AdaptiveGripper& gripper_;
  AdaptiveGripperDriver& driver_;
  const Clock& clock_;
  std::array<double, kFingerCount> targets_;
  bool closing_;
  TimePoint start_;
  TimePoint deadline_;
  std::optional<TimePoint> still_since_;
};

/// Turns the scissor axis to a mode and waits until it is there.
class ModeChange final : public component::RunningOperation {
 public:
  ModeChange(const AdaptiveGripper& gripper, AdaptiveGripperDriver& driver, const Clock& clock, GripperMode mode,
             Duration timeout)
      : gripper_(gripper), driver_(driver), mode_(mode), clock_(clock), deadline_(clock.now() + timeout) {
    driver_.commandMode(mode);
  }

  OperationResult poll() override {
    AdaptiveGripperReading reading;
    try {
      reading = gripper_.checkedRead();
    } catch (const std::exception& e) {
      return OperationResult::failure(e.what());
    }
    if (reading.mode == mode_ && reading.mode_reached) {
      return OperationResult::success({{"mode", std::string(toString(mode_))}});
    }
    if (clock_.now() >= deadline_) {
      return OperationResult::failure("the scissor axis did not reach " + std::string(toString(mode_)) +
                                      " mode within the time limit (something blocks fingers 1 and 2?)");
    }
    return OperationResult::running();
  }
  void cancel() override {}

 private:
  const AdaptiveGripper& gripper_;
  AdaptiveGripperDriver& driver_;
  GripperMode mode_;
  const Clock& clock_;
  TimePoint deadline_;
};

std::string capitalised(std::string_view text) {
  std::string out(text);
  if (!out.empty()) {
    out[0] = static_cast<char>(std::toupper(static_cast<unsigned char>(out[0])));
  }
  return out;
}

}  // namespace

AdaptiveGripper::AdaptiveGripper(AdaptiveGripperDriver& driver, const Clock& clock,
                                 AdaptiveGripperDescription description, AdaptiveGripperOptions options)
    : driver_(driver), clock_(clock), gripper_(std::move(description)), options_(std::move(options)) {
  component::ComponentDescription declared;
  declared.name = options_.name;
  declared.type = "AdaptiveGripper3F";
  declared.implements = {"Gripper"};
  declared.inputs = {"finger_state"};
  declared.outputs = {"finger_command", "mode_command"};
  ParamSpec speed{"speed", ValueType::kDouble, "finger speed (full strokes per second)", options_.speed};
  speed.min = 0.1;
  speed.max = 1.0;
  ParamSpec force{"force", ValueType::kDouble, "grip force per finger (N)", options_.force};
  force.min = gripper_.min_force;
  force.max = gripper_.max_force;
  ParamSpec mode{"mode", ValueType::kString, "basic, pinch, wide or scissor", std::string("basic")};
  for (const GripperMode m : kGripperModes) {
    mode.choices.emplace_back(toString(m));
  }
  // One table: each operation declared with its handler.
  component::OperationTable operations;
  ParamSpec position{"position", ValueType::kDouble,
                     "how far closed the mode's closing fingers stop (0: fully open; above 0 only in a fingertip "
                     "mode, whose fingers stay straight: Pinch)",
                     0.0};
  position.min = 0.0;
  position.max = 0.9;
  operations.add(
      {"Open", "Opens the fingers: fully, or to a position part way in a fingertip mode.", {speed, position}},
      [this](const component::ParamMap& params) -> std::unique_ptr<component::RunningOperation> {
        const double part_way = params.at("position").asDouble();
        std::array<double, kFingerCount> targets{};
        if (part_way > 0.0) {
          const AdaptiveGripperReading reading = checkedRead();
          const AdaptiveModeDescription& current = gripper_.mode(reading.mode);
          if (!current.fingertip) {
            throw std::invalid_argument("Open to " + percent(part_way) + " closed: only in a fingertip mode (pinch); " +
                                        "the gripper is in " + std::string(toString(reading.mode)) + " mode");
          }
          for (std::size_t i = 0; i < targets.size(); ++i) {
            targets[i] = current.closing[i] ? part_way : 0.0;
          }
        }
        return std::make_unique<FingerMotion>(*this, driver_, clock_, targets, params.at("speed").asDouble(),
                                              options_.force, options_.timeout, false);
      });
  operations.add(
      {"Close", "Closes the fingers of the current mode until each stops on the part or closes fully.", {speed, force}},
      [this](const component::ParamMap& params) -> std::unique_ptr<component::RunningOperation> {
        const AdaptiveGripperReading reading = checkedRead();
        const auto& closing = gripper_.mode(reading.mode).closing;
        std::array<double, kFingerCount> targets{};
        for (std::size_t i = 0; i < targets.size(); ++i) {
          targets[i] = closing[i] ? 1.0 : 0.0;
        }
        return std::make_unique<FingerMotion>(*this, driver_, clock_, targets, params.at("speed").asDouble(),
                                              params.at("force").asDouble(), options_.timeout, true);
      });
  operations.add({"SetMode", "Turns fingers 1 and 2 to a mode (the fingers must be open).", {mode}},
                 [this](const component::ParamMap& params) {
                   const auto chosen = modeFromString(params.at("mode").asString());
                   if (!chosen) {  // the choices make this unreachable through the registry; a direct caller may
                     throw std::invalid_argument("SetMode: unknown mode '" + params.at("mode").asString() +
                                                 "' (basic, pinch, wide or scissor)");
                   }
                   return setMode(*chosen);
                 });
  for (const GripperMode m : kGripperModes) {
    const std::string name = capitalised(toString(m)) + "Mode";
    operations.add({name,
                    "Selects " + capitalised(toString(m)) + " mode: " + gripper_.mode(m).description +
                        " (the fingers must be open).",
                    {}},
                   [this, m](const component::ParamMap&) { return setMode(m); });
  }
  declared.symbols = {{"gripper_fingers", world::SymbolKind::kJoints,
                       "the fingers' reading: each finger's position (0 open .. 1 closed), finger_middle first"}};
  declared.predicates = {
      {"gripper_open", 0, "every finger is fully open"},
      {"gripper_closed", 0, "the fingers of the current mode are fully closed, nothing between them"},
      {"gripper_holding", 0, "at least two fingers stopped on something and squeeze it"},
      {"gripper_mode", 1, "gripper_mode(m): the gripper is in mode m"}};
  declare(std::move(declared), std::move(operations));
}

AdaptiveGripperReading AdaptiveGripper::checkedRead() const {
  const AdaptiveGripperReading reading = driver_.read();
  if (const std::string problem = problemWith(reading, clock_.now(), options_.reading_timeout); !problem.empty()) {
    throw std::runtime_error(problem);
  }
  return reading;
}

int AdaptiveGripper::holdingFingers(const AdaptiveGripperReading& reading) const {
  const auto& closing = gripper_.mode(reading.mode).closing;
  int holding = 0;
  for (std::size_t i = 0; i < reading.fingers.size(); ++i) {
    const auto& finger = reading.fingers[i];
    if (closing[i] && finger.contact && finger.force > kHoldingForce && std::abs(finger.speed) < kHoldingSpeed) {
      ++holding;
    }
  }
  return holding;
}

world::Report AdaptiveGripper::report() const {
  // A reading that cannot be trusted makes the report throw: the registry then stops the cell.
  const AdaptiveGripperReading reading = checkedRead();
  world::Report report;
  world::JointsValue fingers;
  for (std::size_t i = 0; i < reading.fingers.size(); ++i) {
    fingers.joint_names.emplace_back(kFingerNames[i]);
    fingers.positions.push_back(reading.fingers[i].position);
  }
  report.symbols.push_back({"gripper_fingers", "", clock_.now(), std::move(fingers), std::nullopt});
  const auto& closing = gripper_.mode(reading.mode).closing;
  bool open = true;
  bool closed = true;
  for (std::size_t i = 0; i < reading.fingers.size(); ++i) {
    open = open && reading.fingers[i].position < kOpenBelow;
    closed = closed && (!closing[i] || (reading.fingers[i].position > kClosedAbove && !reading.fingers[i].contact));
  }
  if (open) {
    report.predicates.push_back({"gripper_open", {}, true, ""});
  }
  if (closed) {
    report.predicates.push_back({"gripper_closed", {}, true, ""});
  }
  if (holdingFingers(reading) >= 2) {
    report.predicates.push_back({"gripper_holding", {}, true, ""});
  }
  if (reading.mode_reached) {
    report.predicates.push_back({"gripper_mode", {std::string(toString(reading.mode))}, true, ""});
  }
  return report;
}

std::unique_ptr<component::RunningOperation> AdaptiveGripper::setMode(GripperMode mode) {
  const AdaptiveGripperReading reading = checkedRead();
  if (reading.mode == mode && reading.mode_reached) {
    return std::make_unique<component::FinishedOperation>(
        OperationResult::success({{"mode", std::string(toString(mode))}}));
  }
  for (std::size_t i = 0; i < reading.fingers.size(); ++i) {
    if (reading.fingers[i].position >= kModeChangeBelow) {
      return std::make_unique<component::FinishedOperation>(OperationResult::failure(
          "cannot change to " + std::string(toString(mode)) + " mode: " + std::string(kFingerNames[i]) + " is " +
          percent(reading.fingers[i].position) +
          " closed (a mode change turns fingers 1 and 2 and would drop a held part); Open the gripper first"));
    }
  }
  return std::make_unique<ModeChange>(*this, driver_, clock_, mode, options_.timeout);
}

}  // namespace costar::gripper
