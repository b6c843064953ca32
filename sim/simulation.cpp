#include "sim/simulation.h"

#include <mujoco/mujoco.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <map>
#include <mutex>
#include <sstream>
#include <stdexcept>

#include "core/paths.h"
#include "gripper/adaptive_gripper_description.h"
#include "sim/adaptive_gripper_sim.h"
#include "sim/cell_model.h"
#include "sim/gl_context.h"
#include "sim/impedance_controller.h"
#include "sim/person_sim.h"
#include "sim/wire_sim.h"

namespace costar::sim {

namespace {

// Computed-torque gains: critically damped, 8 Hz bandwidth, with integral action while the
// setpoint rests, as an arm's position controller settles: without it a steady load the model
// does not know (a wire being bent, a part in the fingers) left the joints at rest a steady error
// of load / (M Kp), up to 6 mrad at the iiwa's wrist bending a wire, beyond the arm's arrival
// tolerance. Ki / Kp = 10 /s: that error goes in about 0.3 s, well within a motion's settling
// time (Kd Kp > Ki keeps the loop stable). The integral is kept, not integrated, while the
// setpoint moves (a motion follows its path as before, the load it held carried over), and its
// part is capped at what a 0.02 rad error would ask (anti-windup: a blocked arm pushes no harder).
constexpr double kArmOmega = 50.0;
constexpr double kArmKp = kArmOmega * kArmOmega;
constexpr double kArmKd = 2.0 * kArmOmega;
constexpr double kArmKi = 10.0 * kArmKp;
constexpr double kArmIntegralLimit = 0.02 * kArmKp / kArmKi;  // rad s

// Threads that turn a depth image into a noisy cloud (the noise does not depend on it).
constexpr int kNoiseThreads = 2;

void replaceMarker(std::string& text, const std::string& marker, const std::string& content) {
  const auto at = text.find(marker);
  if (at == std::string::npos) {
    throw std::runtime_error("the workcell model has no " + marker + " marker");
  }
  text.replace(at, marker.size(), content);
}

std::string format(double value) {
  std::ostringstream out;
  out.precision(9);
  out << value;
  return out.str();
}

std::string vec(const Eigen::Vector3d& v) { return format(v.x()) + " " + format(v.y()) + " " + format(v.z()); }

/// MJCF for one part: a free body. Cameras see the class's boxes (visual geoms, massless, no
/// contacts); contacts and mass come from one box around them (geom group 3, which renderers
/// hide). The sockets matter to what a camera sees, not to how a part rests or is gripped.
std::string partBody(const PartPlacement& part, const world::ObjectClass& object) {
  const Eigen::AlignedBox3d bounds = object.bounds();
  const Eigen::Vector3d half = bounds.sizes() / 2;
  const double density = object.mass / (8.0 * half.prod());
  const Eigen::Quaterniond q(part.pose.linear());
  std::string body = "<body name=\"" + part.name + "\" pos=\"" + vec(part.pose.translation()) + "\" quat=\"" +
                     format(q.w()) + " " + format(q.x()) + " " + format(q.y()) + " " + format(q.z()) +
                     "\"><freejoint/>";
  body += "<geom class=\"part\" type=\"box\" group=\"3\" pos=\"" + vec(bounds.center()) + "\" size=\"" + vec(half) +
          "\" density=\"" + format(density) + "\" rgba=\"0.5 0.5 0.5 0.3\"/>";
  for (const auto& box : object.boxes) {
    body += "<geom type=\"box\" contype=\"0\" conaffinity=\"0\" density=\"0\" pos=\"" + vec(box.center) + "\" size=\"" +
            vec(box.half_size) + "\" material=\"" + object.name + "_" + part.color + "\"/>";
  }
  return body + "</body>\n";
}

}  // namespace

ArmJoints Simulation::homeConfiguration() {
  static const ArmJoints home = arm::loadRobotDescription(arm::robotDescriptionFile(kDefaultRobot)).home;
  return home;
}

// --- implementation ------------------------------------------------------------------------

struct Simulation::Impl {
  mjModel* model = nullptr;
  mjData* data = nullptr;
  std::vector<world::ObjectClass> classes;
  std::vector<PartPlacement> placements;
  std::vector<int> part_bodies;

  std::vector<std::string> arm_joint_names;
  int arm_joints = 0;  // the arm's joints, at most arm::kMaxJoints
  std::array<int, arm::kMaxJoints> arm_qpos{};
  std::array<int, arm::kMaxJoints> arm_dof{};
  // The 2-finger gripper (when `adaptive` is not set).
  int finger_qpos = 0;
  int finger_dof = 0;
  int finger_actuator = 0;
  int left_pad = 0;
  int right_pad = 0;
  // The 3-finger adaptive gripper, when the cell has it.
  std::unique_ptr<SimAdaptiveGripper> adaptive;
  // The scene's bending jig and wire, when it has them.
  std::unique_ptr<SimJig> jig;
  // The wrist force/torque sensor and the controller's Cartesian impedance mode.
  std::unique_ptr<SimForceTorqueSensor> force_torque;
  std::unique_ptr<SimCartesianController> cartesian;
  // The power tool, its stand and the workpiece, when the cell or the scene has them.
  std::unique_ptr<SimPowerTool> power_tool;
  int table_geom = 0;          // the box the arm collides with
  int table_surface_geom = 0;  // the plane parts rest on
  int tcp_site = 0;
  int rgbd_camera = 0;
  int gripper_marker_geom = 0;
  world::Pose rgbd_nominal = world::Pose::Identity();  // optical frame as drawn
  bool camera_moved = false;                           // mounted elsewhere than drawn
  int first_arm_body = 0;
  int tool_body = 0;  // the flange's body

  std::int64_t steps = 0;         // physics steps since time 0
  std::int64_t settle_steps = 0;  // steps taken before time 0
  std::function<ArmSetpoint(TimePoint)> setpoint_source;
  ArmSetpoint held;
  std::array<double, arm::kMaxJoints> integral{};  // the joint controller's integral of the error, rad s
  std::vector<mjtNum> acceleration;                // nv, scratch
  std::vector<mjtNum> torque;                      // nv, scratch

  double max_opening = 0.0;    // m: the stroke, from the finger servo's control range
  double finger_target = 0.0;  // per side, m
  double finger_command = 0.0;
  double finger_speed = 0.05;
  double finger_squeeze = 0.0;  // per side, m: how far a full close drives the setpoint past closed
  std::uint64_t arm_table_contact_steps = 0;
  arm::Wrench hand;  // a person's hand on the tool (world, at the tool centre point)
  TimePoint hand_until{};

