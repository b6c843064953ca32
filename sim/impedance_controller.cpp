#include "sim/impedance_controller.h"

#include <mujoco/mujoco.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include <Eigen/Dense>

namespace costar::sim {

namespace {

/// The admittance's time constant in contact (s): the offset closes a force error in about this.
constexpr double kForceTimeConstant = 0.1;
/// Stiffness floors the damping is scaled from, so that an axis set to 0 N/m is still damped.
constexpr double kMinStiffness = 100.0;          // N/m
constexpr double kMinRotationalStiffness = 5.0;  // N m/rad
/// The null-space posture's stiffness and damping (redundant arms: the elbow).
constexpr double kPostureStiffness = 10.0;  // N m/rad
constexpr double kPostureDamping = 1.0;     // N m s/rad
/// The tool has touched once it pushes with this fraction of the target force.
constexpr double kTouchFraction = 0.5;

using Matrix6 = Eigen::Matrix<double, 6, 6>;
using Vector6 = Eigen::Matrix<double, 6, 1>;

}  // namespace

SimCartesianController::SimCartesianController(const mjModel_* model, mjData_* data, const char* tcp_site,
                                               std::vector<int> arm_dofs, std::vector<int> arm_qpos,
                                               const SimForceTorqueSensor& sensor, std::function<TimePoint()> now)
    : model_(model),
      data_(data),
      arm_dofs_(std::move(arm_dofs)),
      arm_qpos_(std::move(arm_qpos)),
      sensor_(sensor),
      now_(std::move(now)) {
  tcp_site_ = mj_name2id(model, mjOBJ_SITE, tcp_site);
  if (tcp_site_ < 0) {
    throw std::runtime_error(std::string("the workcell model has no site '") + tcp_site + "' (the tool centre point)");
  }
  ft_site_ = mj_name2id(model, mjOBJ_SITE, kForceTorqueSite);
  if (ft_site_ < 0) {
    throw std::runtime_error(std::string("the workcell model has no site '") + kForceTorqueSite + "'");
  }
  const auto nv = static_cast<std::size_t>(model->nv);
  jacobian_.assign(6 * nv, 0.0);
  solved_.assign(6 * nv, 0.0);
  scratch_.assign(nv, 0.0);
  posture_scratch_.assign(nv, 0.0);
}

Eigen::Vector3d SimCartesianController::tcpPosition() const {
  return Eigen::Map<const Eigen::Vector3d>(data_->site_xpos + 3 * tcp_site_);
}

Eigen::Matrix3d SimCartesianController::tcpRotation() const {
  return Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(data_->site_xmat + 9 * tcp_site_);
}

Eigen::Vector3d SimCartesianController::measuredForce() const {
  const Eigen::Matrix3d sensor =
      Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(data_->site_xmat + 9 * ft_site_);
  return sensor * sensor_.read().wrench.force;
}

void SimCartesianController::follow(arm::CartesianMotion motion, TimePoint start) {
  if (!motion.path) {
    throw std::invalid_argument("a Cartesian motion needs a path");
  }
  motion_ = std::move(motion);
  if (motion_.posture.size() != static_cast<int>(arm_qpos_.size())) {
    motion_.posture = arm::JointVector::zero(static_cast<int>(arm_qpos_.size()));
    for (std::size_t i = 0; i < arm_qpos_.size(); ++i) {
      motion_.posture[static_cast<int>(i)] = data_->qpos[arm_qpos_[i]];
    }
  }
  start_ = start;
  ++count_;
  active_ = true;
  stopped_ = false;
  stop_force_ = 0.0;
  path_done_ = false;
  arc_ = 0.0;
  offset_ = 0.0;
  touched_ = false;
  if (motion_.force) {
    motion_.force->direction.normalize();
    const Eigen::Vector3d& n = motion_.force->direction;
    // The offset starts where the tool is along the axis: no jump toward the path.
    offset_ = n.dot(tcpPosition() - motion_.path->sample(Duration{0}).pose.translation());
    axis_force_ = n.dot(measuredForce());
    touched_ = motion_.force->force <= 0.0 || axis_force_ >= kTouchFraction * motion_.force->force;
  }
}

void SimCartesianController::setForce(double force) {
  if (motion_.force) {
    motion_.force->force = force;
    touched_ = touched_ || force <= 0.0;
  }
}

arm::CartesianState SimCartesianController::state() const {
  arm::CartesianState state;
  state.following = active_;
  state.motion = count_;
  state.arc = arc_;
  state.path_done = path_done_;
  state.offset = offset_;
  state.axis_force = axis_force_;
  state.force_limit_stop = stopped_;
  state.stop_force = stop_force_;
  state.stamp = now_();
  return state;
}

arm::JointVector SimCartesianController::torqueLimits() const {
  arm::JointVector limits = arm::JointVector::zero(static_cast<int>(arm_dofs_.size()));
  for (std::size_t i = 0; i < arm_dofs_.size(); ++i) {
    limits[static_cast<int>(i)] = model_->actuator_ctrllimited[i] ? model_->actuator_ctrlrange[2 * i + 1]
                                                                  : std::numeric_limits<double>::infinity();
  }
  return limits;
}

void SimCartesianController::control() {
  const mjModel* m = model_;
  mjData* d = data_;
  const int nv = m->nv;
  const double dt = m->opt.timestep;
  const Eigen::Vector3d force_now = measuredForce();
  if (motion_.force) {
    axis_force_ = motion_.force->direction.dot(force_now);
  }

  if (!stopped_ && force_now.norm() > motion_.force_limit) {
    // The stop condition: no more pressing; the tool held where it gives way to what it pushes
    // (back by the force over the stiffness), so that the force goes, and no further.
    stopped_ = true;
    stop_force_ = force_now.norm();
    // Held where it is: the stiffness then pushes with nothing, the surface's reaction goes, and
    // the tool does not jump back (backing off by the limit over the stiffness lifted it 2 cm
    // after a 40 N stop).
    frozen_.linear() = tcpRotation();
    frozen_.translation() = tcpPosition();
  }

  // The reference.
  world::Pose reference = frozen_;
  Eigen::Vector3d reference_velocity = Eigen::Vector3d::Zero();
  Eigen::Vector3d reference_rate = Eigen::Vector3d::Zero();
  Eigen::Vector3d feedforward = Eigen::Vector3d::Zero();
  if (!stopped_) {
    const Duration elapsed = now_() - start_;
    const arm::CartesianPath::Sample sample = motion_.path->sample(elapsed);
    reference = sample.pose;
    reference_velocity = sample.velocity;
    reference_rate = sample.angular_velocity;
    if (motion_.drift) {
      const arm::CartesianMotion::Drift& drift = *motion_.drift;
      const double moving = std::clamp(toSeconds(elapsed), 0.0, toSeconds(drift.horizon));
      reference.translation() += drift.velocity * moving;
      const Eigen::Vector3d turn = drift.angular_velocity * moving;
      if (turn.norm() > 0.0) {
        reference.linear() = Eigen::AngleAxisd(turn.norm(), turn.normalized()).toRotationMatrix() * reference.linear();
      }
      if (elapsed < drift.horizon) {
        reference_velocity += drift.velocity;
        reference_rate += drift.angular_velocity;
      }
    }
    arc_ = sample.arc;
    path_done_ = elapsed >= motion_.path->duration();
    if (motion_.force) {
      const arm::ForceAxis& axis = *motion_.force;
      const Eigen::Matrix3d r = reference.linear();
      const double stiffness = std::max(kMinStiffness, axis.direction.dot(r * motion_.impedance.stiffness.asDiagonal() *
                                                                          r.transpose() * axis.direction));
      if (!touched_ && axis_force_ >= kTouchFraction * axis.force) {
        // From now on the target force is pushed as well (the feedforward below): the reference
        // steps back by what the stiffness pushes with now, so that the command steps to the
        // target instead of past it by that much (3.7 N over 10 N even at 2 mm/s).
        touched_ = true;
        offset_ -= std::clamp(axis_force_, 0.0, axis.force) / stiffness;
      }
      const double speed = touched_ ? std::clamp((axis.force - axis_force_) / (stiffness * kForceTimeConstant),
                                                 -axis.max_speed, axis.max_speed)
                                    : axis.max_speed;
      offset_ += speed * dt;
      reference.translation() += offset_ * axis.direction;
      reference_velocity += speed * axis.direction;
      if (touched_) {
        feedforward = axis.force * axis.direction;
      }
    }
  }

  // The Jacobian of the tool centre point and the Cartesian inertia Lambda = (J M^-1 J^T)^-1.
  mj_jacSite(m, d, jacobian_.data(), jacobian_.data() + 3 * nv, tcp_site_);
  mj_solveM(m, d, solved_.data(), jacobian_.data(), 6);
  using RowMatrix = Eigen::Matrix<double, 6, Eigen::Dynamic, Eigen::RowMajor>;
  const Eigen::Map<const RowMatrix> jacobian(jacobian_.data(), 6, nv);
  const Eigen::Map<const RowMatrix> solved(solved_.data(), 6, nv);
  const Matrix6 inverse_inertia = jacobian * solved.transpose();
  const Matrix6 inertia = (inverse_inertia + 1e-9 * Matrix6::Identity()).ldlt().solve(Matrix6::Identity());
  const Eigen::Map<const Eigen::VectorXd> qvel(d->qvel, nv);
  const Vector6 twist = jacobian * qvel;

  // Pose error and per-axis stiffness and damping, in the reference's tool axes.
  const Eigen::Matrix3d rotation = tcpRotation();
  const Eigen::Matrix3d r = reference.linear();
  const Eigen::Vector3d position_error = reference.translation() - tcpPosition();
  const Eigen::AngleAxisd turn(r * rotation.transpose());
  const Eigen::Vector3d rotation_error = turn.axis() * turn.angle();
  const arm::CartesianImpedance& impedance = motion_.impedance;
  Eigen::Vector3d damping;
  Eigen::Vector3d rotational_damping;
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector3d axis = r.col(i);
    const double mass = axis.dot(inertia.topLeftCorner<3, 3>() * axis);
    const double inertia_about = axis.dot(inertia.bottomRightCorner<3, 3>() * axis);
    damping[i] = 2.0 * impedance.damping_ratio * std::sqrt(std::max(impedance.stiffness[i], kMinStiffness) * mass);
    rotational_damping[i] =
        2.0 * impedance.damping_ratio *
        std::sqrt(std::max(impedance.rotational_stiffness[i], kMinRotationalStiffness) * std::max(inertia_about, 0.0));
  }
  Eigen::Vector3d force = r * (impedance.stiffness.asDiagonal() * (r.transpose() * position_error) +
                               damping.asDiagonal() * (r.transpose() * (reference_velocity - twist.head<3>()))) +
                          feedforward;
  if (force.norm() > motion_.force_limit) {
    force *= motion_.force_limit / force.norm();
  }
  const Eigen::Vector3d moment =
      r * (impedance.rotational_stiffness.asDiagonal() * (r.transpose() * rotation_error) +
           rotational_damping.asDiagonal() * (r.transpose() * (reference_rate - twist.tail<3>())));
  Vector6 wrench;
  wrench << force, moment;
  const Eigen::VectorXd task = jacobian.transpose() * wrench;

