#include "sim/wire_sim.h"

#include <mujoco/mujoco.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace costar::sim {

namespace {

// The wire's joints: armature (a rotational inertia that MuJoCo adds to a joint) makes the
// stiff, light chain stable at the cell's time step: a joint's own frequency sqrt(k / a) is then
// 1 / (sqrt(2) dt), and the chain's fastest (zig-zag) mode twice that, below the explicit
// spring's limit of 2 / dt. The damping ratio, per joint, lets a released wire settle in a few
// tenths of a second while the bend's damping moment stays small beside its plastic moment at
// the speeds a wire is bent at (a tenth at 1 rad/s).
constexpr double kWireArmatureSteps = 2.0;  // armature = 2 k dt^2
constexpr double kWireDampingRatio = 1.0;
// The pins' slides likewise, critically damped.
constexpr double kPinArmatureSteps = 4.0;
constexpr double kPinDampingRatio = 1.0;
// The grip: two fingers on the wire for 20 ms is a hold; off it for 0.1 s, the hold is over.
constexpr int kHoldSteps = 10;
constexpr int kLostSteps = 50;
constexpr double kPinHeightOffTable = 0.001;  // a pin's foot clears the table's contact plane

std::string format(double value) {
  std::ostringstream out;
  out.precision(9);
  out << value;
  return out.str();
}

std::string vec(double x, double y, double z) { return format(x) + " " + format(y) + " " + format(z); }

std::string yawQuat(double yaw) { return format(std::cos(yaw / 2)) + " 0 0 " + format(std::sin(yaw / 2)); }

int idOf(const mjModel* model, mjtObj type, const std::string& name) {
  const int id = mj_name2id(model, type, name.c_str());
  if (id < 0) {
    throw std::runtime_error("the workcell model lacks the jig's '" + name + "'");
  }
  return id;
}

/// The template sheet on the table under the jig, with the drawing on it: a rectangle around
/// the clamp, the pins and the target's polyline (2 cm margin).
std::string sheet(const JigSpec& jig, double wire_length) {
  const double length = wire_length > 0 ? wire_length : (jig.target.empty() ? 0.1 : jig.target.back().at + 0.05);
  const std::vector<Eigen::Vector2d> drawing = targetPolyline(jig.target, length);
  Eigen::Vector2d low(-0.03, -0.012);
  Eigen::Vector2d high(0.0, 0.012);
  for (const Eigen::Vector2d& p : drawing) {
    low = low.cwiseMin(p);
    high = high.cwiseMax(p);
  }
  for (const PinSpec& pin : jig.pins) {
    low = low.cwiseMin(pin.at - Eigen::Vector2d::Constant(pin.radius));
    high = high.cwiseMax(pin.at + Eigen::Vector2d::Constant(pin.radius));
  }
  low.array() -= 0.02;
  high.array() += 0.02;
  const Eigen::Vector2d centre = (low + high) / 2;
  const Eigen::Vector2d half = (high - low) / 2;
  // A camera straight above the sheet, the jig's x to the picture's right (`costar sim
  // snapshot --camera jig`), seeing the sheet with a margin.
  const double view_height = 1.15 * std::max(half.x() * 0.75, half.y()) / std::tan(12.5 * M_PI / 180.0);
  std::string text = "<camera name=\"jig\" pos=\"" + vec(centre.x(), centre.y(), view_height) +
                     "\" xyaxes=\"1 0 0 0 1 0\" fovy=\"25\"/>";
  text += "<geom name=\"jig_sheet\" type=\"box\" pos=\"" + vec(centre.x(), centre.y(), 0.0003) + "\" size=\"" +
          vec(half.x(), half.y(), 0.0003) + "\" rgba=\"0.36 0.4 0.46 1\" contype=\"0\" conaffinity=\"0\"/>";
  for (std::size_t i = 0; i + 1 < drawing.size(); ++i) {
    const Eigen::Vector2d from = drawing[i];
    const Eigen::Vector2d to = drawing[i + 1];
    const Eigen::Vector2d middle = (from + to) / 2;
    const double half_length = (to - from).norm() / 2 + 0.00075;
    text += "<geom name=\"jig_target_" + std::to_string(i) + "\" type=\"box\" pos=\"" +
            vec(middle.x(), middle.y(), 0.0007) + "\" quat=\"" +
            yawQuat(std::atan2(to.y() - from.y(), to.x() - from.x())) + "\" size=\"" +
            vec(half_length, 0.00075, 0.0001) + "\" rgba=\"0.2 0.85 0.3 1\" contype=\"0\" conaffinity=\"0\"/>";
  }
  return text;
}

}  // namespace

