#include "sim/gripper_bench.h"

#include <mujoco/mujoco.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <sstream>
#include <stdexcept>

#include "component/component.h"
#include "core/paths.h"
#include "gripper/adaptive_gripper.h"
#include "sim/adaptive_gripper_sim.h"
#include "world/object_class.h"
#include "world/world_state.h"

namespace costar::sim {

namespace {

std::string format(double value) {
  std::ostringstream out;
  out.precision(9);
  out << value;
  return out.str();
}

std::string vec(const Eigen::Vector3d& v) { return format(v.x()) + " " + format(v.y()) + " " + format(v.z()); }

/// The bench around a flange body named "flange": a table (a plane for the part, a box for the
/// gripper, the UR5 cell's contact groups) and a carrier with x, y, z slides and a yaw hinge,
/// each driven by a stiff position servo. The flange points down (rotated 180 degrees about x).
std::string benchModel(const world::ObjectClass& part, const Eigen::Vector3d& part_position, double part_yaw) {
  const Eigen::AlignedBox3d bounds = part.bounds();
  const Eigen::Vector3d half = bounds.sizes() / 2;
  const double density = part.mass / (8.0 * half.prod());
  return R"(<mujoco model="gripper_bench">
  <compiler angle="radian" autolimits="true"/>
  <option timestep="0.002" cone="elliptic" impratio="10" integrator="Euler"/>
  <size nconmax="200" njmax="600"/>
  <worldbody>
    <light pos="0 -0.6 1.5" dir="0 0.4 -1"/>
    <geom name="table_surface" type="plane" pos="0 0 0" size="0.5 0.5 0.01" contype="1" conaffinity="1"
          friction="0.5 0.005 0.0001"/>
    <geom name="table" type="box" pos="0 0 -0.02" size="0.5 0.5 0.02" contype="0" conaffinity="2" rgba="0.78 0.76 0.72 1"/>
    <body name="carrier" pos="0 0 0">
      <joint name="carrier_x" type="slide" axis="1 0 0" damping="600" armature="1"/>
      <joint name="carrier_y" type="slide" axis="0 1 0" damping="600" armature="1"/>
      <joint name="carrier_z" type="slide" axis="0 0 1" damping="600" armature="1"/>
      <joint name="carrier_yaw" type="hinge" axis="0 0 1" damping="8" armature="0.05"/>
      <geom name="carrier" type="cylinder" pos="0 0 0.03" size="0.03 0.03" mass="1" contype="0" conaffinity="0"/>
      <body name="flange" quat="0 1 0 0">
      </body>
    </body>
    <body name="part" pos=")" +
         vec(part_position) + R"(" quat=")" + format(std::cos(part_yaw / 2)) + " 0 0 " +
         format(std::sin(part_yaw / 2)) +
         R"("><freejoint/>
      <geom name="part" type="box" pos=")" +
         vec(bounds.center()) + "\" size=\"" + vec(half) + "\" density=\"" + format(density) +
         R"(" contype="1" conaffinity="3" condim="3" friction="0.8 0.005 0.0005" solref="0.004 1" rgba="0.8 0.3 0.2 1"/>
    </body>
  </worldbody>
  <actuator>
    <position name="carrier_x" joint="carrier_x" kp="40000"/>
    <position name="carrier_y" joint="carrier_y" kp="40000"/>
    <position name="carrier_z" joint="carrier_z" kp="40000"/>
    <position name="carrier_yaw" joint="carrier_yaw" kp="400"/>
  </actuator>
</mujoco>
)";
}

}  // namespace

