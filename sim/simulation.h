#pragma once
// A MuJoCo simulation of a workcell: an arm (the UR5 by default, any arm with a robot
// description), a gripper on its flange (the 2-finger gripper by default, or a 3-finger
// adaptive gripper: SimulationOptions::adaptive_gripper), table, parts, RGB-D camera. No MuJoCo type appears here;
// MuJoCo stays in sim/*.cpp.
//
// Physics advances in lockstep with a SimClock (attach()): each tick's interval is
// simulated in fixed steps of the model's timestep (2 ms). The arm follows joint setpoints
// with computed-torque control within the arm's torque limits; the gripper's fingers close by
// force-limited servos, so parts are held only by contact and friction.
//
// Threads: a Simulation is used by one thread at a time, but belongs to none: it may be made,
// stepped, rendered and destroyed on different threads, since its GL context is current only
// inside captureRgbd() and renderImage() (sim/gl_context.h). Several simulations render at once
// on several threads, and any of them may be destroyed while the others render.
//
// Ground truth (parts(), contacts) is for tests and the trial judge only: components that a
// plan uses must get their knowledge from the arm's joint states, the gripper's finger state
// and camera frames.

#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "arm/cartesian_controller.h"
#include "arm/force_torque.h"
#include "arm/joints.h"
#include "arm/robot_description.h"
#include "camera/rgbd.h"
#include "core/clock.h"
#include "core/image.h"
#include "gripper/adaptive_gripper_driver.h"
#include "sim/depth_noise.h"
#include "sim/force_torque.h"
#include "sim/person.h"
#include "sim/power_tool.h"
#include "sim/scene.h"
#include "sim/speed_separation.h"
#include "sim/wire.h"
#include "world/object_class.h"

