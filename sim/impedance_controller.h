#pragma once
// The simulated arm controller's Cartesian impedance mode (arm/cartesian_controller.h), as the
// LBR iiwa's controller offers it: at every physics step the joint torques
//   tau = J^T (K e + D (v_ref - v) + f) + null-space posture torque + gravity and Coriolis
// of the tool centre point's Jacobian J, where e is the pose error from the motion's reference
// (its path's pose moved along the force axis by the admittance's offset), K the stiffness per
// tool axis, D = 2 zeta sqrt(K Lambda) per tool axis with Lambda the arm's Cartesian inertia,
// and f the target force along the force axis once the tool touches. The offset moves toward
// the force: at the approach speed until the tool first touches (half the target force), then
// at (target - measured) / (k tau) (tau 0.1 s), within the approach speed; at that touch it
// steps back by the measured force over k, as f is added, so the command steps to the target and
// not past it. The measured force is the simulated wrist sensor's (noise and tare included), as a
// real controller would have it. The commanded force is limited to the motion's force limit; a
// measured force above it stops the motion (state().force_limit_stop): no more pressing, the
// reference frozen where the tool is, so the force goes and the tool does not jump back. The
// motors' torque limits clamp the rest (MuJoCo's actuator ctrlrange). No MuJoCo type appears here.

#include <cstdint>
#include <functional>
#include <limits>
#include <vector>

#include <Eigen/Geometry>

#include "arm/cartesian_controller.h"
#include "sim/force_torque.h"

struct mjModel_;
struct mjData_;

namespace costar::sim {

class SimCartesianController final : public arm::CartesianController {
 public:
  /// `arm_dofs`: the arm's joints' degrees of freedom in the model, base first (the first
  /// actuators drive them in this order). Everything passed must outlive the controller.
  /// @throws std::runtime_error when the model lacks the site `tcp_site`.
  SimCartesianController(const mjModel_* model, mjData_* data, const char* tcp_site, std::vector<int> arm_dofs,
                         std::vector<int> arm_qpos, const SimForceTorqueSensor& sensor, std::function<TimePoint()> now);

  void follow(arm::CartesianMotion motion, TimePoint start) override;
  void setForce(double force) override;
  arm::CartesianState state() const override;
  arm::JointVector torqueLimits() const override;

  /// Whether a Cartesian motion is in control (the simulation calls control() then).
  bool active() const { return active_; }
  /// Hands control back to the joint controller (a joint trajectory was given).
  void release() { active_ = false; }
  /// Sets the arm's motor commands for this physics step (after mj_step1).
  void control();

 private:
  /// The force the tool pushes with, from the sensor, in the world.
  Eigen::Vector3d measuredForce() const;
  Eigen::Vector3d tcpPosition() const;
  Eigen::Matrix3d tcpRotation() const;

  const mjModel_* model_;
  mjData_* data_;
  int tcp_site_ = 0;
  int ft_site_ = 0;
  std::vector<int> arm_dofs_;
  std::vector<int> arm_qpos_;
  const SimForceTorqueSensor& sensor_;
  std::function<TimePoint()> now_;

  bool active_ = false;
  arm::CartesianMotion motion_;
  TimePoint start_{};
  std::uint64_t count_ = 0;
  double offset_ = 0.0;   // m along the force axis
  bool touched_ = false;  // the tool has touched since the motion started
  double arc_ = 0.0;
  bool path_done_ = false;
  bool stopped_ = false;  // by the force limit
  double stop_force_ = 0.0;
  double axis_force_ = 0.0;
  world::Pose frozen_ = world::Pose::Identity();  // where a stopped motion holds the tool
  // Scratch, sized once.
  std::vector<double> jacobian_;         // 6 x nv, row-major (translation rows, then rotation)
  std::vector<double> solved_;           // 6 x nv
  std::vector<double> scratch_;          // nv
  std::vector<double> posture_scratch_;  // nv
};

}  // namespace costar::sim
