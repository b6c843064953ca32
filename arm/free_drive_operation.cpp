// The Arm component's FreeDrive operation (arm/free_drive.h): every tick it reads the wrist
// sensor, turns the hand's push into the reference's twist, checks the step and hands it to the
// controller's Cartesian impedance as a streamed reference; it ends, stopping the arm where it
// is, when the dead-man is let go or lapses (ArmComponent::holdFreeDrive), or when cancelled.

#include <algorithm>
#include <cmath>

#include "arm/arm_component.h"
#include "arm/arm_motion.h"
#include "arm/free_drive.h"
#include "arm/recorded_trajectory.h"

namespace costar::arm {

using component::OperationResult;
using component::ParamSpec;
using component::ValueType;

namespace {

/// How stiffly every joint is held to the configuration checked for collisions (N m/rad).
constexpr double kJointStiffness = 100.0;
/// Above this (N) on the wrist, whatever pushes, free-drive stops.
constexpr double kForceLimit = ArmComponent::kMaxForceLimit;
/// A recording shorter than this (m of the tool) is not kept.
constexpr double kShortestRecording = 0.005;
/// The arm must be this still (rad/s, any joint) for free-drive to begin.
constexpr double kStillSpeed = 0.05;
/// The tool's speed is measured over this (s) of the joints' measured velocity.
constexpr double kSpeedProbe = 1e-3;

}  // namespace

struct ArmComponent::FreeDriving {
  bool running = false;
  std::uint64_t operation = 0;  // which FreeDrive the dead-man is of
  TimePoint held_until{};
  bool released = false;
  FreeDriveStatus status;
};

void ArmComponent::declareFreeDrive(component::OperationTable& operations) {
  free_driving_ = std::make_shared<FreeDriving>();
  ParamSpec mode{"mode",
                 ValueType::kString,
                 "guiding mode: free, translation (the tool keeps its orientation), rotation (it keeps its place)",
                 std::string("free"),
                 {"free", "translation", "rotation"}};
  ParamSpec locked{"locked", ValueType::kString,
                   "axes the hand cannot move besides, comma-separated: x, y, z, rx, ry, rz (empty: none)",
                   std::string()};
  ParamSpec axes{
      "axes", ValueType::kString, "axes of the guiding mode: world or tool", std::string("world"), {"world", "tool"}};
  ParamSpec hold{"hold", ValueType::kDouble,
                 "seconds the arm may be guided from the start without the dead-man held; each hold adds as much", 0.5};
  hold.min = 0.05;
  hold.max = 600.0;
  ParamSpec record{"record", ValueType::kString,
                   "name to record the guided path under (a trajectory, kept beside the waypoints); empty: none",
                   std::string()};
  ParamSpec record_frame{"record_frame", ValueType::kString,
                         "frame the recorded path is relative to: world or a frame symbol (a detected part)",
                         std::string("world")};
  record_frame.choices_from = "frame";
  operations.add({"FreeDrive",
                  "Hand guiding: the arm yields to a push on the tool (gravity compensated, 250 mm/s at most, "
                  "never into the table or a known part) while its dead-man is held; let go, it stops and holds.",
                  {mode, locked, axes, hold, record, record_frame}},
                 [this](const component::ParamMap& params) { return freeDrive(params); });
}

bool ArmComponent::holdFreeDrive(Duration duration) {
  if (!free_driving_ || !free_driving_->running) {
    return false;
  }
  free_driving_->held_until = std::max(free_driving_->held_until, clock_.now() + duration);
  return true;
}

void ArmComponent::releaseFreeDrive() {
  if (free_driving_ && free_driving_->running) {
    free_driving_->released = true;
  }
}

ArmComponent::FreeDriveStatus ArmComponent::freeDriveStatus() const {
  if (!free_driving_ || !free_driving_->running) {
    return {};
  }
  return free_driving_->status;
}

namespace {

class FreeDriveOperation final : public component::RunningOperation {
 public:
  FreeDriveOperation(std::function<OperationResult(bool first)> tick, std::function<void()> end)
      : tick_(std::move(tick)), end_(std::move(end)) {}
  ~FreeDriveOperation() override {
    if (!result_) {
      end_();
    }
  }
  OperationResult poll() override {
    if (result_) {
      return *result_;
    }
    OperationResult result = tick_(first_);
    first_ = false;
    if (result.state != component::OperationState::kRunning) {
      result_ = result;
      end_();
    }
    return result;
  }
  void cancel() override {
    if (!result_) {
      result_ = OperationResult::failure("FreeDrive: cancelled; the arm was stopped");
      end_();
    }
  }

