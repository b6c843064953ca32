#include "trials/perception_scenes.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "gripper/adaptive_gripper_driver.h"

namespace costar::trials {

std::optional<sim::ArmJoints> armOverTable(const workcell::CellSimulation& cell, const arm::Kinematics& kinematics,
                                           double min_height, std::mt19937_64& random) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const arm::JointLimits& limits = cell.robot.limits;
  const int joints = cell.robot.jointCount();
  for (int attempt = 0; attempt < 20000; ++attempt) {
    arm::JointVector q(joints);
    for (int j = 0; j < joints; ++j) {
      const double middle = 0.5 * (limits.min_position[j] + limits.max_position[j]);
      const double low = std::max(limits.min_position[j], middle - M_PI);
      const double high = std::min(limits.max_position[j], middle + M_PI);
      q[j] = low + (high - low) * unit(random);
    }
    const world::Pose flange = cell.cell.robot_base * kinematics.forward(q);
    const Eigen::Vector3d p = flange.translation();
    const double down = flange.linear().col(2).z();  // the tool axis' vertical component
    if (p.x() > 0.2 && p.x() < 0.8 && std::abs(p.y()) < 0.45 && p.z() > min_height + 0.08 && p.z() < 0.35 &&
        down < 0.2) {
      return q;
    }
  }
  return std::nullopt;
}

std::unique_ptr<sim::Simulation> armOverTableSimulation(const workcell::CellSimulation& cell,
                                                        const arm::Kinematics& kinematics, const sim::Scene& scene,
                                                        sim::SimulationOptions sim_options, double min_height,
                                                        std::mt19937_64& random, ArmOverPose* posed) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int attempt = 0; attempt < 50; ++attempt) {
    const std::optional<sim::ArmJoints> q = armOverTable(cell, kinematics, min_height, random);
    if (!q) {
      return nullptr;
    }
    sim_options.initial_arm = *q;
    auto candidate = sim::Simulation::create(scene, sim_options);
    const Eigen::Vector3d tcp = candidate->tcpPose().translation();
    if (tcp.x() < 0.2 || tcp.x() > 0.8 || std::abs(tcp.y()) > 0.45 || tcp.z() < min_height ||
        candidate->armTableContactSteps() != 0) {
      continue;
    }
    ArmOverPose pose;
    pose.arm = *q;
    if (gripper::AdaptiveGripperDriver* hand = candidate->adaptiveGripper()) {
      pose.fingers = {unit(random), unit(random), unit(random)};
      hand->commandFingers({pose.fingers[0], pose.fingers[1], pose.fingers[2]}, 1.0, 20.0);
    } else {
      pose.fingers = {candidate->maxOpening() * unit(random)};
      candidate->commandFingers(pose.fingers[0], 0.1, 20.0);
    }
    if (posed != nullptr) {
      *posed = pose;
    }
    return candidate;
  }
  return nullptr;
}

std::unique_ptr<sim::Simulation> simulationWithArmOver(const sim::Scene& scene, sim::SimulationOptions sim_options,
                                                       const ArmOverPose& pose) {
  sim_options.initial_arm = pose.arm;
  auto simulation = sim::Simulation::create(scene, sim_options);
  if (pose.arm.size() != simulation->armPositions().size()) {
    throw std::invalid_argument("the arm pose has " + std::to_string(pose.arm.size()) + " joints, the cell's arm " +
                                std::to_string(simulation->armPositions().size()));
  }
  if (gripper::AdaptiveGripperDriver* hand = simulation->adaptiveGripper()) {
    if (pose.fingers.size() != 3) {
      throw std::invalid_argument("the 3-finger hand needs 3 finger positions, the pose has " +
                                  std::to_string(pose.fingers.size()));
    }
    hand->commandFingers({pose.fingers[0], pose.fingers[1], pose.fingers[2]}, 1.0, 20.0);
  } else {
    if (pose.fingers.size() != 1) {
      throw std::invalid_argument("the 2-finger gripper needs one opening, the pose has " +
                                  std::to_string(pose.fingers.size()) + " finger values");
    }
    simulation->commandFingers(pose.fingers[0], 0.1, 20.0);
  }
  return simulation;
}

int stackLinksOnNodes(sim::Scene& scene, const std::vector<world::ObjectClass>& classes, int count,
                      std::mt19937_64& random) {
  const auto node = std::find_if(classes.begin(), classes.end(), [](const auto& c) { return c.name == "node"; });
  const bool has_link = std::any_of(classes.begin(), classes.end(), [](const auto& c) { return c.name == "link"; });
  if (count <= 0 || node == classes.end() || !has_link) {
    return 0;  // draws nothing from `random`
  }
  std::vector<std::size_t> nodes;
  for (std::size_t p = 0; p < scene.parts.size(); ++p) {
    if (scene.parts[p].object_class == "node" && scene.parts[p].at && scene.parts[p].height == 0.0) {
      nodes.push_back(p);
    }
  }
  std::shuffle(nodes.begin(), nodes.end(), random);
  std::uniform_real_distribution<double> yaw(-180.0, 180.0);
  std::uniform_real_distribution<double> off(-0.03, 0.03);
  const world::ObjectClass& link_class =
      *std::find_if(classes.begin(), classes.end(), [](const auto& c) { return c.name == "link"; });
  std::vector<sim::Footprint> lying;  // the links put so far: two must not start inside each other
  for (std::size_t i = 0; i < nodes.size() && static_cast<int>(lying.size()) < count; ++i) {
    const Eigen::Vector3d under = *scene.parts[nodes[i]].at;
    sim::PartRequest link;
    link.object_class = "link";
    const double turn = yaw(random);
    const double along = off(random);
    link.at = Eigen::Vector3d(under.x() + along * std::cos(turn * M_PI / 180.0),
                              under.y() + along * std::sin(turn * M_PI / 180.0), turn);
    link.height = node->bounds().sizes().z() + 0.003;
    const sim::Footprint footprint = sim::Footprint::of(link_class, link.at->x(), link.at->y(), turn * M_PI / 180.0);
    if (std::any_of(lying.begin(), lying.end(),
                    [&footprint](const sim::Footprint& other) { return sim::closerThan(footprint, other, 0.002); })) {
      continue;
    }
    lying.push_back(footprint);
    scene.parts.push_back(link);
  }
  return static_cast<int>(lying.size());
}

}  // namespace costar::trials