struct GripperBench::Impl {
  mjModel* model = nullptr;
  mjData* data = nullptr;
  std::unique_ptr<SimAdaptiveGripper> gripper;
  world::ObjectClass part_class;
  int part_body = -1;
  int part_geom = -1;
  int table_surface = -1;
  int table = -1;
  int flange_body = -1;
  std::array<int, 4> carrier_qpos{};  // x, y, z, yaw
  std::array<int, 4> carrier_dof{};
  int carrier_z_dof = -1;
  double carried_mass = 0.0;                           // carrier and gripper: gravity compensation on the z slide
  Eigen::Vector4d setpoint = Eigen::Vector4d::Zero();  // x, y, z (of the carrier), yaw
  Eigen::Vector4d goal = Eigen::Vector4d::Zero();
  double speed = 0.1;
  std::int64_t steps = 0;
  std::int64_t settle_steps = 0;
  SimClock* clock = nullptr;
  int listener = 0;

  ~Impl() {
    if (clock != nullptr) {
      clock->removeStepListener(listener);
    }
    gripper.reset();
    if (data != nullptr) {
      mj_deleteData(data);
    }
    if (model != nullptr) {
      mj_deleteModel(model);
    }
  }

  TimePoint now() const {
    return TimePoint{} + std::chrono::nanoseconds(static_cast<std::int64_t>(
                             std::llround(static_cast<double>(steps) * model->opt.timestep * 1e9)));
  }

  void step() {
    // The carrier's setpoint moves toward its goal: the position in a straight line at the
    // speed, the yaw at 1 rad/s.
    const double dt = model->opt.timestep;
    const Eigen::Vector3d delta = goal.head<3>() - setpoint.head<3>();
    const double distance = delta.norm();
    const double stride = speed * dt;
    setpoint.head<3>() =
        distance <= stride ? goal.head<3>().eval() : (setpoint.head<3>() + delta * (stride / distance)).eval();
    setpoint[3] += std::clamp(goal[3] - setpoint[3], -dt, dt);
    for (int i = 0; i < 4; ++i) {
      data->ctrl[i] = setpoint[i];
    }
    data->qfrc_applied[carrier_z_dof] = carried_mass * -model->opt.gravity[2];
    gripper->control();
    mj_step(model, data);
    ++steps;
  }
};

