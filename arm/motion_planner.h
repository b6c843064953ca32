#pragma once
// The motion service of one arm (arm/motion_service.h) in the arm's own process: its
// kinematics and set-up, the cell's collision world (read only: the workcell keeps the
// obstacles in it) and its driver's joint reading. The Arm component plans its own motions with
// one; the workcell builds another for the components that ask about motion (SmartMove).
//
// Every motion is planned before it runs: the goal is solved with the arm's IK (solutions
// within the joint limits, nearest first, the first collision-free one taken), the straight
// joint-space motion is checked along its whole length against the table, known parts and the
// arm itself, and when it would collide OMPL plans a way around; a straight Cartesian line is
// followed through IK points `line_step` apart and checked segment by segment. The path is then
// timed within the joint velocity and acceleration limits scaled by the speed.

#include <memory>
#include <string>
#include <vector>

#include "arm/arm_config.h"
#include "arm/arm_driver.h"
#include "arm/kinematics.h"
#include "arm/motion_service.h"

namespace costar::arm {

/// Why a reading of `joint_names.size()` joints cannot be trusted at `now` (not a number, too
/// many or too few values, older than `timeout` by its stamp), or empty.
std::string readingProblem(const ArmState& state, TimePoint now, Duration timeout,
                           const std::vector<std::string>& joint_names);

class MotionPlanner final : public MotionService {
 public:
  /// Everything passed by reference must outlive the planner. Uses of `config`: the base and
  /// tool, the joint names (messages), state_timeout, line_step and planner.
  /// @throws std::invalid_argument without kinematics.
  MotionPlanner(const ArmDriver& driver, const Clock& clock, const planning::CollisionWorld& collisions,
                std::shared_ptr<const Kinematics> kinematics, const ArmConfig& config);

  /// The driver's reading, checked (readingProblem()). @throws std::runtime_error naming the
  /// problem, or the driver's own error.
  ArmState checkedRead() const;

  JointVector joints() const override { return checkedRead().position; }
  world::Pose endpoint() const override { return toolAt(joints()); }
  world::Pose toolAt(const JointVector& q) const override;
  std::vector<JointVector> solutions(const world::Pose& tcp_in_world, const JointVector& seed) const override;
  std::optional<planning::Contact> collision(const JointVector& q, const QueryScene& scene) const override;
  /// The first contact along the straight joint motion from `from` to `to` (every configuration
  /// at the collision world's resolution), or nullopt.
  std::optional<planning::Contact> collisionAlong(const JointVector& from, const JointVector& to,
                                                  const QueryScene& scene = {}) const;
  /// The obstacles of the collision world now (the table, the known parts).
  std::vector<std::string> obstacleNames() const;
  /// How far (m) the point of the arm's collision shapes (links, gripper, tool) that moves most
  /// moves from `from` to `to`: each shape's centre's displacement plus its turn times its reach.
  double largestDisplacement(const JointVector& from, const JointVector& to) const;
  MotionPlan planToJoints(const JointVector& from, const JointVector& goal, double speed,
                          const QueryScene& scene = {}) const override;
  MotionPlan planLine(const JointVector& from, const world::Pose& tcp_in_world, double speed,
                      const QueryScene& scene = {}) const override;
  MotionPlan planToPose(const JointVector& from, const world::Pose& tcp_in_world, double speed,
                        const QueryScene& scene = {}) const override;

  /// A path of joint waypoints timed at `speed`: a point-to-point motion for two, a blended
  /// path through more. Fails (with the reason) for fewer than two or a path the limits refuse.
  MotionPlan timed(std::vector<JointVector> path, double speed) const;

  const Kinematics& kinematics() const { return *kinematics_; }
  const std::vector<std::string>& jointNames() const { return joint_names_; }

 private:
  world::Pose flangeInBase(const world::Pose& tcp_in_world) const;

  const ArmDriver& driver_;
  const Clock& clock_;
  const planning::CollisionWorld& collisions_;
  std::shared_ptr<const Kinematics> kinematics_;
  world::Pose base_in_world_;
  world::Pose tcp_in_flange_;
  std::vector<std::string> joint_names_;
  Duration state_timeout_;
  double line_step_;
  planning::PlannerOptions planner_;
};

}  // namespace costar::arm