std::string jigMjcf(const JigSpec& jig, const std::optional<WireSpec>& wire, const WireMaterial* material,
                    const JigDraw& draw, double timestep) {
  const double dt2 = timestep * timestep;
  const Eigen::Vector3d at = draw.pose.translation();
  const double yaw = std::atan2(draw.pose.linear()(1, 0), draw.pose.linear()(0, 0));
  std::string body = "<body name=\"jig\" pos=\"" + vec(at.x(), at.y(), 0.0) + "\" quat=\"" + yawQuat(yaw) + "\">";
  body += sheet(jig, wire ? draw.wire_length : 0.0);
  // The clamp: a block behind the mouth, holding the wire's start at the jig's height. The
  // gripper collides with it; the wire, clamped, does not.
  const double top = jig.height + 0.012;
  body += "<geom name=\"jig_clamp\" type=\"box\" pos=\"" + vec(-0.02, 0.0, top / 2) + "\" size=\"" +
          vec(0.02, 0.012, top / 2) + "\" rgba=\"0.3 0.32 0.36 1\" contype=\"0\" conaffinity=\"2\"/>";
  // Pins: steel, on two slides of the jig's plane held by springs (the press fit; its rest
  // position moves when pushed past the hold force). They touch the gripper, the wire and parts.
  for (const PinSpec& pin : jig.pins) {
    const std::string name = "pin_" + pin.name;
    body += "<body name=\"" + name + "\" pos=\"" + vec(pin.at.x(), pin.at.y(), 0.0) + "\">";
    const double pin_armature = kPinArmatureSteps * pin.stiffness * dt2;
    const std::string pin_joint = "\" stiffness=\"" + format(pin.stiffness) + "\" armature=\"" + format(pin_armature) +
                                  "\" damping=\"" +
                                  format(2.0 * kPinDampingRatio * std::sqrt(pin.stiffness * pin_armature)) + "\"/>";
    body += "<joint name=\"" + name + "_x\" type=\"slide\" axis=\"1 0 0" + pin_joint;
    body += "<joint name=\"" + name + "_y\" type=\"slide\" axis=\"0 1 0" + pin_joint;
    body += "<geom name=\"" + name + "\" type=\"cylinder\" pos=\"" + vec(0, 0, kPinHeightOffTable + pin.height / 2) +
            "\" size=\"" + format(pin.radius) + " " + format(pin.height / 2) + "\" density=\"7850\" friction=\"" +
            format(material != nullptr ? material->friction : 0.3) +
            " 0.005 0.0001\" solref=\"0.004 1\" solimp=\"0.99 0.999 0.0005\" priority=\"2\" rgba=\"0.72 0.74 0.78 1\" "
            "contype=\"0\" conaffinity=\"7\"/>";
    body += "</body>";
  }
  if (wire) {
    if (material == nullptr) {
      throw std::logic_error("jigMjcf: a wire needs its material");
    }
    const WireJoints joints = wireJoints(*wire, draw.wire_length, draw.youngs_modulus_gpa, draw.yield_strength_mpa);
    const double armature = kWireArmatureSteps * joints.stiffness * dt2;
    const std::string hinge = "\" stiffness=\"" + format(joints.stiffness) + "\" armature=\"" + format(armature) +
                              "\" damping=\"" +
                              format(2.0 * kWireDampingRatio * std::sqrt(joints.stiffness * armature)) + "\"/>";
    const std::string radius = format(wire->diameter / 2);
    const std::string geom_class = "\" size=\"" + radius + "\" density=\"" + format(material->density) +
                                   "\" friction=\"1.0 0.005 0.0001\" condim=\"3\" solref=\"0.004 1\" solimp=\"0.998 "
                                   "0.9999 0.0005\" priority=\"1\" rgba=\"0.55 0.57 0.6 1\"";
    // The clamped stub (inside the clamp, seen only where the clamp is cut away), then the free
    // segments, each on a bending hinge (z: in the table's plane) and a lifting one (y: out of
    // it), both with the wire's bending stiffness per segment.
    body += "<body name=\"wire_0\" pos=\"" + vec(0, 0, jig.height) +
            "\"><geom name=\"wire_0\" type=\"capsule\" "
            "fromto=\"-0.03 0 0 0 0 0" +
            geom_class + " contype=\"0\" conaffinity=\"0\"/>";
    for (int i = 1; i <= wire->segments; ++i) {
      const std::string name = "wire_" + std::to_string(i);
      body += "<body name=\"" + name + "\" pos=\"" + vec(i == 1 ? 0.0 : joints.segment, 0, 0) + "\">";
      body += "<joint name=\"" + name + "_bend\" type=\"hinge\" axis=\"0 0 1" + hinge;
      body += "<joint name=\"" + name + "_lift\" type=\"hinge\" axis=\"0 1 0" + hinge;
      body += "<geom name=\"" + name + "\" type=\"capsule\" fromto=\"0 0 0 " + format(joints.segment) + " 0 0" +
              geom_class + " contype=\"4\" conaffinity=\"3\"/>";
    }
    for (int i = 0; i <= wire->segments; ++i) {
      body += "</body>";
    }
  }
  return body + "</body>\n";
}

