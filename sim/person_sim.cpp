#include "sim/person_sim.h"

#include <mujoco/mujoco.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace costar::sim {

namespace {

constexpr double kFingersClosed = 2.2;        // rad: the fingers curl back over the palm
constexpr double kThumbClosed = 0.9;          // rad
constexpr double kPalmHalfThickness = 0.012;  // m

std::string format(double value) {
  std::ostringstream out;
  out.precision(9);
  out << value;
  return out.str();
}

std::string vec(const Eigen::Vector3d& v) { return format(v.x()) + " " + format(v.y()) + " " + format(v.z()); }

std::string quat(const Eigen::Quaterniond& q) {
  return format(q.w()) + " " + format(q.x()) + " " + format(q.y()) + " " + format(q.z());
}

/// The rotation taking x to `direction`.
Eigen::Quaterniond alongX(const Eigen::Vector3d& direction) {
  if (direction.norm() < 1e-9) {
    return Eigen::Quaterniond::Identity();
  }
  return Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitX(), direction.normalized());
}

int requireId(const mjModel* model, mjtObj type, const char* name) {
  const int id = mj_name2id(model, type, name);
  if (id < 0) {
    throw std::runtime_error(std::string("the workcell model lacks the person's '") + name + "'");
  }
  return id;
}

/// The torso's centre for a shoulder: beside it, away from the table.
Eigen::Vector3d chestPosition(const Eigen::Vector3d& shoulder) {
  const Eigen::Vector3d away(0.0, shoulder.y() >= 0.0 ? 1.0 : -1.0, 0.0);
  return shoulder + 0.12 * away + Eigen::Vector3d(0.17, 0, -0.28);
}

}  // namespace

std::string personBodiesMjcf(const PersonSpec& spec) {
  const PersonMotion motion(spec, spec.seed.value_or(0), 0.0);
  const PersonPose rest = motion.at(-1.0);
  // Hand parts touch parts (contype 1), the table's surface and the arm (conaffinity 2); not
  // each other. Forearm, upper arm, torso and head touch the arm only.
  const std::string hand =
      R"(contype="1" conaffinity="2" condim="4" friction="1.2 0.02 0.001" rgba="0.87 0.68 0.55 1")";
  const std::string limb = R"(contype="0" conaffinity="2" rgba="0.87 0.68 0.55 1")";
  const std::string palm = R"(contype="0" conaffinity="0" mass="0.001" rgba="0.7 0.48 0.48 1")";
  const std::string cloth = R"(contype="0" conaffinity="2" rgba="0.25 0.35 0.55 1")";
  std::string xml;
  // The hand is a free body welded to its mocap target (person_hand_target): it moves with real
  // velocities, so what it holds moves with it by friction, and the arm can push it.
  xml += "<body name=\"person_hand_target\" mocap=\"true\" pos=\"" + vec(rest.wrist) + "\" quat=\"" + quat(rest.hand) +
         "\"/>\n";
  xml += "<body name=\"person_hand\" pos=\"" + vec(rest.wrist) + "\" quat=\"" + quat(rest.hand) + "\"><freejoint/>";
  xml += "<geom name=\"person_palm\" type=\"box\" pos=\"0.05 0 0\" size=\"0.05 0.042 " + format(kPalmHalfThickness) +
         "\" " + hand + "/>";
  // The palm's pinker skin on its palm side (-z), seen only: the camera tells a palm turned up by it.
  xml +=
      "<geom name=\"person_palm_skin\" type=\"box\" pos=\"0.05 0 -0.0122\" size=\"0.048 0.04 0.0004\" " + palm + "/>";
  xml += "<body name=\"person_fingers\" pos=\"0.1 0 0\">";
  xml += "<joint name=\"person_fingers_joint\" type=\"hinge\" axis=\"0 1 0\" range=\"0 " +
         format(kFingersClosed + 0.2) + "\" damping=\"0.05\" armature=\"0.0005\"/>";
  for (const double y : {-0.0315, -0.0105, 0.0105, 0.0315}) {
    xml += "<geom type=\"capsule\" fromto=\"0.008 " + format(y) + " 0 0.075 " + format(y) + " 0\" size=\"0.009\" " +
           hand + "/>";
  }
  xml += "</body>";
  // The thumb at the palm's heel, out of its palm side and leaning back when open; closing
  // leans it forward, so what lies on the palm is squeezed between it and the fingers.
  xml += "<body name=\"person_thumb\" pos=\"0.0 0 -0.012\">";
  xml += "<joint name=\"person_thumb_joint\" type=\"hinge\" axis=\"0 -1 0\" range=\"0 " + format(kThumbClosed + 0.2) +
         "\" damping=\"0.03\" armature=\"0.0005\"/>";
  xml += "<geom type=\"capsule\" fromto=\"-0.004 0 -0.009 -0.022 0 -0.05\" size=\"0.011\" " + hand + "/>";
  xml += "</body></body>\n";
  xml += "<body name=\"person_forearm\" mocap=\"true\" pos=\"" + vec(rest.wrist) + "\" quat=\"" +
         quat(alongX(rest.elbow - rest.wrist)) + "\">";
  xml += "<geom name=\"person_forearm\" type=\"capsule\" fromto=\"0 0 0 " + format(kForearmLength) +
         " 0 0\" size=\"0.035\" " + limb + "/></body>\n";
  xml += "<body name=\"person_upper_arm\" mocap=\"true\" pos=\"" + vec(rest.elbow) + "\" quat=\"" +
         quat(alongX(rest.shoulder - rest.elbow)) + "\">";
  xml += "<geom name=\"person_upper_arm\" type=\"capsule\" fromto=\"0 0 0 " + format(kUpperArmLength) +
         " 0 0\" size=\"0.045\" " + cloth + "/></body>\n";
  // The torso beside the shoulder, away from the table (the side the shoulder is on), and the head.
  xml += "<body name=\"person_torso\" mocap=\"true\" pos=\"" + vec(chestPosition(spec.shoulder) + rest.offset) + "\">";
  xml += "<geom name=\"person_torso\" type=\"box\" size=\"0.2 0.11 0.32\" " + cloth + "/>";
  xml += "<geom name=\"person_head\" type=\"sphere\" pos=\"0 0 0.52\" size=\"0.1\" " + limb + "/></body>\n";
  return xml;
}