  camera::Intrinsics intrinsics = camera::Intrinsics::fromHorizontalFov(640, 480, 58.0 * M_PI / 180.0);
  DepthNoiseOptions noise;
  std::unique_ptr<GlRenderer> renderer;
  std::vector<float> clean_depth;  // the camera's last depth image, before noise

  SimClock* clock = nullptr;
  int listener = 0;

  // The scene's person, the speed and separation monitor and its record.
  std::unique_ptr<SimPerson> person;
  std::optional<SpeedSeparationMonitor> monitor;  // absent: not monitored
  SpeedSeparationParams ssm_params;
  std::vector<int> arm_geoms;         // the arm's and gripper's colliding geoms
  std::vector<Capsule> arm_previous;  // their capsules one step ago
  bool have_previous = false;
  bool settled = false;
  double lag = 0.0;  // s the override held the present trajectory back
  double scale = 1.0;
  double scale_rate = 0.0;
  std::int64_t sensor_steps = 1;  // steps between separation readings
  double sensed = 1e9;
  SeparationStatus status;
  SeparationRecord record;

  ~Impl() {
    if (clock != nullptr) {
      clock->removeStepListener(listener);
    }
    renderer.reset();
    person.reset();
    jig.reset();
    power_tool.reset();
    cartesian.reset();
    force_torque.reset();
    adaptive.reset();
    if (data != nullptr) {
      mj_deleteData(data);
    }
    if (model != nullptr) {
      mj_deleteModel(model);
    }
  }

  int id(mjtObj type, const char* name) const {
    const int found = mj_name2id(model, type, name);
    if (found < 0) {
      throw std::runtime_error(std::string("the workcell model lacks '") + name + "'");
    }
    return found;
  }

  TimePoint now() const {
    return TimePoint(Duration(static_cast<std::int64_t>(std::llround(steps * model->opt.timestep * 1e9))));
  }

  /// Remembers the camera's mounting as drawn (a camera of the world body: its model pose is
  /// its world pose) and moves it by `offset` (SimulationOptions::camera_offset).
  void mountCamera(const world::Pose& offset) {
    const int cam = rgbd_camera;
    const mjtNum* q = model->cam_quat + 4 * cam;
    world::Pose mujoco_camera = world::Pose::Identity();
    mujoco_camera.linear() = Eigen::Quaterniond(q[0], q[1], q[2], q[3]).normalized().toRotationMatrix();
    mujoco_camera.translation() = Eigen::Map<const Eigen::Vector3d>(model->cam_pos + 3 * cam);
    rgbd_nominal = mujoco_camera * opticalInMujocoCamera();
    camera_moved = offset.matrix() != Eigen::Matrix4d::Identity();
    if (!camera_moved) {
      return;  // the model untouched: not even rounded through a quaternion
    }
    mujoco_camera.linear() = offset.linear() * mujoco_camera.linear();
    mujoco_camera.translation() += offset.translation();
    const Eigen::Quaterniond moved(mujoco_camera.linear());
    model->cam_quat[4 * cam + 0] = moved.w();
    model->cam_quat[4 * cam + 1] = moved.x();
    model->cam_quat[4 * cam + 2] = moved.y();
    model->cam_quat[4 * cam + 3] = moved.z();
    Eigen::Map<Eigen::Vector3d>(model->cam_pos + 3 * cam) = mujoco_camera.translation();
  }

  /// MuJoCo's camera looks along -z with y up; the optical frame looks along +z with y down.
  static world::Pose opticalInMujocoCamera() {
    world::Pose optical = world::Pose::Identity();
    optical.linear() = Eigen::Vector3d(1, -1, -1).asDiagonal();
    return optical;
  }

  world::Pose geomPose(int geom) const {
    world::Pose pose = world::Pose::Identity();
    const mjtNum* r = data->geom_xmat + 9 * geom;
    pose.linear() << r[0], r[1], r[2], r[3], r[4], r[5], r[6], r[7], r[8];
    pose.translation() = Eigen::Map<const Eigen::Vector3d>(data->geom_xpos + 3 * geom);
    return pose;
  }

  world::Pose bodyPose(int body) const {
    world::Pose pose = world::Pose::Identity();
    const mjtNum* r = data->xmat + 9 * body;
    pose.linear() << r[0], r[1], r[2], r[3], r[4], r[5], r[6], r[7], r[8];
    pose.translation() = Eigen::Map<const Eigen::Vector3d>(data->xpos + 3 * body);
    return pose;
  }

  bool isArmBody(int body) const {
    // Every body from shoulder_link down the chain (the gripper included) belongs to the arm.
    for (int b = body; b > 0; b = model->body_parentid[b]) {
      if (b == first_arm_body) {
        return true;
      }
    }
    return false;
  }

  void control() {
    if (cartesian->active()) {
      cartesian->control();
      integral.fill(0.0);  // the joint controller starts afresh when it takes over
    } else {
      jointControl();
    }
    if (adaptive) {
      adaptive->control();
      return;
    }
    // Gripper: the servo setpoint moves toward the target at the commanded speed (a full
    // close: on past closed by the squeeze).
    const double step = finger_speed * model->opt.timestep;
    finger_command += std::clamp(finger_target - finger_squeeze - finger_command, -step, step);
    data->ctrl[finger_actuator] = finger_command;
  }

  void jointControl() {
    // Arm: computed torque, tau = M (qdd_d + Kp e + Kd de + Ki int e) + bias, clamped by the actuators.
    // The speed override (speed and separation monitoring) slows the trajectory's time: its
    // sample at t - lag, velocities scaled by s, accelerations by s^2 plus the velocity times s'.
    const TimePoint t = now() - Duration(static_cast<std::int64_t>(std::llround(lag * 1e9)));
    ArmSetpoint setpoint = setpoint_source ? setpoint_source(t) : held;
    if (setpoint.position.size() != arm_joints || setpoint.velocity.size() != arm_joints ||
        setpoint.acceleration.size() != arm_joints) {
      setpoint = held;  // a setpoint for another arm: hold where the last good one was
    } else if (setpoint_source) {
      held = {setpoint.position, ArmJoints::zero(arm_joints), ArmJoints::zero(arm_joints)};
      if (scale < 1.0 || scale_rate != 0.0) {
        for (int i = 0; i < arm_joints; ++i) {
          setpoint.acceleration[i] = setpoint.acceleration[i] * scale * scale + setpoint.velocity[i] * scale_rate;
          setpoint.velocity[i] *= scale;
        }
      }
      lag += (1.0 - scale) * model->opt.timestep;
    }
    std::fill(acceleration.begin(), acceleration.end(), 0.0);
    bool resting = true;
    for (int i = 0; i < arm_joints; ++i) {
      resting = resting && setpoint.velocity[i] == 0.0 && setpoint.acceleration[i] == 0.0;
    }
    for (int i = 0; i < arm_joints; ++i) {
      const double error = setpoint.position[i] - data->qpos[arm_qpos[i]];
      const double rate_error = setpoint.velocity[i] - data->qvel[arm_dof[i]];
      if (resting) {
        integral[i] = std::clamp(integral[i] + error * model->opt.timestep, -kArmIntegralLimit, kArmIntegralLimit);
      }
      acceleration[arm_dof[i]] = setpoint.acceleration[i] + kArmKp * error + kArmKd * rate_error + kArmKi * integral[i];
    }
    mj_mulM(model, data, torque.data(), acceleration.data());
    for (int i = 0; i < arm_joints; ++i) {
      data->ctrl[i] = torque[arm_dof[i]] + data->qfrc_bias[arm_dof[i]];
    }
  }