namespace costar::sim {

/// One value per arm joint (as many as the robot has).
using ArmJoints = arm::JointVector;

/// Where the arm should be at a given time.
struct ArmSetpoint {
  ArmJoints position{};
  ArmJoints velocity{};
  ArmJoints acceleration{};
};

/// The robot a Simulation has when none is given: robots/ur5/ur5.json.
inline constexpr const char* kDefaultRobot = "ur5";

/// Where that default robot stands when no robot is given: at the origin turned 180 degrees about
/// z, so that q = 0 stretches it over the table, as the default cell stands it
/// (workcells/ur5-sim.json "robot_base"; a workcell always gives its own).
inline world::Pose defaultRobotBase() { return world::Pose(Eigen::AngleAxisd(EIGEN_PI, Eigen::Vector3d::UnitZ())); }

struct SimulationOptions {
  /// Folder with data/objects and sim/models (default: the repository, see core/paths.h).
  std::filesystem::path data_root;
  /// The arm: its MuJoCo model (the arm alone), joint names, home, flange and links. Default:
  /// kDefaultRobot's description, its model files under `data_root`.
  std::optional<arm::RobotDescription> robot;
  /// The cell around the robot (table, camera) and the gripper on its flange: MJCF pieces
  /// composed with the robot's model (sim/cell_model.h). Relative paths are under `data_root`.
  std::filesystem::path cell_model = "sim/models/table_cell.xml";
  /// Empty: the 2-finger gripper's piece generated from robots/grippers/parallel-2f.json
  /// (build/robots/grippers/parallel-2f_mount.xml).
  std::filesystem::path gripper_model;
  /// The gripper is the 3-finger adaptive gripper of robots/grippers/NAME.json (under
  /// `data_root`), `gripper_model` its generated workcell piece (NAME_mount.xml,
  /// robots/generate_gripper.py): the simulation drives it, adaptiveGripper() is its driver.
  /// Empty: the 2-finger gripper (fingers(), commandFingers()).
  std::string adaptive_gripper;
  /// Where the robot's base stands in the world; the composed model must agree (checked).
  /// Absent: not checked.
  std::optional<world::Pose> robot_base;
  /// Arm configuration at the start (radians). Default: the robot's home, tool pointing down.
  std::optional<ArmJoints> initial_arm;
  /// Seed of the random part placement (default: the scene's seed).
  std::optional<std::uint64_t> placement_seed;
  DepthNoiseOptions depth_noise;
  /// The wrist force/torque sensor's bias and noise (drawn from the placement seed).
  ForceTorqueNoise force_torque_noise;
  /// The cell's power tool and its stand (sim/power_tool.h); the scene says whether the tool sits
  /// on the stand ("power_tool": true). Absent: the cell has none (a scene that asks for it is
  /// refused).
  std::optional<PowerToolSetup> power_tool;
  /// Physics time to let parts settle before time 0.
  double settle_seconds = 0.3;
  /// Where the RGB-D camera really is, relative to where the cell's drawings put it (the
  /// model's nominal mounting): its optical centre moved by the translation (world axes) and
  /// its orientation turned by the rotation (world axes, about the optical centre). Identity:
  /// mounted as drawn. Absent: the scene's camera_offset (seeded by the placement seed), if
  /// any. Components never learn it; only calibration recovers it.
  std::optional<world::Pose> camera_offset;
  /// Spare parts, one of each class named here: built into the model (its bodies are fixed
  /// once loaded) but parked beside the table on the robot's left (1.6 m out, on the plane of
  /// the table top, which MuJoCo makes endless), out of the camera's view and the arm's reach, for a disturbance that
  /// puts a part on the table mid-task (movePart). Named after the scene's parts (node_3 after node_0..2), in the
  /// class's first colour.
  std::vector<std::string> spare_classes;
  /// With a person in the scene: the controller's speed and separation monitoring
  /// (sim/speed_separation.h) scales the arm's joint trajectories. false: the arm ignores the
  /// person (for measuring what the monitor prevents; the record is kept either way).
  bool speed_separation_monitoring = true;
  SpeedSeparationParams speed_separation;
};

/// The separation between the arm (with its gripper) and the scene's person now.
struct SeparationStatus {
  double separation = 0.0;           // m, between the enclosing capsules (true geometry)
  double sensed_separation = 0.0;    // m, as the monitor last sensed it (every sensor_period)
  double arm_speed = 0.0;            // m/s, the fastest point of the arm's capsules
  double scale = 1.0;                // the speed override, 0 .. 1
  double protective_distance = 0.0;  // S_p at arm_speed
  std::string state;                 // "free", "limited", "stopped" ("off": not monitored)
  bool collaborative = false;        // power and force limiting for a hand-over
  std::string stop_reason;           // why the arm is held (SpeedSeparationMonitor::stopReason)
  std::string arm_geom;              // the closest pair's geoms
  std::string person_geom;
};

/// What the monitor's judge recorded since time 0 (ground truth, for trials and benches).
struct SeparationRecord {
  double seconds = 0.0;               // simulated with the person present
  double min_separation = 1e9;        // m, at any speed
  double fast_seconds = 0.0;          // with the arm faster than fast_speed
  double min_separation_fast = 1e9;   // m, while faster than fast_speed
  double min_margin_fast = 1e9;       // m, separation - S_p(speed) while faster
  std::uint64_t violation_steps = 0;  // physics steps faster with separation < S_p(speed)
  /// Contact while the arm moved of its own accord (its speed override above 0): steps and the
  /// largest total normal force arm-person in a step (N).
  std::uint64_t contact_steps = 0;
  double max_contact_force = 0.0;
  /// Contact while the override held the arm still: the person ran into a stopped arm. Steps in
  /// which the person pushes the stopped arm do not count as the arm moving fast.
  std::uint64_t stopped_contact_steps = 0;
  double max_stopped_contact_force = 0.0;
  /// In collaborative mode (a hand-over): its time, and contact with the person's hand while
  /// the arm moved (steps and the largest force, N; contact elsewhere counts above).
  double collaborative_seconds = 0.0;
  std::uint64_t hand_contact_steps = 0;
  double max_hand_contact_force = 0.0;
  int stops = 0;                              // protective stops
  double stopped_seconds = 0.0;               // with the speed override at 0 while a trajectory ran
  static constexpr double fast_speed = 0.25;  // m/s (the threshold)
};

/// A part's true state, for tests and the trial judge.
struct PartState {
  std::string name;
  std::string object_class;
  std::string color;
  world::Pose pose;
  Eigen::Vector3d linear_velocity = Eigen::Vector3d::Zero();
};

/// The gripper as its sensors see it.
struct FingerState {
  double opening = 0.0;        // distance between the pads, m (0 .. 0.085)
  double opening_speed = 0.0;  // m/s, negative while closing
  double force = 0.0;          // servo force, N (positive squeezes)
  bool pads_in_contact = false;
};

class Simulation {
 public:
  /// Builds the workcell with the scene's parts and lets them settle.
  /// @throws std::runtime_error naming what is missing or wrong (files, classes, model).
  static std::unique_ptr<Simulation> create(const Scene& scene, const SimulationOptions& options = {});
  ~Simulation();
  Simulation(const Simulation&) = delete;
  Simulation& operator=(const Simulation&) = delete;