 private:
  std::function<OperationResult(bool)> tick_;
  std::function<void()> end_;
  bool first_ = true;
  std::optional<OperationResult> result_;
};

}  // namespace

std::unique_ptr<component::RunningOperation> ArmComponent::freeDrive(const component::ParamMap& params) {
  GuidingMode mode;
  try {
    mode =
        GuidingMode::parse(params.at("mode").asString(), params.at("locked").asString(), params.at("axes").asString());
  } catch (const std::invalid_argument& e) {
    return std::make_unique<component::FinishedOperation>(
        OperationResult::failure(std::string("FreeDrive: ") + e.what()));
  }
  if (maxAbs(checkedRead().velocity) > kStillSpeed) {
    return std::make_unique<component::FinishedOperation>(
        OperationResult::failure("FreeDrive: the arm is moving; free-drive begins with the arm at rest"));
  }
  if (free_driving_->running) {
    return std::make_unique<component::FinishedOperation>(
        OperationResult::failure("FreeDrive: free-drive is on already"));
  }
  const std::string record = params.at("record").asString();
  if (!record.empty()) {
    if (const std::string problem = checkWaypointName(record); !problem.empty()) {
      return std::make_unique<component::FinishedOperation>(OperationResult::failure("FreeDrive: record: " + problem));
    }
  }
  const std::string record_frame = params.at("record_frame").asString();
  const std::optional<world::Pose> frame_pose = frameInWorld(record_frame);
  if (!frame_pose) {
    return std::make_unique<component::FinishedOperation>(
        OperationResult::failure("FreeDrive: record_frame: unknown frame '" + record_frame + "'"));
  }
  const Duration hold =
      std::chrono::duration_cast<Duration>(std::chrono::duration<double>(params.at("hold").asDouble()));
  struct Run {
    GuidingMode mode;
    AdmittanceGains gains;
    world::Pose reference = world::Pose::Identity();
    JointVector joints{};
    Twist twist;
    Wrench start_reading;
    Eigen::Matrix3d sensor_at_start = Eigen::Matrix3d::Identity();
    TimePoint last{};
    std::uint64_t arm_motion = 0;
    double travelled = 0.0;
    TimePoint began{};
    RecordedTrajectory recording;  // the tool in the recording's frame, every tick
    world::Pose frame_inverse = world::Pose::Identity();
    ProtectiveStop protective;
    std::uint64_t control_motion = 0;  // the controller's motion count for the last reference given
  };
  auto run = std::make_shared<Run>();
  run->mode = mode;
  run->recording.name = record;
  run->recording.frame = record_frame;
  run->frame_inverse = frame_pose->inverse();
  FreeDriving& driving = *free_driving_;
  driving = FreeDriving{};
  driving.running = true;
  driving.operation = ++motion_->counter;
  driving.held_until = clock_.now() + hold;
  driving.status.active = true;
  driving.status.mode = mode.str();
  run->arm_motion = driving.operation;

  const world::Pose sensor_in_tool = config_.tcp_in_flange.inverse() * force_.sensor->inFlange();
  const Eigen::Vector3d tcp_in_sensor = sensor_in_tool.inverse().translation();
  const JointLimits& limits = kinematics_->limits();
  StepChecks check;
  check.reach = [this, &limits, margin = run->gains.joint_margin](const world::Pose& pose, const JointVector& seed,
                                                                  std::string& why) -> std::optional<JointVector> {
    const std::vector<JointVector> solutions = planner_->solutions(pose, seed);
    if (solutions.empty()) {
      why = "out of the arm's reach";
      return std::nullopt;
    }
    const JointVector& q = solutions.front();
    for (int j = 0; j < q.size(); ++j) {
      if (q[j] < limits.min_position[j] + margin || q[j] > limits.max_position[j] - margin) {
        why = "joint " + std::to_string(j + 1) + " at its limit";
        return std::nullopt;
      }
    }
    return q;
  };
  check.sweep = [this](const JointVector& from, const JointVector& to, std::string& why) {
    if (const auto contact = planner_->collisionAlong(from, to)) {
      why = contact->str();
      return false;
    }
    return true;
  };
  // The arm's links but the gripper's keep the whole look-ahead: the gripper's may touch anything
  // in that sweep (its own, shorter, is check.sweep's).
  check.sweep_arm = [this](const JointVector& from, const JointVector& to, std::string& why) {
    QueryScene scene(AllowedContacts::between(config_.gripper_links, planner_->obstacleNames()));
    scene.workspace = false;  // the tool's own look-ahead (check.sweep) keeps it in the workspace
    if (const auto contact = planner_->collisionAlong(from, to, scene)) {
      why = contact->str();
      return false;
    }
    return true;
  };
  check.displacement = [this](const JointVector& from, const JointVector& to) {
    return planner_->largestDisplacement(from, to);
  };
  check.dexterity = [this](const JointVector& q) {
    return dexterity([this](const JointVector& at) { return toolAt(at); }, q);
  };

  auto tick = [this, run, check, tcp_in_sensor, sensor_in_tool, &driving, &limits](bool first) -> OperationResult {
    const TimePoint now = clock_.now();
    if (motion_->counter != run->arm_motion) {
      return OperationResult::failure("FreeDrive: the arm was stopped, or another motion took over");
    }
    const ArmState state = checkedRead();
    const world::Pose tcp = toolAt(state.position);
    const Eigen::Matrix3d sensor = (tcp * sensor_in_tool).linear();
    const ForceTorqueReading reading = force_.sensor->read();
    if (first) {
      run->reference = tcp;
      run->joints = state.position;
      run->start_reading = reading.wrench;
      run->sensor_at_start = sensor;
      run->last = now;
      run->began = now;
    }
    if (!run->recording.name.empty() &&
        (run->recording.times.empty() || toSeconds(now - run->began) > run->recording.times.back())) {
      run->recording.times.push_back(toSeconds(now - run->began));
      run->recording.poses.push_back(run->frame_inverse * tcp);
    }
    const bool held = !driving.released && now <= driving.held_until;
    if (!held) {
      stopMotion(*motion_, driver_, clock_, kinematics_->limits());
      nlohmann::json data = {{"reason", driving.released ? "released" : "the dead-man lapsed"},
                             {"travelled_m", run->travelled}};
      if (!run->recording.name.empty()) {
        if (run->recording.length() < kShortestRecording) {
          return OperationResult::failure("FreeDrive: nothing recorded as '" + run->recording.name +
                                          "': the tool moved " + formatNumber("%.3f m", run->recording.length()) +
                                          " (less than " + formatNumber("%.3f m", kShortestRecording) + ")");
        }
        try {
          const RecordedTrajectory kept = simplify(run->recording);
          waypoints_.putTrajectory(kept);
          data["recorded"] = kept.name;
          data["samples"] = run->recording.poses.size();
          data["kept"] = kept.poses.size();
          data["seconds"] = kept.duration();
        } catch (const std::exception& e) {
          return OperationResult::failure("FreeDrive: the recording '" + run->recording.name +
                                          "' was not saved: " + e.what());
        }
      }
      return OperationResult::success(std::move(data));
    }
    const double dt = toSeconds(now - run->last);
    run->last = now;
    // The controller latches a force above the limit on the wrist until it is given the next
    // reference: read it before that (read after, it was never seen).
    if (const CartesianState control = force_.controller->state();
        !first && control.motion == run->control_motion && control.force_limit_stop) {
      stopMotion(*motion_, driver_, clock_, kinematics_->limits());
      return OperationResult::failure("FreeDrive: protective stop: the force on the wrist was " +
                                      formatNumber("%.0f N", control.stop_force) + " (at most " +
                                      formatNumber("%.0f N", kForceLimit) + "); the arm was stopped and holds");
    }
    // The tool's own speed and its distance from the reference, measured: a push the compliant
    // arm yields to shows there, not on the wrist.
    JointVector probe = state.position;
    for (int j = 0; j < probe.size() && j < state.velocity.size(); ++j) {
      probe[j] += state.velocity[j] * kSpeedProbe;
    }
    const world::Pose ahead = toolAt(probe);
    const double tool_speed = (ahead.translation() - tcp.translation()).norm() / kSpeedProbe;
    const double tracking = (tcp.translation() - run->reference.translation()).norm();
    const double turn = world::rotationAngle(run->reference, tcp);
    driving.status.tracking = tracking;
    if (const std::string why = run->protective.check(tool_speed, tracking, turn, dt); !why.empty()) {
      stopMotion(*motion_, driver_, clock_, kinematics_->limits());
      return OperationResult::failure("FreeDrive: protective stop: " + why + "; the arm was stopped and holds",
                                      {{"reason", "protective stop"},
                                       {"tool_speed_m_s", tool_speed},
                                       {"tracking_m", tracking},
                                       {"turn_rad", turn},
                                       {"travelled_m", run->travelled}});
    }
    const Wrench hand =
        handWrench(reading.wrench, run->start_reading, sensor, run->sensor_at_start, tcp_in_sensor, force_.payload);
    driving.status.hand = hand;
    FreeDriveStep step{run->reference, run->joints, Twist{}, {}};
    if (dt > 0.0) {
      const Twist wanted = admittance(hand, run->twist, dt, run->mode, run->reference.linear(), run->gains);
      JointVector max_step = limits.max_velocity;
      for (int j = 0; j < max_step.size(); ++j) {
        max_step[j] *= run->gains.joint_speed_fraction * dt;
      }
      // The gripper's short look-ahead keeps besides how far the arm truly is from the configuration
      // its steps were checked at (its links' largest displacement), beyond the push's give it
      // counts already: the joints' give under the hand, up to 1 cm of the gripper's body on the
      // UR5 turned sideways, which touched a node with the clearance alone.
      AdmittanceGains gains = run->gains;
      gains.clearance += std::max(
          0.0, planner_->largestDisplacement(state.position, run->joints) - hand.force.norm() / gains.stiffness);
      step = stepReference(run->reference, run->joints, wanted, dt, max_step, gains, check, hand.force);
    }
    CartesianMotion motion;
    motion.path = std::make_shared<CartesianPath>(CartesianPath::through({run->reference}, {}));
    motion.impedance.stiffness = Eigen::Vector3d::Constant(run->gains.stiffness);
    motion.impedance.rotational_stiffness = Eigen::Vector3d::Constant(run->gains.rotational_stiffness);
    motion.impedance.damping_ratio = 1.0;
    motion.force_limit = kForceLimit;
    // The checked joints held, not only the tool: near a singularity the tool's impedance alone
    // lets the elbow fold away from the configuration the step was checked at.
    motion.posture = run->joints;
    motion.joint_stiffness = kJointStiffness;
    motion.posture_velocity = JointVector::zero(run->joints.size());
    for (int j = 0; dt > 0.0 && j < run->joints.size(); ++j) {
      motion.posture_velocity[j] = (step.joints[j] - run->joints[j]) / dt;
    }
    motion.drift = CartesianMotion::Drift{step.twist.velocity, step.twist.angular_velocity,
                                          std::chrono::duration_cast<Duration>(std::chrono::duration<double>(dt))};
    motion_->trajectory.reset();
    motion_->cartesian = true;
    force_.controller->follow(std::move(motion), now);
    run->control_motion = force_.controller->state().motion;
    run->travelled += (step.reference.translation() - run->reference.translation()).norm();
    run->reference = step.reference;
    run->joints = step.joints;
    run->twist = step.twist;
    driving.status.blocked = step.blocked;
    driving.status.speed = step.twist.velocity.norm();
    driving.status.checked = step.joints;
    return OperationResult::running();
  };
  auto end = [this, run, &driving] {
    if (driving.running && motion_->counter == run->arm_motion) {
      stopMotion(*motion_, driver_, clock_, kinematics_->limits());
    }
    driving.running = false;
    driving.status = {};
  };
  return std::make_unique<FreeDriveOperation>(std::move(tick), std::move(end));
}

}  // namespace costar::arm