  void countTableContacts() {
    for (int i = 0; i < data->ncon; ++i) {
      const mjContact& contact = data->contact[i];
      const int other = contact.geom1 == table_geom ? contact.geom2 : contact.geom2 == table_geom ? contact.geom1 : -1;
      if (other >= 0 && isArmBody(model->geom_bodyid[other])) {
        ++arm_table_contact_steps;
        return;
      }
    }
  }

  /// The separation between the arm's and the person's capsules, and the closest pair.
  double separationNow(int* arm_geom, int* person_geom, std::vector<Capsule>& arm_capsules) const {
    arm_capsules.clear();
    for (const int geom : arm_geoms) {
      arm_capsules.push_back(geomCapsule(model, data, geom));
    }
    double closest = 1e9;
    for (const int other : person->geoms()) {
      const Capsule capsule = geomCapsule(model, data, other);
      for (std::size_t i = 0; i < arm_capsules.size(); ++i) {
        const double distance = capsuleDistance(arm_capsules[i], capsule);
        if (distance < closest) {
          closest = distance;
          *arm_geom = arm_geoms[i];
          *person_geom = other;
        }
      }
    }
    return closest;
  }

  /// Before a physics step: places the person, measures the separation and the arm's speed,
  /// updates the speed override and the record.
  void watchPerson() {
    const double dt = model->opt.timestep;
    // The separation of the step before: a take closes the hand once the robot has withdrawn.
    person->drive(settled ? toSeconds(now()) : -1.0, status.separation);
    mj_kinematics(model, data);
    int arm_geom = -1;
    int person_geom = -1;
    std::vector<Capsule> capsules;
    const double separation = separationNow(&arm_geom, &person_geom, capsules);
    double speed = 0.0;
    if (have_previous) {
      for (std::size_t i = 0; i < capsules.size(); ++i) {
        speed = std::max(
            {speed, (capsules[i].a - arm_previous[i].a).norm() / dt, (capsules[i].b - arm_previous[i].b).norm() / dt});
      }
    }
    arm_previous = std::move(capsules);
    have_previous = true;
    if (steps % sensor_steps == 0) {
      sensed = separation;  // the sensor's reading, held until the next one
    }
    if (monitor) {
      scale = monitor->update(dt, sensed, speed);
      scale_rate = monitor->scaleRate();
    }
    const double protective = protectiveDistance(ssm_params, speed);
    status.separation = separation;
    status.sensed_separation = sensed;
    status.arm_speed = speed;
    status.scale = scale;
    status.protective_distance = protective;
    status.state = monitor ? stateName(monitor->state()) : "off";
    status.collaborative = monitor && monitor->collaborative();
    status.stop_reason = monitor ? monitor->stopReason() : "";
    status.arm_geom = arm_geom >= 0 ? geomName(arm_geom) : "";
    status.person_geom = person_geom >= 0 ? person->geomLabel(person_geom) : "";
    if (!settled) {
      return;
    }
    record.seconds += dt;
    record.min_separation = std::min(record.min_separation, separation);
    // With the override at 0 the controller holds the arm still on its path (it reaches 0 only
    // at the end of braking): the arm moving then was moved by the person, who pushed it (its
    // controller swinging it back afterwards), not of its own accord. Such steps do not count as
    // the arm moving fast; the contact counts apart (recordPersonContact).
    const bool pushed = scale <= 0.0;
    if (speed > SeparationRecord::fast_speed && !pushed) {
      record.fast_seconds += dt;
      record.min_separation_fast = std::min(record.min_separation_fast, separation);
      record.min_margin_fast = std::min(record.min_margin_fast, separation - protective);
      record.violation_steps += separation < protective ? 1 : 0;
    }
    if (monitor) {
      record.collaborative_seconds += monitor->collaborative() ? dt : 0.0;
      record.stops = monitor->stops();
      record.stopped_seconds += scale <= 0.0 && setpoint_source ? dt : 0.0;
    }
  }

  /// After a physics step: the normal force between the arm and the person, counted against
  /// the arm when it was moving (its override above 0), against the person when it was held still.
  void recordPersonContact() {
    double force = 0.0;
    bool hand_only = true;
    for (int i = 0; i < data->ncon; ++i) {
      const mjContact& contact = data->contact[i];
      const bool first = person->isPersonGeom(contact.geom1);
      const bool second = person->isPersonGeom(contact.geom2);
      if (first == second) {
        continue;
      }
      const int other = first ? contact.geom2 : contact.geom1;
      if (!isArmBody(model->geom_bodyid[other])) {
        continue;
      }
      mjtNum wrench[6];
      mj_contactForce(model, data, i, wrench);
      force += std::abs(wrench[0]);
      hand_only = hand_only && person->isHandGeom(first ? contact.geom1 : contact.geom2);
    }
    if (monitor) {
      monitor->setContact(force, hand_only);
    }
    const bool collaborative = monitor && monitor->collaborative();
    if (force > 0.0 && settled && collaborative && hand_only && scale > 0.0) {
      ++record.hand_contact_steps;
      record.max_hand_contact_force = std::max(record.max_hand_contact_force, force);
    } else if (force > 0.0 && settled) {
      if (scale > 0.0) {
        ++record.contact_steps;
        record.max_contact_force = std::max(record.max_contact_force, force);
      } else {
        ++record.stopped_contact_steps;
        record.max_stopped_contact_force = std::max(record.max_stopped_contact_force, force);
      }
    }
  }

  std::string geomName(int geom) const {
    const char* name = mj_id2name(model, mjOBJ_GEOM, geom);
    return name != nullptr ? name : bodyLabel(model->geom_bodyid[geom]);
  }

