#include "arm/free_drive.h"

#include "arm/arm_motion.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include <Eigen/Geometry>
#include <Eigen/SVD>

namespace costar::arm {

namespace {

constexpr double kGravity = 9.81;
constexpr std::array<const char*, 6> kAxisNames{"x", "y", "z", "rx", "ry", "rz"};
/// The look-ahead of a turn: as a translation's, 0.1 m counting as 1 rad (arm/cartesian_path.h).
constexpr double kMetresPerRadian = 0.1;

/// What the flange pushes the payload with to hold it against gravity, in the sensor frame
/// whose rotation in the world is `sensor` (force, and torque about the sensor's origin).
Wrench payloadSupport(const Eigen::Matrix3d& sensor, const Payload& payload) {
  Wrench support;
  support.force = sensor.transpose() * Eigen::Vector3d(0.0, 0.0, payload.mass * kGravity);
  support.torque = payload.center_of_mass.cross(support.force);
  return support;
}

/// `value` with the locked components (x, y, z of `offset` 0 or 3) zeroed, in the mode's axes.
Eigen::Vector3d masked(const Eigen::Vector3d& value, const GuidingMode& mode, int offset,
                       const Eigen::Matrix3d& tool_rotation) {
  const Eigen::Matrix3d axes = mode.tool_axes ? tool_rotation : Eigen::Matrix3d::Identity();
  Eigen::Vector3d local = axes.transpose() * value;
  for (int i = 0; i < 3; ++i) {
    if (mode.locked[static_cast<std::size_t>(offset + i)]) {
      local[i] = 0.0;
    }
  }
  return axes * local;
}

/// The push beyond the dead band, over the damping, within the top speed.
Eigen::Vector3d answer(const Eigen::Vector3d& push, double dead_band, double damping, double max_speed) {
  const double size = push.norm();
  if (size <= dead_band) {
    return Eigen::Vector3d::Zero();
  }
  const double speed = std::min((size - dead_band) / damping, max_speed);
  return push / size * speed;
}

/// `target` reached from `before` by at most `step` (a vector's change).
Eigen::Vector3d ramp(const Eigen::Vector3d& before, const Eigen::Vector3d& target, double step) {
  const Eigen::Vector3d change = target - before;
  return change.norm() <= step ? target : Eigen::Vector3d(before + change.normalized() * step);
}

/// "joints 4, 6" (1-based, as the status names them).
std::string jointList(const std::vector<int>& joints) {
  std::string text = joints.size() == 1 ? "joint " : "joints ";
  for (std::size_t i = 0; i < joints.size(); ++i) {
    text += (i == 0 ? "" : ", ") + std::to_string(joints[i]);
  }
  return text;
}

}  // namespace

Dexterity dexterity(const std::function<world::Pose(const JointVector&)>& tool, const JointVector& q) {
  constexpr double kStep = 1e-6;  // rad: central differences, exact to about 1e-10 here
  const int n = q.size();
  Eigen::MatrixXd jacobian(6, n);
  for (int j = 0; j < n; ++j) {
    JointVector plus = q;
    JointVector minus = q;
    plus[j] += kStep;
    minus[j] -= kStep;
    const world::Pose a = tool(plus);
    const world::Pose b = tool(minus);
    jacobian.block<3, 1>(0, j) = (a.translation() - b.translation()) / (2.0 * kStep);
    // The small turn from b to a: the skew part of their relative rotation.
    const Eigen::Matrix3d turn = a.linear() * b.linear().transpose();
    const Eigen::Vector3d axis(turn(2, 1) - turn(1, 2), turn(0, 2) - turn(2, 0), turn(1, 0) - turn(0, 1));
    jacobian.block<3, 1>(3, j) = axis / 2.0 * kMetresPerRadian / (2.0 * kStep);
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(jacobian, Eigen::ComputeThinV);
  const Eigen::Index last = svd.singularValues().size() - 1;
  Dexterity found;
  found.value = svd.singularValues()[last];
  const Eigen::VectorXd lost = svd.matrixV().col(last).cwiseAbs();
  for (int j = 0; j < n; ++j) {
    if (lost[j] >= 0.5 * lost.maxCoeff()) {
      found.joints.push_back(j + 1);
    }
  }
  return found;
}

GuidingMode GuidingMode::parse(const std::string& mode, const std::string& locked, const std::string& axes) {
  GuidingMode guiding;
  if (mode == "translation") {
    guiding.locked = {false, false, false, true, true, true};
  } else if (mode == "rotation") {
    guiding.locked = {true, true, true, false, false, false};
  } else if (mode != "free") {
    throw std::invalid_argument("mode: '" + mode + "' is not a guiding mode (free, translation, rotation)");
  }
  std::stringstream list(locked);
  for (std::string item; std::getline(list, item, ',');) {
    item.erase(0, item.find_first_not_of(' '));
    item.erase(item.find_last_not_of(' ') + 1);
    if (item.empty()) {
      continue;
    }
    const auto* found = std::find(kAxisNames.begin(), kAxisNames.end(), item);
    if (found == kAxisNames.end()) {
      throw std::invalid_argument("locked: '" + item + "' is not an axis (x, y, z, rx, ry, rz)");
    }
    guiding.locked[static_cast<std::size_t>(found - kAxisNames.begin())] = true;
  }
  if (axes != "world" && axes != "tool") {
    throw std::invalid_argument("axes: '" + axes + "' is neither world nor tool");
  }
  guiding.tool_axes = axes == "tool";
  if (std::all_of(guiding.locked.begin(), guiding.locked.end(), [](bool l) { return l; })) {
    throw std::invalid_argument("locked: every axis is locked: the hand could move nothing");
  }
  return guiding;
}

std::string GuidingMode::str() const {
  const auto all = [this](int from) { return locked[from] && locked[from + 1] && locked[from + 2]; };
  const auto none = [this](int from) { return !locked[from] && !locked[from + 1] && !locked[from + 2]; };
  if (none(0) && none(3)) {
    return "free";
  }
  if (none(0) && all(3)) {
    return "translation";
  }
  if (all(0) && none(3)) {
    return "rotation";
  }
  std::string text = "locked";
  for (std::size_t i = 0; i < 6; ++i) {
    if (locked[i]) {
      text += std::string(text == "locked" ? " " : ", ") + kAxisNames[i];
    }
  }
  return text + (tool_axes ? " (tool)" : " (world)");
}

Wrench handWrench(const Wrench& reading, const Wrench& start_reading, const Eigen::Matrix3d& sensor_now,
                  const Eigen::Matrix3d& sensor_at_start, const Eigen::Vector3d& tcp_in_sensor,
                  const Payload& payload) {
  const Wrench now = payloadSupport(sensor_now, payload);
  const Wrench then = payloadSupport(sensor_at_start, payload);
  // The flange pushes the tool with the payload's support less the hand's push.
  const Eigen::Vector3d force = -((reading.force - start_reading.force) - (now.force - then.force));
  const Eigen::Vector3d torque = -((reading.torque - start_reading.torque) - (now.torque - then.torque));
  Wrench hand;
  hand.force = sensor_now * force;
  hand.torque = sensor_now * (torque - tcp_in_sensor.cross(force));
  return hand;
}

Twist admittance(const Wrench& hand, const Twist& before, double dt, const GuidingMode& mode,
                 const Eigen::Matrix3d& tool_rotation, const AdmittanceGains& gains) {
  const Eigen::Vector3d velocity =
      answer(masked(hand.force, mode, 0, tool_rotation), gains.dead_band, gains.damping, gains.max_speed);
  const Eigen::Vector3d rate = answer(masked(hand.torque, mode, 3, tool_rotation), gains.rotational_dead_band,
                                      gains.rotational_damping, gains.max_rotation_speed);
  Twist twist;
  twist.velocity = masked(ramp(before.velocity, velocity, gains.acceleration * dt), mode, 0, tool_rotation);
  twist.angular_velocity =
      masked(ramp(before.angular_velocity, rate, 4.0 * gains.acceleration * dt), mode, 3, tool_rotation);
  return twist;
}

Eigen::Vector3d gripperLookAhead(const Eigen::Vector3d& velocity, const Eigen::Vector3d& hand_force,
                                 const AdmittanceGains& gains) {
  const double speed = velocity.norm();
  Eigen::Vector3d ahead = hand_force / gains.stiffness;
  if (speed > 0.0) {
    ahead += velocity / speed * (speed * speed / (2.0 * gains.acceleration) + gains.clearance);
  }
  return ahead.norm() > gains.look_ahead ? Eigen::Vector3d(ahead.normalized() * gains.look_ahead) : ahead;
}

world::Pose advance(const world::Pose& pose, const Twist& twist, double dt) {
  world::Pose moved = pose;
  moved.translation() += twist.velocity * dt;
  const Eigen::Vector3d turn = twist.angular_velocity * dt;
  if (turn.norm() > 0.0) {
    moved.linear() = Eigen::AngleAxisd(turn.norm(), turn.normalized()).toRotationMatrix() * pose.linear();
  }
  return moved;
}

std::string ProtectiveStop::check(double tool_speed, double tracking, double turn, double dt) {
  if (tracking > limits_.tracking) {
    return "the tool was " + formatNumber("%.1f mm", 1000.0 * tracking) + " from where free-drive held it (at most " +
           formatNumber("%.0f mm", 1000.0 * limits_.tracking) + ": a push harder than a hand's, or a collision)";
  }
  if (turn > limits_.rotation_tracking) {
    return "the tool was turned " + formatNumber("%.1f deg", turn * 180.0 / M_PI) +
           " from where free-drive held it (at most " +
           formatNumber("%.1f deg", limits_.rotation_tracking * 180.0 / M_PI) +
           ": a twist harder than a hand's, or a collision)";
  }
  if (tool_speed <= limits_.tool_speed) {
    over_for_ = 0.0;
    fastest_ = 0.0;
    return {};
  }
  over_for_ += dt;
  fastest_ = std::max(fastest_, tool_speed);
  if (over_for_ < limits_.over_speed_window) {
    return {};
  }
  return "the tool moved faster than " + formatNumber("%.2f m/s", limits_.tool_speed) + " for " +
         formatNumber("%.0f ms", 1000.0 * over_for_) + " (" + formatNumber("%.2f m/s", fastest_) +
         " at most), the teaching speed limit";
}

FreeDriveStep stepReference(const world::Pose& reference, const JointVector& joints, const Twist& twist, double dt,
                            const JointVector& max_joint_step, const AdmittanceGains& gains, const StepChecks& check,
                            const Eigen::Vector3d& hand_force) {
  FreeDriveStep held{reference, joints, Twist{}, {}};
  const bool moving = twist.velocity.norm() > 0.0;
  const bool turning = twist.angular_velocity.norm() > 0.0;
  if (!moving && !turning) {
    return held;
  }
  Twist translation_only;
  translation_only.velocity = twist.velocity;
  Twist rotation_only;
  rotation_only.angular_velocity = twist.angular_velocity;
  std::vector<Twist> tries{twist};
  if (moving && turning) {
    tries.push_back(translation_only);
    tries.push_back(rotation_only);
  }
  // Against a wall the hand slides along it: the translation less one world axis's part, where
  // the push along the wall is beyond the dead band (the wall takes the rest).
  for (int axis = 0; moving && axis < 3; ++axis) {
    Twist slide = translation_only;
    slide.velocity[axis] = 0.0;
    Eigen::Vector3d along_wall = hand_force;
    along_wall[axis] = 0.0;
    if (slide.velocity.norm() > 0.0 && slide.velocity != twist.velocity && along_wall.norm() > gains.dead_band) {
      tries.push_back(slide);
    }
  }
  std::string first_reason;
  const auto refuse = [&](const std::string& why) {
    if (first_reason.empty()) {
      first_reason = why;
    }
  };
  const bool guarded = static_cast<bool>(check.dexterity);
  const Dexterity here = guarded ? check.dexterity(joints) : Dexterity{};
  // Toward a singularity the step may take this fraction of the top speeds, none below the floor.
  const double near_singular =
      std::clamp((here.value - gains.singular_floor) / (gains.singular_slow - gains.singular_floor), 0.0, 1.0);
  for (Twist attempt : tries) {
    // Near a singularity the joints would turn fast, and the links would swing fast: the twist
    // slows until they do not.
    for (int slowing = 0; slowing < 4; ++slowing) {
      const world::Pose next = advance(reference, attempt, dt);
      std::string why;
      const std::optional<JointVector> q = check.reach(next, joints, why);
      if (!q) {
        refuse(why);
        break;
      }
      double worst = 0.0;
      for (int j = 0; j < joints.size(); ++j) {
        worst = std::max(worst, std::abs((*q)[j] - joints[j]) / max_joint_step[j]);
      }
      if (worst > 1.0) {
        attempt.velocity /= 2.0 * worst;
        attempt.angular_velocity /= 2.0 * worst;
        refuse("a joint would turn too fast (near a singularity)");
        continue;
      }
      if (guarded) {
        const Dexterity there = check.dexterity(*q);
        if (there.value < here.value && there.value < gains.singular_slow) {
          if (there.value <= gains.singular_floor) {
            refuse("at a singularity (" + jointList(there.joints) + "): guide the tool another way");
            break;
          }
          const double fraction = std::max(attempt.velocity.norm() / gains.max_speed,
                                           attempt.angular_velocity.norm() / gains.max_rotation_speed);
          if (fraction > near_singular * (1.0 + 1e-9)) {
            attempt.velocity *= near_singular / fraction;
            attempt.angular_velocity *= near_singular / fraction;
            refuse("slowed near a singularity (" + jointList(there.joints) + ")");
            continue;
          }
        }
      }
      const double moved = check.displacement(joints, *q);
      if (moved > gains.max_point_speed * dt) {
        const double scale = 0.9 * gains.max_point_speed * dt / moved;
        attempt.velocity *= scale;
        attempt.angular_velocity *= scale;
        refuse("a link would move faster than " + formatNumber("%.2f m/s", gains.max_point_speed));
        continue;
      }
      // What lies ahead must be clear too. The gripper (every link, in check.sweep): where the
      // reference stops from its speed with the clearance, the tool pushed on by the hand's give.
      // The arm's other links (check.sweep_arm): the whole look-ahead along the motion, and the
      // fastest point carried as far (an elbow moving faster than the tool looks as far ahead as
      // it moves).
      const auto sweep_arm = check.sweep_arm ? check.sweep_arm : check.sweep;
      Twist turn_ahead;
      if (attempt.angular_velocity.norm() > 0.0) {
        turn_ahead.angular_velocity = attempt.angular_velocity.normalized() * (gains.look_ahead / kMetresPerRadian);
      }
      Twist near = turn_ahead;
      near.velocity = gripperLookAhead(attempt.velocity, hand_force, gains);
      const std::optional<JointVector> gripper_ahead = check.reach(advance(next, near, 1.0), *q, why);
      if (!gripper_ahead || !check.sweep(*q, *gripper_ahead, why)) {
        refuse(why);
        break;
      }
      Twist far = turn_ahead;
      if (attempt.velocity.norm() > 0.0) {
        far.velocity = attempt.velocity.normalized() * gains.look_ahead;
      }
      const std::optional<JointVector> tool_ahead = check.reach(advance(next, far, 1.0), *q, why);
      if (!tool_ahead || !sweep_arm(*q, *tool_ahead, why)) {
        refuse(why);
        break;
      }
      if (moved > 0.0) {
        JointVector links_ahead = *q;
        for (int j = 0; j < joints.size(); ++j) {
          links_ahead[j] += ((*q)[j] - joints[j]) * gains.look_ahead / moved;
        }
        if (!sweep_arm(*q, links_ahead, why)) {
          refuse(why);
          break;
        }
      }
      return {next, *q, attempt,
              attempt.velocity == twist.velocity && attempt.angular_velocity == twist.angular_velocity ? std::string()
                                                                                                       : first_reason};
    }
  }
  held.blocked = first_reason;
  return held;
}

}  // namespace costar::arm