std::string personEqualityMjcf() {
  return "<equality><weld name=\"person_hand_weld\" body1=\"person_hand\" body2=\"person_hand_target\" "
         "solref=\"0.01 1\"/></equality>\n";
}

std::string personActuatorsMjcf() {
  return "<position name=\"person_fingers\" joint=\"person_fingers_joint\" kp=\"3\" forcerange=\"-1.5 1.5\" "
         "ctrlrange=\"0 " +
         format(kFingersClosed) +
         "\"/>\n"
         "<position name=\"person_thumb\" joint=\"person_thumb_joint\" kp=\"2\" forcerange=\"-1 1\" ctrlrange=\"0 " +
         format(kThumbClosed) + "\"/>\n";
}

Capsule geomCapsule(const mjModel* model, const mjData* data, int geom) {
  const Eigen::Vector3d centre = Eigen::Map<const Eigen::Vector3d>(data->geom_xpos + 3 * geom);
  Eigen::Matrix3d r;
  const mjtNum* m = data->geom_xmat + 9 * geom;
  r << m[0], m[1], m[2], m[3], m[4], m[5], m[6], m[7], m[8];
  const mjtNum* size = model->geom_size + 3 * geom;
  Capsule capsule;
  switch (model->geom_type[geom]) {
    case mjGEOM_SPHERE:
      capsule = {centre, centre, size[0]};
      break;
    case mjGEOM_CAPSULE:
    case mjGEOM_CYLINDER:
      capsule = {centre - size[1] * r.col(2), centre + size[1] * r.col(2), size[0]};
      break;
    case mjGEOM_BOX: {
      int longest = 0;
      for (int i = 1; i < 3; ++i) {
        if (size[i] > size[longest]) {
          longest = i;
        }
      }
      const int u = (longest + 1) % 3;
      const int v = (longest + 2) % 3;
      const double half = size[longest];
      capsule = {centre - half * r.col(longest), centre + half * r.col(longest),
                 std::sqrt(size[u] * size[u] + size[v] * size[v])};
      break;
    }
    default:
      capsule = {centre, centre, model->geom_rbound[geom]};
      break;
  }
  return capsule;
}