SimJig::SimJig(mjModel* model, mjData* data, JigSpec jig, std::optional<WireSpec> wire, JigDraw draw, Gripper gripper)
    : model_(model),
      data_(data),
      jig_(std::move(jig)),
      wire_(std::move(wire)),
      draw_(draw),
      gripper_(std::move(gripper)) {
  geom_kind_.assign(static_cast<std::size_t>(model_->ngeom), -1);
  const int jig_body = idOf(model_, mjOBJ_BODY, "jig");
  for (int g = 0; g < model_->ngeom; ++g) {
    if (model_->geom_bodyid[g] == jig_body) {
      geom_kind_[static_cast<std::size_t>(g)] = -2;
    }
  }
  for (std::size_t i = 0; i < jig_.pins.size(); ++i) {
    const PinSpec& spec = jig_.pins[i];
    Pin pin;
    pin.body = idOf(model_, mjOBJ_BODY, "pin_" + spec.name);
    pin.qpos_x = model_->jnt_qposadr[idOf(model_, mjOBJ_JOINT, "pin_" + spec.name + "_x")];
    pin.qpos_y = model_->jnt_qposadr[idOf(model_, mjOBJ_JOINT, "pin_" + spec.name + "_y")];
    geom_kind_[static_cast<std::size_t>(idOf(model_, mjOBJ_GEOM, "pin_" + spec.name))] = 1 + static_cast<int>(i);
    pins_.push_back(pin);
  }
  if (wire_) {
    joints_ = wireJoints(*wire_, draw_.wire_length, draw_.youngs_modulus_gpa, draw_.yield_strength_mpa);
    for (int i = 1; i <= wire_->segments; ++i) {
      const std::string name = "wire_" + std::to_string(i);
      wire_bodies_.push_back(idOf(model_, mjOBJ_BODY, name));
      geom_kind_[static_cast<std::size_t>(idOf(model_, mjOBJ_GEOM, name))] = 0;
      for (const char* kind : {"_bend", "_lift"}) {
        wire_qpos_.push_back(model_->jnt_qposadr[idOf(model_, mjOBJ_JOINT, name + kind)]);
      }
    }
  }
}