GripperBench::GripperBench(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
GripperBench::~GripperBench() = default;

std::unique_ptr<GripperBench> GripperBench::create(const GripperBenchOptions& options) {
  auto impl = std::make_unique<Impl>();
  const std::filesystem::path root = options.data_root.empty() ? dataRoot() : options.data_root;
  gripper::AdaptiveGripperDescription description =
      gripper::loadAdaptiveGripperDescription(gripper::gripperDescriptionFile(options.gripper, root));
  impl->part_class = world::loadObjectClass(root / "data" / "objects" / (options.part_class + ".json"));
  const Eigen::Vector3d part_position(options.part_x, options.part_y, impl->part_class.rest_height);

  std::string xml = benchModel(impl->part_class, part_position, options.part_yaw);
  mountAdaptiveGripper(xml, "flange", gripperModelFiles(options.gripper, options.model_dir));

  mjVFS vfs;
  mj_defaultVFS(&vfs);
  const char* kModelName = "gripper_bench.xml";
  if (mj_makeEmptyFileVFS(&vfs, kModelName, static_cast<int>(xml.size())) != 0) {
    throw std::runtime_error("MuJoCo: cannot allocate the model in memory");
  }
  const int file = mj_findFileVFS(&vfs, kModelName);
  std::memcpy(vfs.filedata[file], xml.data(), xml.size());
  char error[1024] = "";
  impl->model = mj_loadXML(kModelName, &vfs, error, sizeof error);
  mj_deleteVFS(&vfs);
  if (impl->model == nullptr) {
    throw std::runtime_error(std::string("MuJoCo cannot load the gripper bench: ") + error);
  }
  impl->data = mj_makeData(impl->model);
  mjModel* m = impl->model;
  Impl* raw = impl.get();
  impl->gripper = std::make_unique<SimAdaptiveGripper>(m, impl->data, description, [raw] { return raw->now(); });
  const char* carrier_joints[] = {"carrier_x", "carrier_y", "carrier_z", "carrier_yaw"};
  for (int i = 0; i < 4; ++i) {
    const int joint = mj_name2id(m, mjOBJ_JOINT, carrier_joints[i]);
    impl->carrier_qpos[static_cast<std::size_t>(i)] = m->jnt_qposadr[joint];
    impl->carrier_dof[static_cast<std::size_t>(i)] = m->jnt_dofadr[joint];
  }
  impl->carrier_z_dof = impl->carrier_dof[2];
  const int carrier = mj_name2id(m, mjOBJ_BODY, "carrier");
  impl->carried_mass = m->body_subtreemass[carrier];
  impl->part_body = mj_name2id(m, mjOBJ_BODY, "part");
  impl->part_geom = mj_name2id(m, mjOBJ_GEOM, "part");
  impl->table_surface = mj_name2id(m, mjOBJ_GEOM, "table_surface");
  impl->table = mj_name2id(m, mjOBJ_GEOM, "table");
  impl->flange_body = mj_name2id(m, mjOBJ_BODY, "flange");

  // Start with the flange 0.35 m above the part, the fingers open, and let the part settle.
  impl->goal = impl->setpoint = Eigen::Vector4d(options.part_x, options.part_y, 0.35, 0.0);
  for (int i = 0; i < 4; ++i) {
    impl->data->qpos[impl->carrier_qpos[static_cast<std::size_t>(i)]] = impl->setpoint[i];
  }
  impl->gripper->reset(gripper::GripperMode::kBasic);
  mj_forward(m, impl->data);
  const auto settle = static_cast<std::int64_t>(options.settle_seconds / m->opt.timestep);
  for (std::int64_t i = 0; i < settle; ++i) {
    impl->step();
  }
  impl->settle_steps = impl->steps;
  impl->steps = 0;
  return std::unique_ptr<GripperBench>(new GripperBench(std::move(impl)));
}

TimePoint GripperBench::time() const { return impl_->now(); }

void GripperBench::stepTo(TimePoint t) {
  const double dt = impl_->model->opt.timestep;
  const auto target = static_cast<std::int64_t>(std::floor(toSeconds(t) / dt + 1e-9));
  while (impl_->steps < target) {
    impl_->step();
  }
}

void GripperBench::attach(SimClock& clock) {
  detach();
  impl_->clock = &clock;
  impl_->listener = clock.addStepListener([this](TimePoint, TimePoint to) { stepTo(to); });
}

void GripperBench::detach() {
  if (impl_->clock != nullptr) {
    impl_->clock->removeStepListener(impl_->listener);
    impl_->clock = nullptr;
  }
}

gripper::AdaptiveGripperDriver& GripperBench::driver() { return *impl_->gripper; }
const gripper::AdaptiveGripperDescription& GripperBench::gripper() const { return impl_->gripper->description(); }

void GripperBench::moveFlange(const Eigen::Vector3d& position, double yaw, double speed) {
  // The carrier's origin is the flange's origin (the flange body only turns).
  impl_->goal = Eigen::Vector4d(position.x(), position.y(), position.z(), yaw);
  impl_->speed = std::max(speed, 1e-3);
}

bool GripperBench::flangeArrived() const {
  const Impl& impl = *impl_;
  if ((impl.setpoint - impl.goal).norm() > 1e-9) {
    return false;
  }
  Eigen::Vector3d at;
  for (int i = 0; i < 3; ++i) {
    at[i] = impl.data->qpos[impl.carrier_qpos[static_cast<std::size_t>(i)]];
  }
  return (at - impl.goal.head<3>()).norm() < 0.001 &&
         std::abs(impl.data->qpos[impl.carrier_qpos[3]] - impl.goal[3]) < 0.01;
}

namespace {
world::Pose bodyPose(const mjData* data, int body) {
  world::Pose pose = world::Pose::Identity();
  pose.translation() = Eigen::Vector3d(data->xpos[3 * body], data->xpos[3 * body + 1], data->xpos[3 * body + 2]);
  pose.linear() = Eigen::Quaterniond(data->xquat[4 * body], data->xquat[4 * body + 1], data->xquat[4 * body + 2],
                                     data->xquat[4 * body + 3])
                      .toRotationMatrix();
  return pose;
}
}  // namespace

world::Pose GripperBench::flangePose() const { return bodyPose(impl_->data, impl_->flange_body); }
world::Pose GripperBench::partPose() const { return bodyPose(impl_->data, impl_->part_body); }
double GripperBench::partRestHeight() const { return impl_->part_class.rest_height; }
const world::ObjectClass& GripperBench::partClass() const { return impl_->part_class; }
std::int64_t GripperBench::steps() const { return impl_->steps; }

std::vector<std::string> GripperBench::partContacts() const {
  const Impl& impl = *impl_;
  std::vector<std::string> touches;
  const auto add = [&](const std::string& name) {
    if (std::find(touches.begin(), touches.end(), name) == touches.end()) {
      touches.push_back(name);
    }
  };
  for (int c = 0; c < impl.data->ncon; ++c) {
    const mjContact& contact = impl.data->contact[c];
    int other = -1;
    if (contact.geom1 == impl.part_geom) {
      other = contact.geom2;
    } else if (contact.geom2 == impl.part_geom) {
      other = contact.geom1;
    } else {
      continue;
    }
    if (other == impl.table_surface || other == impl.table) {
      add("table");
    } else if (const int finger = impl.gripper->fingerOfGeom(other); finger >= 0) {
      add(std::string(gripper::kFingerNames[static_cast<std::size_t>(finger)]));
    } else if (impl.gripper->isGripperGeom(other)) {
      add("palm");
    }
  }
  std::sort(touches.begin(), touches.end());
  return touches;
}

// --- one trial ---------------------------------------------------------------------------

namespace {

/// Runs an operation of the component to completion on the clock (10 ms ticks).
component::OperationResult run(component::Component& gripper, SimClock& clock, const std::string& operation,
                               component::ParamMap params, Duration limit) {
  for (const auto& spec : gripper.description().operation(operation)->params) {
    params.try_emplace(spec.name, *spec.default_value);
  }
  const auto id = gripper.start(operation, params);
  const TimePoint deadline = clock.now() + limit;
  while (clock.now() < deadline) {
    const component::OperationResult result = gripper.poll(id);
    if (result.state != component::OperationState::kRunning) {
      return result;
    }
    clock.advanceBy(std::chrono::milliseconds(10));
  }
  gripper.cancel(id);
  return component::OperationResult::failure(operation + " did not finish");
}

bool moveAndWait(GripperBench& bench, SimClock& clock, const Eigen::Vector3d& position, double yaw, double speed) {
  bench.moveFlange(position, yaw, speed);
  for (int tick = 0; tick < 1000; ++tick) {
    clock.advanceBy(std::chrono::milliseconds(10));
    if (bench.flangeArrived()) {
      return true;
    }
  }
  return false;
}

}  // namespace

GripperTrialResult runGripperTrial(const GripperTrialOptions& options) {
  GripperTrialResult result;
  auto bench = GripperBench::create(options.bench);
  SimClock clock;
  bench->attach(clock);
  gripper::AdaptiveGripper component(bench->driver(), clock, bench->gripper());
  const auto fail = [&](std::string reason) {
    result.reason = std::move(reason);
    result.simulated_seconds = toSeconds(clock.now());
    return result;
  };

  if (const auto set = run(component, clock, "SetMode", {{"mode", std::string(gripper::toString(options.mode))}},
                           std::chrono::seconds(5));
      set.state != component::OperationState::kSuccess) {
    return fail("SetMode: " + set.reason);
  }
  // The flange's pose for the grasp: part * s * T * tcp^-1 (the tool pointing down), with the
  // part's symmetry s about its vertical axis that turns the carrier least (as SmartMove would).
  world::Pose tcp_in_flange = world::Pose::Identity();
  tcp_in_flange.translation() = bench->gripper().tcp;
  world::Pose flange = world::Pose::Identity();
  double least_turn = 1e9;
  for (const Eigen::Matrix3d& symmetry : bench->partClass().symmetries) {
    if (std::abs(symmetry(2, 2) - 1.0) > 1e-9) {
      continue;  // keeps the part's vertical axis: the part looks the same from above
    }
    world::Pose turned = world::Pose::Identity();
    turned.linear() = symmetry;
    const world::Pose candidate = bench->partPose() * turned * options.tcp_in_part * tcp_in_flange.inverse();
    const double turn = std::abs(std::atan2(candidate.linear()(1, 0), candidate.linear()(0, 0)));
    if (turn < least_turn - 1e-9) {
      least_turn = turn;
      flange = candidate;
    }
  }
  const Eigen::Vector3d z = flange.linear().col(2);
  if (z.z() > -0.99) {
    return fail("the grasp does not point the tool down (only top grasps on the bench)");
  }
  // The flange turned 180 degrees about x, then by the yaw: R = Rz(yaw) Rx(pi), whose x column
  // is (cos yaw, sin yaw, 0).
  const Eigen::Vector3d x = flange.linear().col(0);
  const double yaw = std::atan2(x.y(), x.x()) + options.approach_error.z();
  flange.translation() += Eigen::Vector3d(options.approach_error.x(), options.approach_error.y(), 0.0);
  const Eigen::Vector3d above = flange.translation() + Eigen::Vector3d(0, 0, 0.08);
  if (!moveAndWait(*bench, clock, above, yaw, 0.3) || !moveAndWait(*bench, clock, flange.translation(), yaw, 0.1)) {
    return fail("the carrier did not reach the grasp");
  }
  const TimePoint close_start = clock.now();
  const auto close = run(component, clock, "Close", {{"force", options.force}}, std::chrono::seconds(5));
  result.close_seconds = toSeconds(clock.now() - close_start);
  if (close.state != component::OperationState::kSuccess) {
    return fail("Close: " + close.reason);
  }
  moveAndWait(*bench, clock, flange.translation() + Eigen::Vector3d(0, 0, options.lift), yaw, 0.05);
  const Eigen::Vector3d held = bench->flangePose().inverse() * bench->partPose().translation();
  clock.advanceBy(std::chrono::nanoseconds(static_cast<std::int64_t>(options.hold_seconds * 1e9)));
  // Slip: how far the part slid out of the hand (along the flange's z, away from the palm). An
  // encompassing grasp may still pull the part in toward the palm; that is not slipping.
  result.slip = std::max(0.0, (bench->flangePose().inverse() * bench->partPose().translation() - held).z());

  result.lifted = bench->partPose().translation().z() - bench->partRestHeight();
  result.contacts = bench->partContacts();
  world::WorldState world;
  world.update("gripper", component.report());
  result.holding_predicate = world.holds("gripper_holding", {});
  result.simulated_seconds = toSeconds(clock.now());
  const auto touches = [&](const std::string& what) {
    return std::find(result.contacts.begin(), result.contacts.end(), what) != result.contacts.end();
  };
  const int fingers = static_cast<int>(touches("finger_middle")) + static_cast<int>(touches("finger_1")) +
                      static_cast<int>(touches("finger_2"));
  char text[160];
  if (result.lifted < 0.9 * options.lift) {
    std::snprintf(text, sizeof text, "the part was lifted %.1f mm, not %.0f mm", result.lifted * 1000,
                  options.lift * 1000);
    return fail(text);
  }
  if (result.slip > 0.003) {
    std::snprintf(text, sizeof text, "the part slid %.1f mm out of the hand during the hold", result.slip * 1000);
    return fail(text);
  }
  if (touches("table")) {
    return fail("the part still touches the table");
  }
  if (fingers < 2) {
    return fail("the part touches " + std::to_string(fingers) + " finger(s), not at least 2");
  }
  if (!result.holding_predicate) {
    return fail("the gripper does not report gripper_holding");
  }
  result.success = true;
  return result;
}

}  // namespace costar::sim