  // --- time ------------------------------------------------------------------------------
  /// Simulated time (0 after settling).
  TimePoint time() const;
  /// Simulates up to `t` in whole physics steps.
  void stepTo(TimePoint t);
  /// Steps whenever `clock` advances, until detach() or destruction. The clock must outlive
  /// the attachment.
  void attach(SimClock& clock);
  void detach();
  Duration timestep() const;

  // --- arm -------------------------------------------------------------------------------
  ArmJoints armPositions() const;
  ArmJoints armVelocities() const;
  /// The controller asks `source` for a setpoint at every physics step. Without a source
  /// (nullptr) the arm holds the last setpoint.
  void setArmSetpointSource(std::function<ArmSetpoint(TimePoint)> source);
  /// Pose of the gripper's tool centre point in the world (true value).
  world::Pose tcpPose() const;
  /// Number of physics steps in which an arm or gripper geom touched the table so far.
  std::uint64_t armTableContactSteps() const;
  /// The wrist force/torque sensor at the flange (sim/force_torque.h): its driver, readings
  /// stamped with the simulated time. It lives as long as the simulation.
  arm::ForceTorqueSensor& forceTorqueSensor();
  /// The controller's Cartesian impedance mode (sim/impedance_controller.h); a joint setpoint
  /// source (setArmSetpointSource) takes the arm back from it. It lives as long as the simulation.
  arm::CartesianController& cartesianController();
  /// What the wrist sensor carries: the mass and centre of mass (in the sensor's frame, the
  /// flange's) of everything beyond it (the gripper, and what it holds rigidly in the model).
  arm::Payload toolPayload() const;
  /// A person's hand on the tool (free-drive, docs/TEACHING.md): a force (N) and a torque (N m)
  /// in world axes, applied at the tool centre point on the flange's body at every physics step
  /// for `hold` of simulated time (the hand lets go then, as when a page's drag stream stops), or
  /// until changed (a zero wrench: the hand lets go). @throws std::invalid_argument for a wrench
  /// that is not finite.
  void setHandWrench(const arm::Wrench& at_tcp, Duration hold = std::chrono::hours(24));
  arm::Wrench handWrench() const;
  /// The true wrench at the flange sensor (no bias, no noise, never tared; what the flange
  /// pushes the tool side with, in the flange frame), for tests and the trial judge.
  arm::Wrench trueFlangeWrench() const;

  // --- gripper ---------------------------------------------------------------------------
  /// The 2-finger gripper's fingers. @throws std::logic_error when the cell has the adaptive
  /// gripper (use adaptiveGripper()).
  FingerState fingers() const;
  /// Moves the fingers toward `opening` (m) at `speed` (m/s), squeezing with at most `force` (N).
  /// @throws std::logic_error when the cell has the adaptive gripper.
  void commandFingers(double opening, double speed, double force);
  /// The 3-finger adaptive gripper's driver (readings stamped with the simulated time), or
  /// nullptr when the cell has the 2-finger gripper. It lives as long as the simulation.
  gripper::AdaptiveGripperDriver* adaptiveGripper();

  // --- power tool ------------------------------------------------------------------------
  /// The power tool's driver and its ground truth (the workpiece's worked texels, its log), or
  /// nullptr when the cell has no power tool and the scene no workpiece. It lives as long as the
  /// simulation.
  SimPowerTool* powerTool();
  /// The 2-finger gripper's stroke (m): twice its finger servo's control range, as the model
  /// gives it (robots/grippers/NAME.json's stroke_m). @throws std::logic_error with the adaptive gripper.
  double maxOpening() const;

