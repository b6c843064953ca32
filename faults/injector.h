#pragma once
// Breaks a cell's drivers and components on purpose, as fault specs say (faults/fault.h).
// The workcell asks the injector to wrap each driver and component it builds; a wrapper
// implements the same interface (ArmDriver, GripperDriver, RgbdCamera, Component), passes
// every call through until its fault is due, then answers as the broken device would.
//
// What the wrappers model, and what they do not: a driver's faults are in its feedback path
// (readings fail, freeze or turn to NaN); commands still reach the controller, so the cell
// can stop the arm. A call that truly blocks cannot be interrupted in-process: a component
// that "hangs" answers every call with NoAnswer, which is what the caller of a component
// behind a process boundary sees when its call times out.
//
// The injector records when each fault was due and when it first took effect (the first
// call answered faultily), for the fault campaign's judge.

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "arm/arm_driver.h"
#include "camera/rgbd.h"
#include "component/component.h"
#include "core/clock.h"
#include "faults/fault.h"
#include "gripper/adaptive_gripper_driver.h"
#include "gripper/gripper_driver.h"

namespace costar::faults {

/// One fault, as it happened.
struct FaultRecord {
  FaultSpec spec;
  /// When a time-based (or random) fault is due.
  std::optional<TimePoint> due;
  /// When it became active (due time, or the call that made it due).
  std::optional<TimePoint> activated;
  /// When a call was first answered faultily.
  std::optional<TimePoint> first_effect;
  /// Calls counted for op=N.
  int calls = 0;
  /// A component's throw has been thrown (it throws once).
  bool spent = false;
};

class Injector {
 public:
  /// `seed` draws the random times, in the order of the specs.
  Injector(std::vector<FaultSpec> specs, std::uint64_t seed);
  /// Parses each spec. @throws FaultSpecError naming the bad one.
  static std::shared_ptr<Injector> fromText(const std::vector<std::string>& specs, std::uint64_t seed);

  /// The clock that decides when faults are due. Call before wrapping.
  void attach(const Clock& clock) { clock_ = &clock; }

  /// The driver as the cell should use it: wrapped once per fault that targets it, or the
  /// driver itself. The injector owns the wrappers: it must outlive their users.
  arm::ArmDriver& wrap(arm::ArmDriver& driver);
  gripper::GripperDriver& wrap(gripper::GripperDriver& driver);
  /// A 3-finger adaptive gripper's driver: the same target, "gripper-driver".
  gripper::AdaptiveGripperDriver& wrap(gripper::AdaptiveGripperDriver& driver);
  camera::RgbdCamera& wrap(camera::RgbdCamera& camera);
  /// The component wrapped once per fault that targets its name, or itself.
  std::shared_ptr<component::Component> wrap(std::shared_ptr<component::Component> component);

  /// Call once the cell is built. @throws FaultSpecError for a target the cell does not have
  /// or a kind its target cannot have, naming the targets there are.
  void checkTargets() const;

  const std::vector<FaultRecord>& records() const { return records_; }
  /// One line per fault: when it was due and when it took effect, for people.
  std::string summary() const;

  /// The fault state a wrapper consults: is fault `index` active now? `counts` marks a call
  /// that op=N counts.
  bool active(std::size_t index, bool counts);
  /// A wrapper answered faultily.
  void effect(std::size_t index);
  FaultRecord& record(std::size_t index) { return records_[index]; }

 private:
  TimePoint now() const;
  std::vector<std::size_t> faultsOn(std::string_view target) const;
  /// `inner` wrapped once per fault on `target`, innermost first; the wrappers kept in `wrappers`.
  template <class Faulty, class Interface>
  Interface& chain(Interface& inner, const char* target, std::vector<std::unique_ptr<Interface>>& wrappers);

  std::vector<FaultRecord> records_;
  const Clock* clock_ = nullptr;
  std::vector<std::string> wrapped_targets_;
  std::vector<std::unique_ptr<arm::ArmDriver>> arm_wrappers_;
  std::vector<std::unique_ptr<gripper::GripperDriver>> gripper_wrappers_;
  std::vector<std::unique_ptr<gripper::AdaptiveGripperDriver>> adaptive_wrappers_;
  std::vector<std::unique_ptr<camera::RgbdCamera>> camera_wrappers_;
};

}  // namespace costar::faults