void SimJig::afterStep(double time_s) {
  plasticity();
  watchPins();
  if (wire_) {
    watchGrip(time_s);
  }
}

void SimJig::plasticity() {
  // Each hinge: past the yield angle from its rest angle, the rest angle follows the bend.
  const double yield = joints_.yield_angle;
  for (const int q : wire_qpos_) {
    const double strain = data_->qpos[q] - model_->qpos_spring[q];
    if (strain > yield) {
      model_->qpos_spring[q] = data_->qpos[q] - yield;
    } else if (strain < -yield) {
      model_->qpos_spring[q] = data_->qpos[q] + yield;
    }
  }
}

void SimJig::watchPins() {
  // A pin's spring force is its press fit's hold; past the hold force it slips (its rest
  // position follows) and stays where it was pushed.
  for (std::size_t i = 0; i < pins_.size(); ++i) {
    Pin& pin = pins_[i];
    const PinSpec& spec = jig_.pins[i];
    const Eigen::Vector2d position(data_->qpos[pin.qpos_x], data_->qpos[pin.qpos_y]);
    const Eigen::Vector2d rest(model_->qpos_spring[pin.qpos_x], model_->qpos_spring[pin.qpos_y]);
    const Eigen::Vector2d give = position - rest;
    const double force = spec.stiffness * give.norm();
    pin.max_force = std::max(pin.max_force, force);
    if (force > spec.hold_force) {
      const Eigen::Vector2d moved = position - give.normalized() * (spec.hold_force / spec.stiffness);
      model_->qpos_spring[pin.qpos_x] = moved.x();
      model_->qpos_spring[pin.qpos_y] = moved.y();
    }
  }
}

Eigen::Vector3d SimJig::wirePoint(int segment, double along) const {
  const int body = wire_bodies_[static_cast<std::size_t>(segment)];
  const Eigen::Map<const Eigen::Matrix<mjtNum, 3, 3, Eigen::RowMajor>> rotation(data_->xmat + 9 * body);
  return Eigen::Map<const Eigen::Vector3d>(data_->xpos + 3 * body) + rotation.col(0) * along;
}

void SimJig::watchGrip(double time_s) {
  // Which fingers touch the wire now.
  std::vector<int> fingers;
  for (int c = 0; c < data_->ncon; ++c) {
    const mjContact& contact = data_->contact[c];
    const int a = geom_kind_[static_cast<std::size_t>(contact.geom1)];
    const int b = geom_kind_[static_cast<std::size_t>(contact.geom2)];
    const int other = a == 0 ? contact.geom2 : b == 0 ? contact.geom1 : -1;
    if (other < 0) {
      continue;
    }
    const int finger = gripper_.finger_of_geom(other);
    if (finger >= 0 && std::find(fingers.begin(), fingers.end(), finger) == fingers.end()) {
      fingers.push_back(finger);
    }
  }
  const bool touching = fingers.size() >= 2;
  grip_.held = touching;
  const Eigen::Map<const Eigen::Vector3d> tcp(data_->site_xpos + 3 * gripper_.tcp_site);
  const Eigen::Map<const Eigen::Matrix<mjtNum, 3, 3, Eigen::RowMajor>> tcp_rotation(data_->site_xmat +
                                                                                    9 * gripper_.tcp_site);
  const bool holding = grip_.holds > grip_.releases + grip_.pulled_out;
  if (!holding) {
    touching_steps_ = touching ? touching_steps_ + 1 : 0;
    if (touching_steps_ < kHoldSteps) {
      return;
    }
    // A hold begins: remember the wire's point nearest the TCP, in the TCP's frame.
    ++grip_.holds;
    apart_steps_ = 0;
    closure_at_hold_ = gripper_.commanded_closure();
    double nearest = 1e9;
    for (std::size_t i = 0; i < wire_bodies_.size(); ++i) {
      const Eigen::Vector3d start = wirePoint(static_cast<int>(i), 0.0);
      const Eigen::Vector3d axis = wirePoint(static_cast<int>(i), joints_.segment) - start;
      const double along = std::clamp((tcp - start).dot(axis) / axis.squaredNorm(), 0.0, 1.0) * joints_.segment;
      const double distance = (wirePoint(static_cast<int>(i), along) - tcp).norm();
      if (distance < nearest) {
        nearest = distance;
        grasp_segment_ = static_cast<int>(i);
        grasp_along_ = along;
      }
    }
    grasp_in_tcp_ = tcp_rotation.transpose() * (wirePoint(grasp_segment_, grasp_along_) - tcp);
    return;
  }
  if (touching) {
    apart_steps_ = 0;
    const Eigen::Vector3d now = tcp_rotation.transpose() * (wirePoint(grasp_segment_, grasp_along_) - tcp);
    grip_.max_slip = std::max(grip_.max_slip, (now - grasp_in_tcp_).norm());
    return;
  }
  if (++apart_steps_ < kLostSteps) {
    return;
  }
  // The hold is over: let go of, or pulled out of fingers still told to close.
  touching_steps_ = 0;
  if (gripper_.commanded_closure() + 1e-6 < closure_at_hold_) {
    ++grip_.releases;
  } else {
    ++grip_.pulled_out;
    if (grip_.pulled_out_at < 0) {
      grip_.pulled_out_at = time_s;
    }
  }
}