  // The posture in the null space of the tool's motion: tau0 - J^T Lambda J M^-1 tau0.
  std::fill(scratch_.begin(), scratch_.end(), 0.0);
  for (std::size_t i = 0; i < arm_dofs_.size(); ++i) {
    const int dof = arm_dofs_[i];
    scratch_[static_cast<std::size_t>(dof)] =
        kPostureStiffness * (motion_.posture[static_cast<int>(i)] - d->qpos[arm_qpos_[i]]) -
        kPostureDamping * d->qvel[dof];
  }
  mj_solveM(m, d, posture_scratch_.data(), scratch_.data(), 1);
  const Eigen::Map<const Eigen::VectorXd> accelerated(posture_scratch_.data(), nv);
  const Vector6 projected = inertia * (jacobian * accelerated);
  const Eigen::VectorXd removed = jacobian.transpose() * projected;
  for (std::size_t i = 0; i < arm_dofs_.size(); ++i) {
    const int dof = arm_dofs_[i];
    d->ctrl[i] = task[dof] + scratch_[static_cast<std::size_t>(dof)] - removed[dof] + d->qfrc_bias[dof];
  }
  if (motion_.joint_stiffness > 0.0 && !stopped_) {
    // The whole configuration held too (free-drive's checked joints), moving with the drift.
    const bool moving = motion_.drift && motion_.posture_velocity.size() == static_cast<int>(arm_dofs_.size());
    const double along = moving ? std::clamp(toSeconds(now_() - start_), 0.0, toSeconds(motion_.drift->horizon)) : 0.0;
    const bool drifting = moving && now_() - start_ < motion_.drift->horizon;
    for (std::size_t i = 0; i < arm_dofs_.size(); ++i) {
      const int dof = arm_dofs_[i];
      const int j = static_cast<int>(i);
      const double target = motion_.posture[j] + (moving ? motion_.posture_velocity[j] * along : 0.0);
      const double rate = drifting ? motion_.posture_velocity[j] : 0.0;
      const double joint_inertia = std::max(d->qM[m->dof_Madr[dof]], 1e-3);  // kg m^2 about the joint now
      d->ctrl[i] += motion_.joint_stiffness * (target - d->qpos[arm_qpos_[i]]) +
                    2.0 * std::sqrt(motion_.joint_stiffness * joint_inertia) * (rate - d->qvel[dof]);
    }
  }
}

}  // namespace costar::sim
