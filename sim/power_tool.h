#pragma once
// The simulated power tool (an orbital sander/polisher, data/tools/NAME.json): a free body with a
// pad, a motor housing and a knob a gripper picks up from its stand, the stand (fixed, beside the
// robot) and the workpiece it polishes (a block fixed on the table, from the scene). Its driver
// (tool::PowerToolDriver) switches it and reads it as a real tool's I/O would: the power, the
// speed (a first-order motor), the knob's presence switch (two fingers of the gripper touch the
// tool) and the stand's (the tool sits in it).
//
// Ground truth for tests and the trial judge: while the tool runs (at least half its lowest
// speed) and its pad presses on the workpiece (2 N or more, the normal forces of the pad's
// contacts with it), the texels of the workpiece's marked area under the pad (its square, grown
// by the orbit's radius) are worked: each texel (2 mm) keeps the time it was worked and the
// largest force it was worked with. A log at 100 Hz keeps the tool's state, the pad's force and
// where it is on the workpiece, how fast the arm's joints turn and whether the arm touches the
// workpiece. The tool can be taken away (parked off the table, as a person who borrows it does)
// and given back onto its stand. No MuJoCo type appears here.

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "sim/scene.h"
#include "tool/power_tool_description.h"
#include "tool/power_tool_driver.h"
#include "world/pose.h"

struct mjModel_;
struct mjData_;

namespace costar::sim {

/// The cell's power tool: what it is and where its stand stands (the centre of the stand's
/// base on the table, z up).
struct PowerToolSetup {
  tool::PowerToolDescription tool;
  world::Pose stand = world::Pose::Identity();

  /// Where the tool frame (the pad's working face) is when the tool sits on its stand.
  world::Pose dockedPose() const;
};

/// The workpiece's top face (its centre, z out of it) in the world.
world::Pose workpieceTop(const WorkpieceRequest& workpiece);

/// The MJCF bodies (for the model's worldbody) and assets of the stand with the tool on it (when
/// `setup` and `tool_on_stand`: a scene without the tool has neither) and of the workpiece (when
/// given).
std::string powerToolBodies(const PowerToolSetup* setup, bool tool_on_stand, const WorkpieceRequest* workpiece);
std::string powerToolAssets();

/// One 100 Hz sample of the log.
struct PowerToolSample {
  double time = 0.0;  // s of simulated time
  bool powered = false;
  double speed = 0.0;
  bool held = false;
  bool docked = false;
  bool away = false;                              // taken away (take())
  double pad_force = 0.0;                         // N, the pad's push on the workpiece (normal forces of its contacts)
  Eigen::Vector2d pad = Eigen::Vector2d::Zero();  // the pad's centre on the workpiece's top (m)
  bool working = false;                           // it works the surface: running and pressing with 2 N or more
  double arm_speed = 0.0;                         // rad/s, the fastest arm joint
  bool arm_on_workpiece = false;                  // an arm or gripper geom touches the workpiece
};

/// The worked texels of the workpiece's marked area.
struct Coverage {
  int columns = 0;  // along the workpiece's x
  int rows = 0;
  double texel = 0.002;  // m
  Eigen::Vector2d marked = Eigen::Vector2d::Zero();
  std::vector<float> worked_seconds;  // row-major, row 0 at -y
  std::vector<float> max_force;       // N

  /// The fraction of texels worked for at least `seconds`.
  double fraction(double seconds = 0.05) const;
};

class SimPowerTool final : public tool::PowerToolDriver {
 public:
  /// `hand_part(geom)`: which finger of the gripper a geom belongs to (0, 1, 2...; a larger
  /// number for the palm), -1 when it is not the gripper's; `arm_geom(geom)`: the arm's or the
  /// gripper's. @throws std::runtime_error when the model lacks the tool's bodies.
  SimPowerTool(const mjModel_* model, mjData_* data, std::optional<PowerToolSetup> setup,
               std::optional<WorkpieceRequest> workpiece, bool tool_present, std::function<int(int)> hand_part,
               std::function<bool(int)> arm_geom, std::function<double()> arm_speed, std::function<TimePoint()> now);

  tool::PowerToolReading read() const override;
  void command(bool on, double speed) override;

  /// After every physics step: the motor, the arm's contacts; every 10 ms the switches, the pad
  /// and the log.
  void step();

  // --- ground truth and disturbances (tests, the trial judge) ---------------------------------
  bool hasTool() const { return tool_body_ >= 0; }
  /// Takes the tool (out of the gripper or off its stand) and parks it off the table.
  void take();
  /// Puts the tool back on its stand, at rest.
  void giveBack();
  /// Puts the tool's frame (its pad's working face) at `pose`, at rest (tests).
  void placeTool(const world::Pose& pose);
  bool away() const { return away_; }
  world::Pose toolPose() const;
  const std::optional<PowerToolSetup>& setup() const { return setup_; }
  const std::vector<PowerToolSample>& log() const { return log_; }
  /// Absent without a workpiece.
  const std::optional<Coverage>& coverage() const { return coverage_; }
  /// The friction coefficient (sliding) of the pad's contacts with the workpiece now; absent
  /// while they do not touch.
  std::optional<double> padFriction() const;
  /// Physics steps in which an arm or gripper geom touched the workpiece.
  std::uint64_t armWorkpieceSteps() const { return arm_workpiece_steps_; }

  static constexpr double kWorkingForce = 2.0;  // N
  static constexpr int kSampleSteps = 5;        // physics steps between samples (10 ms)

 private:
  void sense();
  void work(const world::Pose& pad, double force);

  const mjModel_* model_;
  mjData_* data_;
  std::optional<PowerToolSetup> setup_;
  std::optional<WorkpieceRequest> workpiece_;
  std::function<int(int)> hand_part_;
  std::function<bool(int)> arm_geom_;
  std::function<double()> arm_speed_;
  std::function<TimePoint()> now_;
  int tool_body_ = -1;
  int tool_qpos_ = 0;
  int tool_dof_ = 0;
  int pad_geom_ = -1;
  int stand_body_ = -1;
  int workpiece_geom_ = -1;
  world::Pose workpiece_top_ = world::Pose::Identity();
  bool powered_ = false;
  double target_ = 0.0;
  double speed_ = 0.0;
  bool held_ = false;
  bool docked_ = false;
  bool away_ = false;
  int steps_ = 0;
  std::uint64_t arm_workpiece_steps_ = 0;
  bool arm_touched_ = false;  // since the last sample
  std::vector<PowerToolSample> log_;
  std::optional<Coverage> coverage_;
};

}  // namespace costar::sim
