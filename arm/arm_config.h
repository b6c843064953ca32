#pragma once
// How an arm is set up in a cell: where it stands, its tool, its joints' names, home, speeds
// and the tolerances of its motions. Read by the Arm component and its motion planner.

#include <cmath>
#include <string>
#include <vector>

#include "arm/joints.h"
#include "core/clock.h"
#include "planning/planner.h"
#include "world/pose.h"

namespace costar::arm {

struct ArmConfig {
  std::string name = "arm";
  /// The component's concrete type (the robot description's "type", e.g. "UR5").
  std::string type = "Arm";
  /// Where the robot's base frame is in the world.
  world::Pose base_in_world = world::Pose::Identity();
  /// The tool centre point in the flange frame (between the gripper's finger pads).
  world::Pose tcp_in_flange = world::Pose::Identity();
  /// The gripper's own links in the collision model: the flange link its body is mounted on (the
  /// robot description's tool.name) and the gripper's links (its description's fingers), not the
  /// arm's wrist that carries them. Free-drive brings them as near a part or the table as the
  /// tool's stopping distance and the hand's push need, where the arm's links keep the whole
  /// look-ahead (arm/free_drive.h). Empty: every link keeps the whole look-ahead.
  std::vector<std::string> gripper_links;
  /// The joints' names (in arm_joints and joint waypoints) and labels for people ("wrist 3"),
  /// base first; empty: "joint_1", "joint_2"... and no labels.
  std::vector<std::string> joint_names;
  std::vector<std::string> joint_labels;
  /// The home configuration (Home), one angle per joint.
  JointVector home{};
  /// Default speed of motions: a fraction of the joint velocity and acceleration limits.
  double default_speed = 0.5;
  /// at_waypoint tolerances.
  double at_waypoint_distance = 0.005;            // m
  double at_waypoint_angle = 2.0 * M_PI / 180.0;  // rad
  double at_waypoint_joints = 0.01;               // rad
  /// A motion fails if the arm is not within this of its goal this long after the end.
  double arrival_tolerance = 0.005;  // rad
  Duration settle_time = std::chrono::seconds(1);
  /// A joint state older than this (by the driver's stamp) means the driver stopped updating.
  Duration state_timeout = std::chrono::milliseconds(50);
  /// Cartesian straight lines are followed through IK points this far apart.
  double line_step = 0.005;  // m
  planning::PlannerOptions planner;
};

}  // namespace costar::arm