  // --- camera ----------------------------------------------------------------------------
  const camera::Intrinsics& rgbdIntrinsics() const;
  /// Pose of the RGB-D camera's optical frame (x right, y down, z forward) in the world: the
  /// true pose (nominal mounting moved by SimulationOptions::camera_offset).
  world::Pose rgbdPose() const;
  /// The optical frame where the cell's drawings put it (the model's mounting, without the
  /// offset): what the system believes before it calibrates the camera.
  world::Pose rgbdNominalPose() const;
  /// Renders the RGB-D camera now and applies the depth noise model with `noise_seed`.
  /// Without `colour` the frame's colour image is left empty and only depth is rendered
  /// (faster; the points are the same).
  camera::RgbdFrame captureRgbd(std::uint64_t noise_seed, bool colour = true);
  /// Renders a named camera ("rgbd", "overview") at any size up to 1280 x 960.
  RgbImage renderImage(const std::string& camera, int width, int height);

  // --- ground truth (tests and the trial judge only) ----------------------------------------
  std::vector<PartState> parts() const;
  /// True for a part parked off the table top (a spare, or a part taken away).
  static bool parked(const PartState& part) {
    const Region table = tableTop();
    const Eigen::Vector3d& p = part.pose.translation();
    return p.x() < table.min.x() || p.x() > table.max.x() || p.y() < table.min.y() || p.y() > table.max.y();
  }
  /// The calibration marker fixed to the gripper (DICT_4X4_50 id kGripperMarkerId, black
  /// square kGripperMarkerSize wide): its frame (x to the image's right, y up, z out of it) in
  /// the world, and in the flange frame (tool0), true values.
  world::Pose gripperMarkerPose() const;
  world::Pose gripperMarkerInFlange() const;
  static constexpr int kGripperMarkerId = 1;
  static constexpr double kGripperMarkerSize = 0.05;
  /// Puts a part elsewhere at rest, as a person who moves or takes away a part mid-task would
  /// (scenario tests and evaluation; plans never call it). Takes effect at once (positions
  /// are recomputed); physics carries on from there.
  /// @throws std::invalid_argument for an unknown part.
  void movePart(const std::string& name, const world::Pose& pose);
  /// Pairs of bodies in contact: part names, "table", "arm", and the gripper's fingers:
  /// "left_finger", "right_finger" (2-finger), "finger_middle", "finger_1", "finger_2" and
  /// "palm" (adaptive gripper); with a jig, "wire", "pin_NAME" and "jig" (its clamp).
  std::vector<std::pair<std::string, std::string>> contacts() const;
  const std::vector<world::ObjectClass>& objectClasses() const;
  /// The scene's bending jig and wire as they truly are (sim/wire.h): the pins, the wire's
  /// centreline and bends, how the gripper has held it so far. Absent without a "jig".
  std::optional<JigState> jig() const;
  /// The scene's person as the script places it now (absent without a "person").
  std::optional<PersonPose> person() const;
  /// The separation monitor's reading now, and its record (absent without a person).
  std::optional<SeparationStatus> separation() const;
  std::optional<SeparationRecord> separationRecord() const;
  /// How far the speed override has held the present joint trajectory back: the controller
  /// follows its sample at t - start - lag (arm::ArmDriver::heldBack).
  Duration trajectoryLag() const;
  /// The monitor's stop input (SpeedSeparationMonitor::setStopInput): the arm brakes along
  /// its path to rest and stays until released. @throws std::logic_error without a monitor (no
  /// person in the scene, or monitoring off).
  void setStopInput(bool stop);
  /// The monitor's collaborative mode (power and force limiting for a hand-over,
  /// SpeedSeparationMonitor::setCollaborative): the arm at most 0.2 m/s at any separation,
  /// stopped by contact outside the person's hand or a hand force above 140 N.
  /// @throws std::logic_error without a monitor.
  void setCollaborative(bool on);

  /// The default robot's "home" configuration: tool pointing down above the table.
  static ArmJoints homeConfiguration();
  /// The arm's joints as the model names them, base first.
  const std::vector<std::string>& armJointNames() const;

 private:
  struct Impl;
  explicit Simulation(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace costar::sim