JigState SimJig::state() const {
  JigState state;
  state.spec = jig_;
  state.draw = draw_;
  for (std::size_t i = 0; i < pins_.size(); ++i) {
    const Pin& pin = pins_[i];
    const PinSpec& spec = jig_.pins[i];
    PinState pin_state;
    pin_state.name = spec.name;
    const Eigen::Vector3d nominal = draw_.pose * Eigen::Vector3d(spec.at.x(), spec.at.y(), 0.0);
    pin_state.nominal = nominal.head<2>();
    pin_state.position = Eigen::Map<const Eigen::Vector3d>(data_->xpos + 3 * pin.body).head<2>();
    pin_state.slipped = Eigen::Vector2d(model_->qpos_spring[pin.qpos_x], model_->qpos_spring[pin.qpos_y]).norm();
    pin_state.max_force = pin.max_force;
    state.pins.push_back(pin_state);
  }
  if (!wire_) {
    return state;
  }
  state.has_wire = true;
  state.joints = joints_;
  state.grip = grip_;
  state.wire.push_back(wirePoint(0, 0.0));
  for (std::size_t i = 0; i < wire_bodies_.size(); ++i) {
    state.wire.push_back(wirePoint(static_cast<int>(i), joints_.segment));
    mjtNum velocity[6];
    mj_objectVelocity(model_, data_, mjOBJ_BODY, wire_bodies_[i], velocity, 0);
    const Eigen::Vector3d angular(velocity[0], velocity[1], velocity[2]);
    const Eigen::Vector3d linear(velocity[3], velocity[4], velocity[5]);
    const Eigen::Vector3d to_end = state.wire.back() - wirePoint(static_cast<int>(i), 0.0);
    state.wire_speed = std::max({state.wire_speed, linear.norm(), (linear + angular.cross(to_end)).norm()});
  }
  state.bends = measureBends(state.wire, jig_.target);
  return state;
}

std::string SimJig::geomLabel(int geom) const {
  if (geom < 0 || geom >= static_cast<int>(geom_kind_.size())) {
    return {};
  }
  const int kind = geom_kind_[static_cast<std::size_t>(geom)];
  if (kind == 0) {
    return "wire";
  }
  if (kind > 0) {
    return "pin_" + jig_.pins[static_cast<std::size_t>(kind - 1)].name;
  }
  return kind == -2 ? "jig" : std::string();
}

}  // namespace costar::sim