  /// The hand's wrench on the flange's body, at its centre of mass.
  void applyHand() {
    if (hand_until <= now()) {
      hand = {};
    }
    mjtNum* applied = data->xfrc_applied + 6 * tool_body;
    const Eigen::Vector3d tcp = Eigen::Map<const Eigen::Vector3d>(data->site_xpos + 3 * tcp_site);
    const Eigen::Vector3d com = Eigen::Map<const Eigen::Vector3d>(data->xipos + 3 * tool_body);
    const Eigen::Vector3d about_com = hand.torque + (tcp - com).cross(hand.force);
    for (int i = 0; i < 3; ++i) {
      applied[i] = hand.force[i];
      applied[3 + i] = about_com[i];
    }
  }

  void step() {
    if (person) {
      watchPerson();
    }
    mj_step1(model, data);
    applyHand();
    control();
    mj_step2(model, data);
    if (data->warning[mjWARN_CONTACTFULL].number > 0 || data->warning[mjWARN_CNSTRFULL].number > 0) {
      // MuJoCo would carry on without the contacts that did not fit: wrong physics.
      throw std::runtime_error("physics: more contacts or constraint rows than the workcell model's <size nconmax=" +
                               std::to_string(model->nconmax) + " njmax=" + std::to_string(model->njmax) + "> allows");
    }
    countTableContacts();
    if (person) {
      recordPersonContact();
    }
    ++steps;
    if (jig) {
      jig->afterStep(toSeconds(now()));
    }
    force_torque->sample();
    if (power_tool) {
      power_tool->step();
    }
  }

  /// Which finger of the gripper a geom belongs to (kPalm and up: the palm), -1: not the gripper.
  int handPart(int geom) const {
    constexpr int kPalmPart = 100;
    if (adaptive) {
      if (!adaptive->isGripperGeom(geom)) {
        return -1;
      }
      const int finger = adaptive->fingerOfGeom(geom);
      return finger >= 0 ? finger : kPalmPart;
    }
    const int body = model->geom_bodyid[geom];
    const char* name = mj_id2name(model, mjOBJ_BODY, body);
    const std::string label = name != nullptr ? name : "";
    if (label == "left_finger") {
      return 0;
    }
    if (label == "right_finger") {
      return 1;
    }
    for (int b = body; b > 0; b = model->body_parentid[b]) {
      if (b == tool_body) {
        return kPalmPart;
      }
    }
    return -1;
  }

  double armSpeed() const {
    double fastest = 0.0;
    for (int i = 0; i < arm_joints; ++i) {
      fastest = std::max(fastest, std::abs(data->qvel[arm_dof[i]]));
    }
    return fastest;
  }

  /// The finger a geom belongs to for the jig's watch on the wire: the adaptive gripper's
  /// fingers 0..2, the 2-finger gripper's left (0) and right (1); -1 for any other geom.
  int fingerOfGeom(int geom) const {
    if (adaptive) {
      return adaptive->fingerOfGeom(geom);
    }
    const char* body = mj_id2name(model, mjOBJ_BODY, model->geom_bodyid[geom]);
    const std::string name = body != nullptr ? body : "";
    return name == "left_finger" ? 0 : name == "right_finger" ? 1 : -1;
  }

  /// How far the gripper was last told to close, 0 (open) to 1 (closed).
  double commandedClosure() const {
    return adaptive ? adaptive->commandedClosure() : 1.0 - finger_target / (max_opening / 2);
  }

  /// A geom's label in contacts(): the adaptive gripper's by finger, else its body's.
  std::string geomLabel(int geom) const {
    if (geom == table_geom || geom == table_surface_geom) {
      return "table";
    }
    if (jig) {
      if (std::string label = jig->geomLabel(geom); !label.empty()) {
        return label;
      }
    }
    if (person && person->isPersonGeom(geom)) {
      return person->geomLabel(geom);
    }
    if (adaptive && adaptive->isGripperGeom(geom)) {
      const int finger = adaptive->fingerOfGeom(geom);
      return finger >= 0 ? std::string(gripper::kFingerNames[static_cast<std::size_t>(finger)]) : "palm";
    }
    return bodyLabel(model->geom_bodyid[geom]);
  }

  void requireParallel(const char* what) const {
    if (adaptive) {
      throw std::logic_error(std::string("Simulation::") + what +
                             ": this cell's gripper is the 3-finger adaptive gripper '" + adaptive->description().name +
                             "' (use adaptiveGripper())");
    }
  }