SimPerson::SimPerson(mjModel* model, mjData* data, const PersonSpec& spec, std::uint64_t seed, std::vector<int> parts)
    : model_(model), data_(data), motion_(spec, seed), parts_(std::move(parts)) {
  hand_mocap_ = model->body_mocapid[requireId(model, mjOBJ_BODY, "person_hand_target")];
  hand_body_ = requireId(model, mjOBJ_BODY, "person_hand");
  forearm_mocap_ = model->body_mocapid[requireId(model, mjOBJ_BODY, "person_forearm")];
  upper_arm_mocap_ = model->body_mocapid[requireId(model, mjOBJ_BODY, "person_upper_arm")];
  torso_mocap_ = model->body_mocapid[requireId(model, mjOBJ_BODY, "person_torso")];
  fingers_actuator_ = requireId(model, mjOBJ_ACTUATOR, "person_fingers");
  thumb_actuator_ = requireId(model, mjOBJ_ACTUATOR, "person_thumb");
  for (int geom = 0; geom < model->ngeom; ++geom) {
    const char* name = mj_id2name(model, mjOBJ_BODY, model->geom_bodyid[geom]);
    if (name != nullptr && std::string(name).rfind("person_", 0) == 0) {
      geoms_.push_back(geom);
    }
  }
  shoulder_ = spec.shoulder;
  drive(-1.0);
}

bool SimPerson::isPersonGeom(int geom) const { return std::binary_search(geoms_.begin(), geoms_.end(), geom); }

bool SimPerson::isHandGeom(int geom) const {
  if (!isPersonGeom(geom)) {
    return false;
  }
  const std::string body = geomLabel(geom);
  return body == "person_hand" || body == "person_fingers" || body == "person_thumb";
}

std::string SimPerson::geomLabel(int geom) const {
  const char* name = mj_id2name(model_, mjOBJ_BODY, model_->geom_bodyid[geom]);
  return name != nullptr ? name : "person";
}

int SimPerson::partOnPalm() const {
  // The palm's side of the palm, as placed now (the hand's body, not its target: what the
  // palm carries is where the palm is).
  const int hand = hand_body_;
  const Eigen::Vector3d wrist = Eigen::Map<const Eigen::Vector3d>(data_->xpos + 3 * hand);
  Eigen::Matrix3d r;
  const mjtNum* m = data_->xmat + 9 * hand;
  r << m[0], m[1], m[2], m[3], m[4], m[5], m[6], m[7], m[8];
  if (r.col(2).z() > -0.8) {
    return -1;  // not turned up
  }
  for (const int body : parts_) {
    // In the hand's frame: over the palm (x 0-11 cm from the wrist, within 5 cm of its
    // middle), its centre less than 4 cm out of the palm's surface (a 5 cm node lying on it: 2.5 cm).
    const Eigen::Vector3d local = r.transpose() * (Eigen::Map<const Eigen::Vector3d>(data_->xpos + 3 * body) - wrist);
    const double out = -local.z() - kPalmHalfThickness;
    if (local.x() > 0.0 && local.x() < 0.11 && std::abs(local.y()) < 0.05 && out > 0.0 && out < 0.04) {
      return body;
    }
  }
  return -1;
}

void SimPerson::drive(double seconds, double arm_clearance) {
  if (seconds >= 0.0) {
    const PersonMotion::StepAt step = motion_.stepAt(seconds + ahead_);
    if (step.kind == PersonStep::Kind::kTake && step.settled && arm_clearance > kTakeClearance && partOnPalm() >= 0) {
      ahead_ += step.end - (seconds + ahead_);
    }
  }
  pose_ = motion_.at(seconds + ahead_);
  const auto place = [this](int mocap, const Eigen::Vector3d& position, const Eigen::Quaterniond& rotation) {
    Eigen::Map<Eigen::Vector3d>(data_->mocap_pos + 3 * mocap) = position;
    mjtNum* q = data_->mocap_quat + 4 * mocap;
    q[0] = rotation.w();
    q[1] = rotation.x();
    q[2] = rotation.y();
    q[3] = rotation.z();
  };
  place(hand_mocap_, pose_.wrist, pose_.hand);
  place(forearm_mocap_, pose_.wrist, alongX(pose_.elbow - pose_.wrist));
  place(upper_arm_mocap_, pose_.elbow, alongX(pose_.shoulder - pose_.elbow));
  place(torso_mocap_, chestPosition(shoulder_) + pose_.offset, Eigen::Quaterniond::Identity());
  data_->ctrl[fingers_actuator_] = pose_.closure * kFingersClosed;
  data_->ctrl[thumb_actuator_] = pose_.closure * kThumbClosed;
}

}  // namespace costar::sim
