#pragma once
// A parallel 2-finger gripper (e.g. a Robotiq 2F-85) as a CoSTAR component implementing the
// abstract Gripper. It has one mode, Pinch: BasicMode, WideMode and ScissorMode fail with a
// reason. Its predicates come from the fingers' readings, never from the last command:
//   gripper_open      the fingers are (nearly) fully open
//   gripper_closed    the fingers are (nearly) fully closed: nothing between them
//   gripper_holding   the fingers stopped on something and squeeze it
//   gripper_mode(m)   m = pinch

#include <memory>

#include "component/operation_table.h"
#include "core/clock.h"
#include "gripper/gripper_driver.h"

namespace costar::gripper {

struct ParallelGripperOptions {
  std::string name = "gripper";
  double speed = 0.1;        // m/s, default for Open and Close
  double force = 40.0;       // N, default grip force
  double max_force = 120.0;  // N, the most Close accepts (the gripper's description)
  /// Close and Open fail when the fingers have not settled after this long.
  Duration timeout = std::chrono::seconds(3);
  /// A finger reading older than this (by the driver's stamp) means the driver stopped updating.
  Duration reading_timeout = std::chrono::milliseconds(50);
};

class ParallelGripper final : public component::TableComponent {
 public:
  /// The driver and clock must outlive the component.
  ParallelGripper(GripperDriver& driver, const Clock& clock, ParallelGripperOptions options = {});
  world::Report report() const override;

  /// Thresholds of the predicates: within 2 mm of fully open / closed; holding when the
  /// fingers touch something and squeeze it with more than 2 N while moving slower than
  /// 2 cm/s (a held part shifting in the fingers as the arm stops moves them a few mm/s; a
  /// closing stroke is faster).
  static constexpr double kOpenMargin = 0.002;
  static constexpr double kClosedBelow = 0.002;
  static constexpr double kHoldingForce = 2.0;
  static constexpr double kHoldingSpeed = 0.02;

  /// The driver's reading, checked: finite and fresh. @throws std::runtime_error naming the
  /// problem (NaN readings, a reading that stopped updating, or the driver's own error).
  FingerReading checkedRead() const;

 private:
  GripperDriver& driver_;
  const Clock& clock_;
  ParallelGripperOptions options_;
};

}  // namespace costar::gripper
