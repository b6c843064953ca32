// The Arm component's FollowTrajectory: replays a recorded trajectory (arm/recorded_trajectory.h)
// absolute or relative to a frame. The kept samples are interpolated every 5 mm and 2 degrees
// (lerp and slerp), each pose solved nearest to the one before within the joint limits and
// checked free of collisions; the arm goes to the start (a planned motion), then follows the
// joint path blended within 0.0002 rad, timed to last as long as the recording (`speed` 1) or
// longer, within the joint limits.

#include <algorithm>
#include <cmath>

#include "arm/arm_component.h"
#include "arm/arm_motion.h"
#include "arm/recorded_trajectory.h"

namespace costar::arm {

using component::OperationResult;
using component::ParamSpec;
using component::ValueType;

namespace {

constexpr double kStepDistance = 0.005;            // m between the poses solved
constexpr double kStepAngle = 2.0 * M_PI / 180.0;  // rad
/// The most a joint may turn between two poses solved (more: a branch of the inverse kinematics
/// changed, or a singularity: the path cannot be followed as recorded).
constexpr double kMaxJointStep = 0.25;
constexpr double kPathTolerance = 2e-4;  // rad, the joint path's blends
constexpr double kApproachSpeed = 0.3;

/// Runs two motions one after the other: to the start, then along the path.
class TwoMotions final : public component::RunningOperation {
 public:
  TwoMotions(std::unique_ptr<component::RunningOperation> first,
             std::function<std::unique_ptr<component::RunningOperation>()> second)
      : current_(std::move(first)), second_(std::move(second)) {}
  OperationResult poll() override {
    OperationResult result = current_->poll();
    if (result.state == component::OperationState::kSuccess && second_) {
      current_ = second_();
      second_ = nullptr;
      return OperationResult::running();
    }
    return result;
  }
  void cancel() override { current_->cancel(); }

 private:
  std::unique_ptr<component::RunningOperation> current_;
  std::function<std::unique_ptr<component::RunningOperation>()> second_;
};

}  // namespace

std::unique_ptr<component::RunningOperation> ArmComponent::followTrajectory(const component::ParamMap& params) {
  const auto failed = [](const std::string& reason) {
    return std::make_unique<component::FinishedOperation>(OperationResult::failure("FollowTrajectory: " + reason));
  };
  const std::string name = params.at("trajectory").asString();
  const std::optional<RecordedTrajectory> trajectory = waypoints_.findTrajectory(name);
  if (!trajectory) {
    return failed("unknown trajectory '" + name + "' (record one with FreeDrive's record)");
  }
  const std::string frame = params.at("frame").asString().empty() ? trajectory->frame : params.at("frame").asString();
  const std::optional<world::Pose> base = frameInWorld(frame);
  if (!base) {
    return failed("unknown frame '" + frame + "'");
  }
  const double speed = params.at("speed").asDouble();
  // The poses to solve, in the world.
  std::vector<world::Pose> poses{*base * trajectory->poses.front()};
  for (std::size_t i = 1; i < trajectory->poses.size(); ++i) {
    const world::Pose& from = trajectory->poses[i - 1];
    const world::Pose& to = trajectory->poses[i];
    const int steps =
        std::max(1, static_cast<int>(std::ceil(std::max((to.translation() - from.translation()).norm() / kStepDistance,
                                                        world::rotationAngle(from, to) / kStepAngle))));
    const double t0 = trajectory->times[i - 1];
    const double t1 = trajectory->times[i];
    for (int k = 1; k <= steps; ++k) {
      poses.push_back(*base * trajectory->at(t0 + (t1 - t0) * k / steps));
    }
  }
  std::vector<JointVector> path;
  JointVector seed;
  try {
    seed = checkedRead().position;
  } catch (const std::exception& e) {
    return failed(e.what());
  }
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const std::vector<JointVector> solutions = planner_->solutions(poses[i], seed);
    const std::string where =
        "the pose " + formatNumber("%.0f", 100.0 * static_cast<double>(i) / static_cast<double>(poses.size() - 1)) +
        " % along '" + name + "' in frame '" + frame + "'";
    if (solutions.empty()) {
      return failed(where + " is out of the arm's reach");
    }
    const JointVector& q = solutions.front();
    if (i > 0 && maxAbsDifference(q, seed) > kMaxJointStep) {
      return failed(where + " needs the joints to jump (a singularity or another arm configuration)");
    }
    if (const auto contact = planner_->collision(q, {})) {
      return failed(where + ": " + contact->str());
    }
    path.push_back(q);
    seed = q;
  }
  // Timed to last as long as the recording over the speed, or as the joint limits need.
  const double wanted = trajectory->duration() / speed;
  const auto duration_at = [&](double scale) {
    return toSeconds(JointTrajectory::alongPath(path, kinematics_->limits(), scale, kPathTolerance).duration());
  };
  double scale = 1.0;
  try {
    if (duration_at(1.0) < wanted) {
      double fast = 1.0;
      double slow = 0.005;
      for (int i = 0; i < 20; ++i) {
        const double middle = std::sqrt(fast * slow);
        (duration_at(middle) < wanted ? fast : slow) = middle;
      }
      scale = slow;
    }
    MotionPlan plan;
    plan.trajectory = std::make_shared<JointTrajectory>(
        JointTrajectory::alongPath(path, kinematics_->limits(), scale, kPathTolerance));
    plan.goal = path.back();
    plan.path = path;
    plan.speed = scale;
    MotionPlan approach = planToJoints(path.front(), kApproachSpeed);
    if (!approach.ok()) {
      return failed("to the start of '" + name + "': " + approach.failure);
    }
    return std::make_unique<TwoMotions>(
        execute(std::move(approach), "FollowTrajectory (to the start)"),
        [this, plan = std::move(plan)]() mutable { return execute(std::move(plan), "FollowTrajectory"); });
  } catch (const std::invalid_argument& e) {
    return failed(e.what());
  }
}

void ArmComponent::declareFollowTrajectory(component::OperationTable& operations) {
  ParamSpec name{"trajectory", ValueType::kString, "a recorded trajectory (FreeDrive's record)", {}};
  name.choices_from = "trajectory";
  ParamSpec frame{"frame", ValueType::kString,
                  "frame to replay it in: world or a frame symbol (a detected part); empty: the one it was recorded in",
                  std::string()};
  frame.choices_from = "frame";
  ParamSpec speed{"speed", ValueType::kDouble, "1: as fast as it was recorded; 0.5: half as fast", 1.0};
  speed.min = 0.1;
  speed.max = 1.0;
  operations.add({"FollowTrajectory",
                  "Replays a trajectory recorded by hand guiding, absolute or relative to a frame.",
                  {name, frame, speed}},
                 [this](const component::ParamMap& params) { return followTrajectory(params); });
}

}  // namespace costar::arm