  std::string bodyLabel(int body) const {
    if (body == 0) {
      return "world";
    }
    for (std::size_t i = 0; i < part_bodies.size(); ++i) {
      if (part_bodies[i] == body) {
        return placements[i].name;
      }
    }
    const char* name = mj_id2name(model, mjOBJ_BODY, body);
    const std::string label = name != nullptr ? name : "body";
    if (label == "left_finger" || label == "right_finger") {
      return label;
    }
    return isArmBody(body) ? "arm" : label;
  }
};

Simulation::Simulation(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Simulation::~Simulation() = default;

std::unique_ptr<Simulation> Simulation::create(const Scene& scene, const SimulationOptions& options) {
  // MuJoCo's warnings ("Nan, Inf or huge value in QACC ...") go to standard error like the rest
  // of the log, not to a MUJOCO_LOG.TXT it would write in whatever folder the user ran from.
  static std::once_flag route_warnings;
  std::call_once(route_warnings, [] {
    mju_user_warning = [](const char* message) { std::fprintf(stderr, "MuJoCo warning: %s\n", message); };
  });
  auto impl = std::make_unique<Impl>();
  const std::filesystem::path root = options.data_root.empty() ? dataRoot() : options.data_root;
  impl->classes = world::loadObjectClasses(root / "data" / "objects");
  impl->placements = placeParts(scene, impl->classes, options.placement_seed);
  // Spares: parked 1.6 m out on the robot's left, 20 cm apart, resting on the table top's
  // plane (a plane is endless to MuJoCo: below it a part would be thrown up).
  for (std::size_t i = 0; i < options.spare_classes.size(); ++i) {
    const std::string& name = options.spare_classes[i];
    const auto object = std::find_if(impl->classes.begin(), impl->classes.end(),
                                     [&](const world::ObjectClass& c) { return c.name == name; });
    if (object == impl->classes.end() || object->colors.empty()) {
      throw std::runtime_error("spare part: unknown object class '" + name + "'");
    }
    const auto same = std::count_if(impl->placements.begin(), impl->placements.end(),
                                    [&](const PartPlacement& p) { return p.object_class == name; });
    PartPlacement spare;
    spare.name = name + "_" + std::to_string(same);
    spare.object_class = name;
    spare.color = object->colors.front().first;
    spare.pose = world::Pose::Identity();
    spare.pose.translation() = Eigen::Vector3d(0.4 + 0.2 * static_cast<double>(i), 1.6, object->rest_height);
    impl->placements.push_back(std::move(spare));
  }
  impl->noise = options.depth_noise;

  // The robot: its description names the model, the joints, home and links. The default
  // robot's model files are read from `root`, like everything else.
  const arm::RobotDescription robot =
      options.robot ? *options.robot : arm::loadRobotDescription(arm::robotDescriptionFile(kDefaultRobot, root));
  const std::optional<world::Pose> robot_base =
      options.robot_base || options.robot ? options.robot_base : std::optional<world::Pose>(defaultRobotBase());

  // Model: the cell, the robot and its gripper composed, plus a material per class colour and
  // a body per part.
  const auto under_root = [&root](const std::filesystem::path& path) {
    return path.is_absolute() ? path : root / path;
  };
  std::optional<gripper::AdaptiveGripperDescription> adaptive;
  if (!options.adaptive_gripper.empty()) {
    adaptive = gripper::loadAdaptiveGripperDescription(gripper::gripperDescriptionFile(options.adaptive_gripper, root));
  }
  std::string xml = composeCellModel({under_root(options.cell_model), robot.mjcf,
                                      options.gripper_model.empty()
                                          ? std::filesystem::path(COSTAR_GRIPPER_MODEL_DIR) / "parallel-2f_mount.xml"
                                          : under_root(options.gripper_model),
                                      robot.urdf_tool_link, robot_base, kForceTorqueSite, kForceSensor, kTorqueSensor});
  std::string assets;
  for (const auto& object : impl->classes) {
    for (const auto& [color_name, rgb] : object.colors) {
      assets += "<material name=\"" + object.name + "_" + color_name + "\" rgba=\"" + vec(rgb) +
                " 1\" specular=\"0.2\" shininess=\"0.3\"/>\n";
    }
  }
  std::string bodies;
  for (const auto& part : impl->placements) {
    const auto object = std::find_if(impl->classes.begin(), impl->classes.end(),
                                     [&](const world::ObjectClass& c) { return c.name == part.object_class; });
    bodies += partBody(part, *object);
  }
  // The bending jig and its wire, drawn for this placement seed (sim/wire.h).
  std::optional<WireMaterial> material;
  std::optional<JigDraw> jig_draw;
  if (scene.jig) {
    if (scene.wire) {
      const std::vector<WireMaterial> materials = loadWireMaterials(root / "data/wire_materials.json");
      std::string known;
      for (const WireMaterial& candidate : materials) {
        if (candidate.name == scene.wire->material) {
          material = candidate;
        }
        known += (known.empty() ? "" : ", ") + candidate.name;
      }
      if (!material) {
        throw std::runtime_error("scene '" + scene.label + "': wire.material: unknown material '" +
                                 scene.wire->material + "' (known: " + known + ")");
      }
    }
    jig_draw =
        drawJig(*scene.jig, scene.wire, material ? &*material : nullptr, options.placement_seed.value_or(scene.seed));
    bodies += jigMjcf(*scene.jig, scene.wire, material ? &*material : nullptr, *jig_draw, modelTimestep(xml));
  }
  if (scene.power_tool && !options.power_tool) {
    throw std::runtime_error("scene '" + scene.label +
                             "' puts the power tool on its stand, but this workcell has no power tool");
  }
  if (options.power_tool || scene.workpiece) {
    assets += powerToolAssets();
    bodies += powerToolBodies(options.power_tool ? &*options.power_tool : nullptr, scene.power_tool,
                              scene.workpiece ? &*scene.workpiece : nullptr);
  }
  if (scene.person) {
    bodies += personBodiesMjcf(*scene.person);
    const auto actuators = xml.rfind("</actuator>");
    if (actuators == std::string::npos) {
      throw std::runtime_error("the workcell model has no <actuator> section for the person's fingers");
    }
    xml.insert(actuators, personActuatorsMjcf());
    const auto end = xml.rfind("</mujoco>");
    if (end == std::string::npos) {
      throw std::runtime_error("the workcell model has no </mujoco>");
    }
    xml.insert(end, personEqualityMjcf());
  }
  replaceMarker(xml, "<!--PART_ASSETS-->", assets);
  replaceMarker(xml, "<!--PARTS-->", bodies);

  mjVFS vfs;
  mj_defaultVFS(&vfs);
  const char* kModelName = "workcell.xml";
  if (mj_makeEmptyFileVFS(&vfs, kModelName, static_cast<int>(xml.size())) != 0) {
    throw std::runtime_error("MuJoCo: cannot allocate the model in memory");
  }
  const int file = mj_findFileVFS(&vfs, kModelName);
  std::memcpy(vfs.filedata[file], xml.data(), xml.size());
  char error[1024] = "";
  impl->model = mj_loadXML(kModelName, &vfs, error, sizeof error);
  mj_deleteVFS(&vfs);
  if (impl->model == nullptr) {
    throw std::runtime_error(std::string("MuJoCo cannot load the workcell for scene '") + scene.label + "': " + error);
  }
  impl->data = mj_makeData(impl->model);
  mjModel* m = impl->model;
  if (scene.wire) {
    // The wire's chain puts the model at 60 degrees of freedom and more, where MuJoCo's "auto"
    // picks sparse constraint Jacobians; their rows run down the chain's one branch, so they are
    // not sparse, and the dense ones give the same solution 1.5 times faster (docs/WIRE_BENDING.md).
    m->opt.jacobian = mjJAC_DENSE;
  }

  impl->arm_joint_names = robot.joint_names;
  impl->arm_joints = robot.jointCount();
  for (int i = 0; i < impl->arm_joints; ++i) {
    if (mj_name2id(m, mjOBJ_JOINT, robot.joint_names[i].c_str()) < 0) {  // a description edited by hand
      throw std::runtime_error("robot description '" + robot.file.string() + "': joints[" + std::to_string(i) +
                               "]: the simulator's model '" + robot.mjcf.string() + "' has no joint '" +
                               robot.joint_names[i] + "'");
    }
    const int joint = impl->id(mjOBJ_JOINT, robot.joint_names[i].c_str());
    impl->arm_qpos[i] = m->jnt_qposadr[joint];
    impl->arm_dof[i] = m->jnt_dofadr[joint];
  }
  if (adaptive) {
    Impl* raw = impl.get();
    impl->adaptive =
        std::make_unique<SimAdaptiveGripper>(m, impl->data, std::move(*adaptive), [raw] { return raw->now(); });
  } else {
    const int finger_joint = impl->id(mjOBJ_JOINT, "left_finger_joint");
    impl->finger_qpos = m->jnt_qposadr[finger_joint];
    impl->finger_dof = m->jnt_dofadr[finger_joint];
    impl->finger_actuator = impl->id(mjOBJ_ACTUATOR, "fingers");
    impl->max_opening = 2.0 * m->actuator_ctrlrange[2 * impl->finger_actuator + 1];
    if (!(impl->max_opening > 0.0)) {
      throw std::runtime_error(
          "the gripper model's finger servo 'fingers' has no control range above 0: its "
          "ctrlrange's upper end is half the stroke");
    }
    impl->finger_target = impl->finger_command = impl->max_opening / 2;
    impl->left_pad = impl->id(mjOBJ_GEOM, "left_pad");
    impl->right_pad = impl->id(mjOBJ_GEOM, "right_pad");
  }
  {
    Impl* raw = impl.get();
    impl->force_torque =
        std::make_unique<SimForceTorqueSensor>(m, impl->data, options.placement_seed.value_or(scene.seed),
                                               options.force_torque_noise, [raw] { return raw->now(); });
    std::vector<int> dofs;
    std::vector<int> qpos;
    for (int i = 0; i < impl->arm_joints; ++i) {
      dofs.push_back(impl->arm_dof[i]);
      qpos.push_back(impl->arm_qpos[i]);
    }
    impl->cartesian = std::make_unique<SimCartesianController>(m, impl->data, "tcp", std::move(dofs), std::move(qpos),
                                                               *impl->force_torque, [raw] { return raw->now(); });
  }
  if (options.power_tool || scene.workpiece) {
    Impl* raw = impl.get();
    impl->power_tool = std::make_unique<SimPowerTool>(
        m, impl->data, options.power_tool, scene.workpiece, scene.power_tool,
        [raw](int geom) { return raw->handPart(geom); },
        [raw](int geom) { return raw->isArmBody(raw->model->geom_bodyid[geom]); }, [raw] { return raw->armSpeed(); },
        [raw] { return raw->now(); });
  }
  impl->table_geom = impl->id(mjOBJ_GEOM, "table");
  impl->table_surface_geom = impl->id(mjOBJ_GEOM, "table_surface");
  impl->tcp_site = impl->id(mjOBJ_SITE, "tcp");
  impl->rgbd_camera = impl->id(mjOBJ_CAMERA, "rgbd");
  impl->first_arm_body = impl->id(mjOBJ_BODY, robot.first_moving_link.c_str());
  impl->gripper_marker_geom = impl->id(mjOBJ_GEOM, "gripper_marker");
  impl->mountCamera(options.camera_offset.value_or(
      scene.camera_offset ? cameraOffsetPose(*scene.camera_offset, options.placement_seed.value_or(scene.seed))
                          : world::Pose::Identity()));
  impl->tool_body = impl->id(mjOBJ_BODY, robot.urdf_tool_link.c_str());  // the flange, as the robot names it
  if (robot_base) {
    mj_kinematics(m, impl->data);
    const world::Pose base = impl->bodyPose(impl->id(mjOBJ_BODY, robot.base_link.c_str()));
    if ((base.matrix() - robot_base->matrix()).cwiseAbs().maxCoeff() > 1e-9) {
      throw std::runtime_error("the robot's base body '" + robot.base_link + "' stands at " + vec(base.translation()) +
                               " in the model, the workcell says " + vec(robot_base->translation()) +
                               " (or turned otherwise)");
    }
  }
  for (const auto& part : impl->placements) {
    impl->part_bodies.push_back(impl->id(mjOBJ_BODY, part.name.c_str()));
  }
  if (scene.person) {
    impl->person = std::make_unique<SimPerson>(m, impl->data, *scene.person,
                                               options.placement_seed.value_or(scene.seed), impl->part_bodies);
    for (int geom = 0; geom < m->ngeom; ++geom) {
      if (impl->isArmBody(m->geom_bodyid[geom]) && (m->geom_contype[geom] != 0 || m->geom_conaffinity[geom] != 0)) {
        impl->arm_geoms.push_back(geom);
      }
    }
    impl->ssm_params = options.speed_separation;
    impl->ssm_params.control_period = m->opt.timestep;
    impl->sensor_steps =
        std::max<std::int64_t>(1, std::llround(options.speed_separation.sensor_period / m->opt.timestep));
    impl->ssm_params.sensor_period = static_cast<double>(impl->sensor_steps) * m->opt.timestep;
    if (options.speed_separation_monitoring) {
      impl->monitor.emplace(impl->ssm_params);
    }
  }
  if (scene.jig) {
    const Impl* raw = impl.get();
    SimJig::Gripper gripper{[raw](int geom) { return raw->fingerOfGeom(geom); },
                            [raw] { return raw->commandedClosure(); }, impl->tcp_site};
    impl->jig = std::make_unique<SimJig>(m, impl->data, *scene.jig, scene.wire, *jig_draw, std::move(gripper));
  }
  // Square pixels, principal point at the centre, focal length from the model's fovy.
  const double fovy = m->cam_fovy[impl->rgbd_camera] * M_PI / 180.0;
  impl->intrinsics.fy = impl->intrinsics.height / (2.0 * std::tan(fovy / 2.0));
  impl->intrinsics.fx = impl->intrinsics.fy;
  impl->acceleration.assign(m->nv, 0.0);
  impl->torque.assign(m->nv, 0.0);

  // Start at the initial configuration, fingers open, and let the parts settle.
  const ArmJoints initial = options.initial_arm.value_or(robot.home);
  if (initial.size() != impl->arm_joints) {
    throw std::runtime_error("the initial arm configuration has " + std::to_string(initial.size()) +
                             " joints, the arm " + std::to_string(impl->arm_joints));
  }
  for (int i = 0; i < impl->arm_joints; ++i) {
    impl->data->qpos[impl->arm_qpos[i]] = initial[i];
  }
  impl->held = {initial, ArmJoints::zero(impl->arm_joints), ArmJoints::zero(impl->arm_joints)};
  if (impl->adaptive) {
    impl->adaptive->reset(gripper::GripperMode::kBasic);
  } else {
    impl->data->qpos[impl->finger_qpos] = impl->max_opening / 2;
    impl->data->qpos[m->jnt_qposadr[impl->id(mjOBJ_JOINT, "right_finger_joint")]] = impl->max_opening / 2;
  }
  mj_forward(m, impl->data);
  const auto settle = static_cast<std::int64_t>(std::ceil(options.settle_seconds / m->opt.timestep));
  for (std::int64_t i = 0; i < settle; ++i) {
    impl->step();
  }
  impl->settle_steps = settle;
  impl->steps = 0;
  impl->settled = true;
  impl->arm_table_contact_steps = 0;
  return std::unique_ptr<Simulation>(new Simulation(std::move(impl)));
}

TimePoint Simulation::time() const { return impl_->now(); }

Duration Simulation::timestep() const {
  return Duration(static_cast<std::int64_t>(std::llround(impl_->model->opt.timestep * 1e9)));
}

void Simulation::stepTo(TimePoint t) {
  const double dt = impl_->model->opt.timestep;
  const auto target = static_cast<std::int64_t>(std::floor(toSeconds(t) / dt + 1e-9));
  while (impl_->steps < target) {
    impl_->step();
  }
}

void Simulation::attach(SimClock& clock) {
  detach();
  impl_->clock = &clock;
  impl_->listener = clock.addStepListener([this](TimePoint, TimePoint to) { stepTo(to); });
}

void Simulation::detach() {
  if (impl_->clock != nullptr) {
    impl_->clock->removeStepListener(impl_->listener);
    impl_->clock = nullptr;
  }
}

const std::vector<std::string>& Simulation::armJointNames() const { return impl_->arm_joint_names; }

ArmJoints Simulation::armPositions() const {
  ArmJoints q = ArmJoints::zero(impl_->arm_joints);
  for (int i = 0; i < impl_->arm_joints; ++i) {
    q[i] = impl_->data->qpos[impl_->arm_qpos[i]];
  }
  return q;
}

ArmJoints Simulation::armVelocities() const {
  ArmJoints v = ArmJoints::zero(impl_->arm_joints);
  for (int i = 0; i < impl_->arm_joints; ++i) {
    v[i] = impl_->data->qvel[impl_->arm_dof[i]];
  }
  return v;
}

void Simulation::setArmSetpointSource(std::function<ArmSetpoint(TimePoint)> source) {
  impl_->lag = 0.0;
  if (impl_->cartesian->active()) {
    // The joint controller takes over from where the arm is.
    impl_->held = {armPositions(), ArmJoints::zero(impl_->arm_joints), ArmJoints::zero(impl_->arm_joints)};
    impl_->cartesian->release();
  }
  impl_->setpoint_source = std::move(source);
}

arm::ForceTorqueSensor& Simulation::forceTorqueSensor() { return *impl_->force_torque; }

arm::CartesianController& Simulation::cartesianController() { return *impl_->cartesian; }

arm::Wrench Simulation::trueFlangeWrench() const { return impl_->force_torque->truth(); }

arm::Payload Simulation::toolPayload() const {
  const mjModel* m = impl_->model;
  const mjData* d = impl_->data;
  const int body = impl_->tool_body;
  const Eigen::Matrix3d rotation = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(d->xmat + 9 * body);
  const Eigen::Vector3d origin = Eigen::Map<const Eigen::Vector3d>(d->xpos + 3 * body);
  // subtree_com is the centre of mass of the body and its descendants, in the world.
  const Eigen::Vector3d com = Eigen::Map<const Eigen::Vector3d>(d->subtree_com + 3 * body);
  return {m->body_subtreemass[body], rotation.transpose() * (com - origin)};
}

void Simulation::setHandWrench(const arm::Wrench& at_tcp, Duration hold) {
  if (!at_tcp.force.allFinite() || !at_tcp.torque.allFinite()) {
    throw std::invalid_argument("the hand's wrench is not finite");
  }
  impl_->hand = at_tcp;
  impl_->hand_until = time() + hold;
}

arm::Wrench Simulation::handWrench() const { return impl_->hand; }

world::Pose Simulation::tcpPose() const {
  const mjData* d = impl_->data;
  world::Pose pose = world::Pose::Identity();
  const mjtNum* r = d->site_xmat + 9 * impl_->tcp_site;
  pose.linear() << r[0], r[1], r[2], r[3], r[4], r[5], r[6], r[7], r[8];
  pose.translation() = Eigen::Map<const Eigen::Vector3d>(d->site_xpos + 3 * impl_->tcp_site);
  return pose;
}

std::uint64_t Simulation::armTableContactSteps() const { return impl_->arm_table_contact_steps; }

double Simulation::maxOpening() const {
  impl_->requireParallel("maxOpening");
  return impl_->max_opening;
}

FingerState Simulation::fingers() const {
  impl_->requireParallel("fingers");
  const mjData* d = impl_->data;
  FingerState state;
  state.opening = 2.0 * d->qpos[impl_->finger_qpos];
  state.opening_speed = 2.0 * d->qvel[impl_->finger_dof];
  state.force = -d->actuator_force[impl_->finger_actuator];
  for (int i = 0; i < d->ncon; ++i) {
    const mjContact& contact = d->contact[i];
    for (const int pad : {impl_->left_pad, impl_->right_pad}) {
      if (contact.geom1 == pad || contact.geom2 == pad) {
        const int other = contact.geom1 == pad ? contact.geom2 : contact.geom1;
        if (other != impl_->left_pad && other != impl_->right_pad) {
          state.pads_in_contact = true;
        }
      }
    }
  }
  return state;
}

void Simulation::commandFingers(double opening, double speed, double force) {
  impl_->requireParallel("commandFingers");
  // A new command starts from where the fingers are (not from the previous setpoint).
  impl_->finger_command = impl_->data->qpos[impl_->finger_qpos];
  impl_->finger_target = std::clamp(opening, 0.0, impl_->max_opening) / 2.0;
  impl_->finger_speed = std::max(speed, 1e-3) / 2.0;
  const double limit = std::clamp(force, 1.0, 200.0);
  // The grip force limit: MuJoCo 2.2.2 clamps an actuator's force by mjModel's range only (no
  // mjData counterpart); the model is this simulation's own (each Simulation loads one).
  mjModel* model = impl_->model;
  const int actuator = impl_->finger_actuator;
  model->actuator_forcerange[2 * actuator] = -limit;
  model->actuator_forcerange[2 * actuator + 1] = limit;
  // A full close presses whatever is between the fingers with the set force, as an electric
  // gripper's motor current does. The position servo pushes by its gain times how far its
  // setpoint is past where the fingers stopped: with the setpoint at closed, a 2 mm wire got
  // 3 N of a 20 N close (kp 3000 N/m, 1 mm a side) and turned and slid in the pads while it was
  // bent. So the setpoint goes on past closed by the limit's worth, within a control range
  // widened to match; with nothing between, the finger joints' limit takes the push.
  impl_->finger_squeeze = impl_->finger_target <= 0.0 ? limit / model->actuator_gainprm[mjNGAIN * actuator] : 0.0;
  model->actuator_ctrlrange[2 * actuator] = -impl_->finger_squeeze;
}

gripper::AdaptiveGripperDriver* Simulation::adaptiveGripper() { return impl_->adaptive.get(); }

SimPowerTool* Simulation::powerTool() { return impl_->power_tool.get(); }

const camera::Intrinsics& Simulation::rgbdIntrinsics() const { return impl_->intrinsics; }

world::Pose Simulation::rgbdPose() const {
  const mjData* d = impl_->data;
  const int cam = impl_->rgbd_camera;
  world::Pose mujoco_camera = world::Pose::Identity();
  const mjtNum* r = d->cam_xmat + 9 * cam;
  mujoco_camera.linear() << r[0], r[1], r[2], r[3], r[4], r[5], r[6], r[7], r[8];
  mujoco_camera.translation() = Eigen::Map<const Eigen::Vector3d>(d->cam_xpos + 3 * cam);
  // MuJoCo's camera looks along -z with y up; the optical frame looks along +z with y down.
  world::Pose optical = world::Pose::Identity();
  optical.linear() = Eigen::Vector3d(1, -1, -1).asDiagonal();
  return mujoco_camera * optical;
}

world::Pose Simulation::rgbdNominalPose() const {
  // Not moved: exactly the pose MuJoCo puts the camera at (the drawing's quaternion through
  // MuJoCo's own arithmetic), so a cell that believes its drawings sees what it saw before.
  return impl_->camera_moved ? impl_->rgbd_nominal : rgbdPose();
}

world::Pose Simulation::gripperMarkerPose() const { return impl_->geomPose(impl_->gripper_marker_geom); }

world::Pose Simulation::gripperMarkerInFlange() const {
  return impl_->bodyPose(impl_->tool_body).inverse() * gripperMarkerPose();
}

camera::RgbdFrame Simulation::captureRgbd(std::uint64_t noise_seed, bool colour) {
  if (!impl_->renderer) {
    impl_->renderer = std::make_unique<GlRenderer>(impl_->model);
  }
  const camera::Intrinsics& in = impl_->intrinsics;
  camera::RgbdFrame frame;
  frame.intrinsics = in;
  frame.stamp = time();
  frame.camera_pose = rgbdPose();
  impl_->renderer->render(impl_->model, impl_->data, impl_->rgbd_camera, in.width, in.height,
                          colour ? &frame.rgb : nullptr, &impl_->clean_depth);
  noisyPointCloud(impl_->clean_depth, in, impl_->noise, noise_seed, frame.points, kNoiseThreads);
  return frame;
}

RgbImage Simulation::renderImage(const std::string& camera, int width, int height) {
  if (!impl_->renderer) {
    impl_->renderer = std::make_unique<GlRenderer>(impl_->model);
  }
  const int id = impl_->id(mjOBJ_CAMERA, camera.c_str());
  RgbImage image;
  impl_->renderer->render(impl_->model, impl_->data, id, width, height, &image, nullptr);
  return image;
}

std::vector<PartState> Simulation::parts() const {
  std::vector<PartState> states;
  const mjData* d = impl_->data;
  for (std::size_t i = 0; i < impl_->placements.size(); ++i) {
    const int body = impl_->part_bodies[i];
    PartState state;
    state.name = impl_->placements[i].name;
    state.object_class = impl_->placements[i].object_class;
    state.color = impl_->placements[i].color;
    const mjtNum* q = d->xquat + 4 * body;
    state.pose = world::Pose::Identity();
    state.pose.linear() = Eigen::Quaterniond(q[0], q[1], q[2], q[3]).normalized().toRotationMatrix();
    state.pose.translation() = Eigen::Map<const Eigen::Vector3d>(d->xpos + 3 * body);
    const int dof = impl_->model->jnt_dofadr[impl_->model->body_jntadr[body]];
    state.linear_velocity = Eigen::Map<const Eigen::Vector3d>(d->qvel + dof);
    states.push_back(std::move(state));
  }
  return states;
}

void Simulation::movePart(const std::string& name, const world::Pose& pose) {
  for (std::size_t i = 0; i < impl_->placements.size(); ++i) {
    if (impl_->placements[i].name != name) {
      continue;
    }
    const mjModel* m = impl_->model;
    mjData* d = impl_->data;
    const int joint = m->body_jntadr[impl_->part_bodies[i]];
    mjtNum* q = d->qpos + m->jnt_qposadr[joint];
    const Eigen::Quaterniond rotation(pose.linear());
    q[0] = pose.translation().x();
    q[1] = pose.translation().y();
    q[2] = pose.translation().z();
    q[3] = rotation.w();
    q[4] = rotation.x();
    q[5] = rotation.y();
    q[6] = rotation.z();
    std::fill_n(d->qvel + m->jnt_dofadr[joint], 6, 0.0);
    mj_forward(m, d);
    return;
  }
  throw std::invalid_argument("Simulation::movePart: no part '" + name + "'");
}

std::vector<std::pair<std::string, std::string>> Simulation::contacts() const {
  std::vector<std::pair<std::string, std::string>> pairs;
  const mjData* d = impl_->data;
  for (int i = 0; i < d->ncon; ++i) {
    const mjContact& contact = d->contact[i];
    std::string a = impl_->geomLabel(contact.geom1);
    std::string b = impl_->geomLabel(contact.geom2);
    if (a > b) {
      std::swap(a, b);
    }
    const std::pair<std::string, std::string> pair{a, b};
    if (std::find(pairs.begin(), pairs.end(), pair) == pairs.end()) {
      pairs.push_back(pair);
    }
  }
  return pairs;
}

const std::vector<world::ObjectClass>& Simulation::objectClasses() const { return impl_->classes; }

std::optional<JigState> Simulation::jig() const {
  if (!impl_->jig) {
    return std::nullopt;
  }
  return impl_->jig->state();
}

std::optional<PersonPose> Simulation::person() const {
  if (!impl_->person) {
    return std::nullopt;
  }
  return impl_->person->pose();
}

std::optional<SeparationStatus> Simulation::separation() const {
  if (!impl_->person) {
    return std::nullopt;
  }
  return impl_->status;
}

std::optional<SeparationRecord> Simulation::separationRecord() const {
  if (!impl_->person) {
    return std::nullopt;
  }
  return impl_->record;
}

void Simulation::setStopInput(bool stop) {
  if (!impl_->monitor) {
    throw std::logic_error(
        "Simulation::setStopInput: no speed and separation monitor (no person in the scene, or "
        "monitoring off)");
  }
  impl_->monitor->setStopInput(stop);
}

void Simulation::setCollaborative(bool on) {
  if (!impl_->monitor) {
    throw std::logic_error(
        "Simulation::setCollaborative: no speed and separation monitor (no person in the scene, or "
        "monitoring off)");
  }
  impl_->monitor->setCollaborative(on);
}

Duration Simulation::trajectoryLag() const {
  return Duration(static_cast<std::int64_t>(std::llround(impl_->lag * 1e9)));
}

}  // namespace costar::sim
