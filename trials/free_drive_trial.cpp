#include "trials/free_drive_trial.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <set>
#include <stdexcept>

#include <Eigen/Geometry>

#include "arm/arm_component.h"
#include "arm/free_drive.h"
#include "bt/builder.h"
#include "bt/executor.h"
#include "bt/plan_xml.h"
#include "sim/simulation.h"
#include "workcell/workcell.h"

namespace costar::trials {

namespace {

constexpr double kMaxHandForce = 45.0;    // N: a firm push
constexpr double kMaxHandTorque = 1.5;    // N m
constexpr double kPullStiffness = 150.0;  // N/m: how the hand pulls toward its target
constexpr double kTurnStiffness = 3.0;    // N m/rad
constexpr double kStillSpeed = 0.02;      // rad/s

bool isRobotBody(const std::string& name) {
  static const std::set<std::string> robot{"arm",      "left_finger", "right_finger", "finger_middle",
                                           "finger_1", "finger_2",    "palm"};
  return robot.contains(name);
}

/// Runs one node to its end; returns the failure reason, or empty.
std::string runNode(workcell::Workcell& cell, const std::string& node, const std::function<void()>& each_tick) {
  const bt::Plan plan =
      bt::loadPlanText(R"(<root BTCPP_format="4"><BehaviorTree ID="drag">)" + node + "</BehaviorTree></root>", "drag",
                       {.follow_includes = false});
  bt::Tree tree = bt::buildTree(plan, cell.nodes(), cell.clock());
  bt::Executor executor(tree, cell.clock());
  executor.setBeforeTick([&] {
    cell.beforeTick();
    if (each_tick) {
      each_tick();
    }
  });
  const bt::RunResult result = executor.run();
  return result.status == bt::Status::kSuccess ? std::string() : result.failure_reason;
}

}  // namespace

FreeDriveTrialResult runFreeDriveTrial(workcell::Workcell& cell, const FreeDriveTrialOptions& options) {
  sim::Simulation* simulation = cell.simulation();
  if (simulation == nullptr) {
    throw std::invalid_argument("the free-drive trial needs a simulated workcell, not '" + cell.name() + "'");
  }
  auto* arm = dynamic_cast<arm::ArmComponent*>(cell.components().provider("FreeDrive"));
  if (arm == nullptr) {
    throw std::invalid_argument("workcell '" + cell.name() + "' has no arm with FreeDrive");
  }
  FreeDriveTrialResult result;
  // The parts known to the collision world, as a person would have detected them first.
  if (cell.components().provider("DetectObjects") != nullptr) {
    if (std::string failure = runNode(cell, "<DetectObjects/>", {}); !failure.empty()) {
      result.failure = "DetectObjects: " + failure;
      return result;
    }
  }
  std::set<std::string> parts;
  for (const sim::PartState& part : simulation->parts()) {
    parts.insert(part.name);
  }
  const arm::JointLimits& limits = arm->limits();
  std::mt19937_64 random(options.seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const sim::Region table = sim::defaultRegions().at("table");

  const TimePoint start = cell.clock().now();
  const auto elapsed = [&] { return toSeconds(cell.clock().now() - start); };
  result.closest_to_limit = 1e9;
  result.least_dexterity = 1e9;
  result.lowest_tool = 1e9;
  const std::uint64_t table_steps_before = simulation->armTableContactSteps();
  world::Pose last_tcp = simulation->tcpPose();
  TimePoint last_time = cell.clock().now();

  const auto judge = [&] {
    const arm::JointVector q = simulation->armPositions();
    bool violated = false;
    for (int j = 0; j < q.size(); ++j) {
      const double margin = std::min(q[j] - limits.min_position[j], limits.max_position[j] - q[j]);
      result.closest_to_limit = std::min(result.closest_to_limit, margin);
      violated = violated || margin < 0.0;
    }
    result.joint_limit_violations += violated ? 1 : 0;
    const arm::ArmComponent::FreeDriveStatus checked = arm->freeDriveStatus();
    if (checked.active) {
      result.max_tracking = std::max(result.max_tracking, checked.tracking);
    }
    if (checked.active && checked.checked.size() == q.size()) {
      for (int j = 0; j < q.size(); ++j) {
        result.max_departure = std::max(result.max_departure, std::abs(q[j] - checked.checked[j]));
      }
      const arm::Dexterity here = arm::dexterity([arm](const arm::JointVector& at) { return arm->toolAt(at); }, q);
      if (here.value < result.least_dexterity) {
        result.least_dexterity = here.value;
        result.least_dexterity_joints.clear();
        for (int j : here.joints) {
          result.least_dexterity_joints += (result.least_dexterity_joints.empty() ? "" : ", ") + std::to_string(j);
        }
      }
    }
    for (const auto& [a, b] : simulation->contacts()) {
      if ((isRobotBody(a) && parts.contains(b)) || (isRobotBody(b) && parts.contains(a))) {
        if (result.part_contact_ticks == 0) {
          result.first_part_contact = a + " / " + b + " at " + std::to_string(elapsed()) + " s";
        }
        ++result.part_contact_ticks;
        break;
      }
    }
    const world::Pose tcp = simulation->tcpPose();
    const double dt = toSeconds(cell.clock().now() - last_time);
    if (dt > 0.0) {
      const double distance = (tcp.translation() - last_tcp.translation()).norm();
      if (distance / dt > result.max_tool_speed) {
        result.max_tool_speed = distance / dt;
        result.max_speed_at = elapsed();
        result.max_speed_held = arm->freeDriveStatus().active;
      }
      result.travelled += distance;
    }
    result.lowest_tool = std::min(result.lowest_tool, tcp.translation().z());
    last_tcp = tcp;
    last_time = cell.clock().now();
    const arm::ArmComponent::FreeDriveStatus status = arm->freeDriveStatus();
    if (status.active && !status.blocked.empty()) {
      ++result.blocked[status.blocked];
    }
  };

  const std::vector<std::pair<std::string, std::string>> modes = {
      {"free", ""}, {"translation", ""}, {"rotation", ""}, {"free", "z"}};
  while (elapsed() < options.seconds && result.failure.empty()) {
    // One hold of the dead-man: 5 to 30 s in one guiding mode.
    const double r = unit(random);
    const auto& mode = !options.modes ? modes[0]
                       : r < 0.5      ? modes[0]
                       : r < 0.7      ? modes[1]
                       : r < 0.85     ? modes[2]
                                      : modes[3];
    const double hold_end = std::min(options.seconds, elapsed() + 5.0 + 25.0 * unit(random));
    double next_target = 0.0;
    Eigen::Vector3d target = simulation->tcpPose().translation();
    Eigen::Matrix3d turn_to = simulation->tcpPose().linear();
    ++result.holds;
    const std::string failure =
        runNode(cell, "<FreeDrive mode=\"" + mode.first + "\" locked=\"" + mode.second + "\" hold=\"0.3\"/>", [&] {
          judge();
          const double now = elapsed();
          if (now >= hold_end) {
            simulation->setHandWrench({});
            return;  // let go: the dead-man lapses
          }
          if (now >= next_target) {
            next_target = now + 1.0 + 4.0 * unit(random);
            target = Eigen::Vector3d(table.min.x() + unit(random) * (table.max.x() - table.min.x()),
                                     table.min.y() + unit(random) * (table.max.y() - table.min.y()),
                                     unit(random) < 0.25 ? -0.1 : 0.02 + 0.5 * unit(random));
            if (unit(random) < 0.15 && !parts.empty()) {  // into a part
              auto it = parts.begin();
              std::advance(it, static_cast<long>(unit(random) * static_cast<double>(parts.size())) %
                                   static_cast<long>(parts.size()));
              for (const sim::PartState& part : simulation->parts()) {
                if (part.name == *it) {
                  target = part.pose.translation();
                }
              }
            }
            const Eigen::Vector3d axis = Eigen::Vector3d(unit(random) - 0.5, unit(random) - 0.5, unit(random) - 0.5);
            turn_to = Eigen::AngleAxisd(0.8 * unit(random), axis.normalized()) * simulation->tcpPose().linear();
          }
          const world::Pose tcp = simulation->tcpPose();
          arm::Wrench hand;
          hand.force = kPullStiffness * (target - tcp.translation());
          if (hand.force.norm() > kMaxHandForce) {
            hand.force *= kMaxHandForce / hand.force.norm();
          }
          const Eigen::AngleAxisd error(turn_to * tcp.linear().transpose());
          hand.torque = kTurnStiffness * error.angle() * error.axis();
          if (hand.torque.norm() > kMaxHandTorque) {
            hand.torque *= kMaxHandTorque / hand.torque.norm();
          }
          simulation->setHandWrench(hand);
          arm->holdFreeDrive(std::chrono::milliseconds(300));
        });
    simulation->setHandWrench({});
    if (!failure.empty()) {
      result.failure = failure;
      break;
    }
    // Let go: how long until the arm is at rest (the operation stopped it).
    const double let_go = elapsed();
    double still_at = -1.0;
    runNode(cell, "<Sleep msec=\"500\"/>", [&] {
      judge();
      if (still_at < 0.0 && arm::maxAbs(simulation->armVelocities()) < kStillSpeed) {
        still_at = elapsed();
      }
    });
    result.max_stop_time = std::max(result.max_stop_time, still_at < 0.0 ? 0.5 : still_at - let_go);
  }
  result.seconds = elapsed();
  result.table_contact_steps = simulation->armTableContactSteps() - table_steps_before;
  return result;
}

namespace {

/// The distance of `p` to the polyline `path`, and where along it (index of the segment, fraction).
std::pair<double, std::pair<std::size_t, double>> nearest(const std::vector<world::Pose>& path,
                                                          const Eigen::Vector3d& p) {
  double best = (path.front().translation() - p).norm();
  std::pair<std::size_t, double> where{0, 0.0};
  for (std::size_t i = 1; i < path.size(); ++i) {
    const Eigen::Vector3d a = path[i - 1].translation();
    const Eigen::Vector3d ab = path[i].translation() - a;
    const double s = ab.squaredNorm() > 0.0 ? std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0) : 0.0;
    const double distance = (a + s * ab - p).norm();
    if (distance < best) {
      best = distance;
      where = {i - 1, s};
    }
  }
  return {best, where};
}

}  // namespace

ReplayTrialResult runReplayTrial(workcell::Workcell& cell, std::uint64_t seed, double speed, const std::string& name) {
  sim::Simulation* simulation = cell.simulation();
  auto* arm =
      simulation == nullptr ? nullptr : dynamic_cast<arm::ArmComponent*>(cell.components().provider("FreeDrive"));
  if (arm == nullptr) {
    throw std::invalid_argument("the replay trial needs a simulated workcell with free-drive, not '" + cell.name() +
                                "'");
  }
  ReplayTrialResult result;
  std::mt19937_64 random(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  // The stroke: an arc of radius 0.1-0.15 m through 80-120 degrees, in a plane tilted up to 20
  // degrees, drawn in 3 to 5 s, the tool turning up to 15 degrees about its axis meanwhile.
  const world::Pose start = simulation->tcpPose();
  const double radius = 0.1 + 0.05 * unit(random);
  const double sweep = (80.0 + 40.0 * unit(random)) * M_PI / 180.0;
  const double heading = 2.0 * M_PI * unit(random);
  const double tilt = 20.0 * M_PI / 180.0 * unit(random);
  const double stroke_seconds = 3.0 + 2.0 * unit(random);
  const double twist = (unit(random) - 0.5) * 30.0 * M_PI / 180.0;
  const Eigen::Matrix3d plane =
      (Eigen::AngleAxisd(heading, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(tilt, Eigen::Vector3d::UnitX()))
          .toRotationMatrix();
  const Eigen::Vector3d centre = start.translation() - plane * Eigen::Vector3d(radius, 0.0, 0.0);
  std::vector<world::Pose> recorded;
  const TimePoint began = cell.clock().now();
  const std::string failure = runNode(cell, "<FreeDrive mode=\"free\" hold=\"0.2\" record=\"" + name + "\"/>", [&] {
    const double t = toSeconds(cell.clock().now() - began);
    const world::Pose tcp = simulation->tcpPose();
    if (t > stroke_seconds + 1.0) {
      simulation->setHandWrench({});
      return;
    }
    recorded.push_back(tcp);
    const double s = std::clamp(t / stroke_seconds, 0.0, 1.0);
    const double eased = s * s * (3.0 - 2.0 * s);  // the hand starts and ends gently
    const Eigen::Vector3d target =
        centre + plane * Eigen::Vector3d(radius * std::cos(sweep * eased), radius * std::sin(sweep * eased), 0.0);
    const Eigen::Matrix3d turn_to = Eigen::AngleAxisd(twist * eased, Eigen::Vector3d::UnitZ()) * start.linear();
    arm::Wrench hand;
    hand.force = 600.0 * (target - tcp.translation());
    if (hand.force.norm() > 40.0) {
      hand.force *= 40.0 / hand.force.norm();
    }
    const Eigen::AngleAxisd error(turn_to * tcp.linear().transpose());
    hand.torque = 8.0 * error.angle() * error.axis();
    simulation->setHandWrench(hand);
    arm->holdFreeDrive(std::chrono::milliseconds(100));
  });
  simulation->setHandWrench({});
  if (!failure.empty()) {
    result.failure = "recording: " + failure;
    return result;
  }
  result.samples = recorded.size();
  result.recorded_seconds = stroke_seconds;
  for (std::size_t i = 1; i < recorded.size(); ++i) {
    result.length += (recorded[i].translation() - recorded[i - 1].translation()).norm();
  }
  // Replay, from where the stroke ended: to its start, then along it.
  std::vector<world::Pose> replayed;
  std::optional<TimePoint> on_path;
  const std::string replay_failure =
      runNode(cell, "<FollowTrajectory trajectory=\"" + name + "\" speed=\"" + std::to_string(speed) + "\"/>", [&] {
        const world::Pose tcp = simulation->tcpPose();
        if (!on_path && (tcp.translation() - recorded.front().translation()).norm() < 0.002 &&
            arm::maxAbs(simulation->armVelocities()) < 0.02) {
          on_path = cell.clock().now();
        }
        if (on_path) {
          replayed.push_back(tcp);
        }
      });
  if (!replay_failure.empty()) {
    result.failure = "replay: " + replay_failure;
    return result;
  }
  if (on_path) {
    result.replay_seconds = toSeconds(cell.clock().now() - *on_path);
  }
  // Each replayed pose against the recorded path, each recorded pose against the replayed one.
  double sum = 0.0;
  std::size_t count = 0;
  const auto compare = [&](const std::vector<world::Pose>& from, const std::vector<world::Pose>& to) {
    for (const world::Pose& pose : from) {
      const auto [distance, where] = nearest(to, pose.translation());
      sum += distance * distance;
      ++count;
      result.max_position = std::max(result.max_position, distance);
      const std::size_t next = std::min(where.first + 1, to.size() - 1);
      const world::Pose& there = where.second < 0.5 ? to[where.first] : to[next];
      result.max_angle = std::max(result.max_angle, world::rotationAngle(pose, there));
    }
  };
  if (replayed.size() < 2) {
    result.failure = "the replay never reached the stroke's start";
    return result;
  }
  compare(replayed, recorded);
  compare(recorded, replayed);
  result.rms_position = std::sqrt(sum / static_cast<double>(count));
  if (const auto kept = arm->waypoints().findTrajectory(name)) {
    result.kept = kept->poses.size();
  }
  return result;
}

}  // namespace costar::trials
