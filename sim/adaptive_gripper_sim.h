#pragma once
// The 3-finger adaptive gripper in MuJoCo, on any flange: its generated model mounted into a
// workcell's MJCF, and its driver (the simulator behind gripper::AdaptiveGripperDriver).
//
// The model comes from robots/grippers/NAME.json (robots/generate_gripper.py writes
// NAME_body.xml and NAME_sections.xml at build time). mountAdaptiveGripper() puts the bodies
// inside the flange body of any workcell model and the tendons and actuators at its top level;
// SimAdaptiveGripper then finds its joints, tendons and actuators by name in the compiled
// model. The owner of the model calls control() before every physics step. Grasps are
// physical: the fingers squeeze the part through contacts, with the force limit of the
// flexion servos; nothing welds a part to the gripper.
//
// No MuJoCo type appears here: the model and data are passed as MuJoCo's opaque structs.

#include <array>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "gripper/adaptive_gripper_description.h"
#include "gripper/adaptive_gripper_driver.h"

struct mjModel_;
struct mjData_;

namespace costar::sim {

/// The generated model files of a gripper.
struct GripperModelFiles {
  std::filesystem::path body;      // NAME_body.xml: goes inside the flange body
  std::filesystem::path sections;  // NAME_sections.xml: goes at the model's top level
};

/// The files of gripper `name` in `dir` (default: where the build generated them).
/// @throws std::runtime_error naming a missing file.
GripperModelFiles gripperModelFiles(const std::string& name, const std::filesystem::path& dir = {});

/// Puts the gripper into a workcell's MJCF text: its bodies right inside the body named
/// `flange_body` (the gripper's mounting frame is that body's frame), its tendons, equalities
/// and actuators before </mujoco>. The model must use angle="radian".
/// @throws std::runtime_error when the flange body or a file is missing.
void mountAdaptiveGripper(std::string& mjcf, const std::string& flange_body, const GripperModelFiles& files);

/// The simulated gripper: its servos' control and its sensors, in a compiled model that has it
/// mounted. Stamps readings with `now()`.
class SimAdaptiveGripper final : public gripper::AdaptiveGripperDriver {
 public:
  /// @throws std::runtime_error naming a joint, tendon or actuator the model lacks.
  SimAdaptiveGripper(mjModel_* model, mjData_* data, gripper::AdaptiveGripperDescription description,
                     std::function<TimePoint()> now);

  gripper::AdaptiveGripperReading read() const override;
  void commandFingers(const std::array<double, gripper::kFingerCount>& positions, double speed, double force) override;
  void commandMode(gripper::GripperMode mode) override;

  /// Advances the servos' setpoints by one physics step; call before every mj_step.
  void control();
  /// Puts the fingers open and the scissor axis at `mode` at once (a model's initial state).
  void reset(gripper::GripperMode mode);
  /// How far the fingers were last told to close: the most closed finger's target, 0 (open) to 1.
  double commandedClosure() const;
  /// Whether a geom belongs to the gripper, and to which finger (-1: the palm or not a finger).
  bool isGripperGeom(int geom) const;
  int fingerOfGeom(int geom) const;
  const gripper::AdaptiveGripperDescription& description() const { return description_; }

 private:
  struct Finger {
    int tendon = -1;
    int actuator = -1;
    std::array<int, 3> joints{};
    double open = 0.0;              // tendon length when open (rad)
    double closed = 0.0;            // when closed
    double closed_fingertip = 0.0;  // when closed in a fingertip mode (the medial phalanx held straight)
    double target = 0.0;            // 0..1
    double setpoint = 0.0;
  };
  double position(const Finger& finger) const;
  double closedLength(const Finger& finger) const;
  void applyMode();

  mjModel_* model_;
  mjData_* data_;
  gripper::AdaptiveGripperDescription description_;
  std::function<TimePoint()> now_;
  std::array<Finger, gripper::kFingerCount> fingers_{};
  double speed_ = 0.5;  // strokes per second
  int scissor_joint_ = -1;
  int scissor_actuator_ = -1;
  double scissor_target_ = 0.0;  // rad
  double scissor_setpoint_ = 0.0;
  double scissor_speed_ = 2.0;        // rad/s
  std::vector<int> fingertip_locks_;  // equalities that hold medial and distal straight
  gripper::GripperMode mode_ = gripper::GripperMode::kBasic;
  std::vector<int> geom_finger_;  // per geom: finger index, 3 for the palm, -1 not the gripper
};

}  // namespace costar::sim
