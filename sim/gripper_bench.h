#pragma once
// A test bench for a 3-finger adaptive gripper without an arm: the gripper on a carrier (three
// slide joints and a yaw hinge, stiff position servos) above a table with one part. The
// carrier's flange stands for any arm's flange: the gripper is mounted on it from its
// generated model exactly as on an arm (mountAdaptiveGripper). Physics steps in lockstep with a
// SimClock, as Simulation does; ground truth (the part's pose and contacts) is for tests and
// the trials only.
//
// runGripperTrial() is one pick: set the mode, descend over the part to a grasp, close, lift
// 5 cm, hold 2 s, and judge from the simulated world's true state.

#include <Eigen/Geometry>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "core/clock.h"
#include "gripper/adaptive_gripper_description.h"
#include "gripper/adaptive_gripper_driver.h"
#include "world/object_class.h"
#include "world/pose.h"

namespace costar::sim {

struct GripperBenchOptions {
  std::string gripper = "robotiq3f";
  /// Folder with data/objects and robots/grippers (default: dataRoot()).
  std::filesystem::path data_root;
  /// Folder with the generated gripper models (default: where the build wrote them).
  std::filesystem::path model_dir;
  std::string part_class = "node";
  /// Where the part's frame rests on the table (z is set to the class's rest height).
  double part_x = 0.0;
  double part_y = 0.0;
  double part_yaw = 0.0;  // rad
  /// Physics time to let the part settle before time 0.
  double settle_seconds = 0.2;
};

class GripperBench {
 public:
  /// @throws std::runtime_error naming what is missing or wrong (files, class, model).
  static std::unique_ptr<GripperBench> create(const GripperBenchOptions& options);
  ~GripperBench();
  GripperBench(const GripperBench&) = delete;
  GripperBench& operator=(const GripperBench&) = delete;

  TimePoint time() const;
  void stepTo(TimePoint t);
  /// Steps whenever `clock` advances, until detach() or destruction.
  void attach(SimClock& clock);
  void detach();

  /// The gripper's simulated driver (stamps readings with the simulated time).
  gripper::AdaptiveGripperDriver& driver();
  const gripper::AdaptiveGripperDescription& gripper() const;

  /// Moves the flange toward `position` (world), its z axis pointing down and turned by `yaw`
  /// about the world's z, at `speed` (m/s, straight line; the yaw turns at 1 rad/s).
  void moveFlange(const Eigen::Vector3d& position, double yaw, double speed);
  /// The carrier's setpoint reached and the flange within 1 mm of it.
  bool flangeArrived() const;
  /// The flange's pose in the world (true value): z along the approach.
  world::Pose flangePose() const;

  // --- ground truth (tests and trials only) -----------------------------------------------
  world::Pose partPose() const;
  double partRestHeight() const;
  const world::ObjectClass& partClass() const;
  /// What the part touches: "finger_middle", "finger_1", "finger_2", "palm", "table".
  std::vector<std::string> partContacts() const;
  /// Physics steps so far (after settling).
  std::int64_t steps() const;

 private:
  struct Impl;
  explicit GripperBench(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

/// One pick on the bench.
struct GripperTrialOptions {
  GripperBenchOptions bench;
  gripper::GripperMode mode = gripper::GripperMode::kBasic;
  /// The grasp: the gripper's tool centre point in the part's frame (a taught grasp T,
  /// smartmove::GraspLibrary for this gripper). The flange goes to part * T * tcp^-1.
  world::Pose tcp_in_part = world::Pose::Identity();
  /// Where the gripper goes wrong, as a perception error would put it: the grasp moved by
  /// (x, y) in the world (m) and turned by `yaw` (rad) about the vertical.
  Eigen::Vector3d approach_error = Eigen::Vector3d::Zero();  // x, y, yaw
  double force = 40.0;                                       // N per finger
  double lift = 0.05;                                        // m
  double hold_seconds = 2.0;
};

struct GripperTrialResult {
  bool success = false;
  /// Why it failed, in words (empty on success).
  std::string reason;
  double lifted = 0.0;                // the part's height above its rest height after the hold, m
  double slip = 0.0;                  // how far the part slid out of the hand during the hold, m
  double close_seconds = 0.0;         // how long Close took (simulated)
  bool holding_predicate = false;     // gripper_holding after the hold
  std::vector<std::string> contacts;  // what the part touches after the hold
  double simulated_seconds = 0.0;
};

/// Runs one pick with the AdaptiveGripper component on a SimClock: SetMode, approach from
/// 8 cm above the grasp, Close, lift, hold; success when after the hold the part is lifted by
/// at least 90 % of `lift`, slid less than 3 mm out of the hand during the hold (an
/// encompassing grasp may pull it toward the palm), touches at
/// least two fingers and not the table, and the gripper reports gripper_holding. @throws std::runtime_error when the
/// bench cannot be built.
GripperTrialResult runGripperTrial(const GripperTrialOptions& options);

}  // namespace costar::sim
