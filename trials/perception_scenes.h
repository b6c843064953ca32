#pragma once
// Scenes for perception's training data and its evaluation (trials/perception_collect.h,
// trials/perception_eval.h): the cell's own arm posed over the table, its gripper's fingers
// anywhere between open and closed; links lying across nodes (the stacked parts of an assembly).

#include <memory>
#include <optional>
#include <random>
#include <vector>

#include "arm/kinematics.h"
#include "sim/scene.h"
#include "sim/simulation.h"
#include "workcell/cell_simulation.h"
#include "world/object_class.h"

namespace costar::trials {

/// A random configuration of the cell's arm, each joint uniform within its limits (a revolute
/// joint's range cut to one turn about its middle: more repeats poses), that puts the flange over
/// the table (x 0.2-0.8 m, |y| < 0.45 m, 8 cm above `min_height` to 0.35 m) with the tool pointing
/// down or sideways, judged by the arm's forward kinematics; nullopt when 20,000 draws found none.
std::optional<sim::ArmJoints> armOverTable(const workcell::CellSimulation& cell, const arm::Kinematics& kinematics,
                                           double min_height, std::mt19937_64& random);

/// Where the arm stands and where its fingers were sent: enough to pose them so again.
struct ArmOverPose {
  sim::ArmJoints arm;
  /// The 3-finger hand's three finger positions (0 open, 1 closed), or the 2-finger gripper's
  /// opening (m, one value).
  std::vector<double> fingers;
};

/// The cell's simulation of `scene` with the arm posed over the table (armOverTable; the tool
/// centre point `min_height` or more above it, no arm or gripper geom touching the table), the
/// fingers sent somewhere between open and closed (they get there in about half a second of
/// simulated time, which the caller runs); null when 50 poses failed. `posed`, when given, gets
/// the pose chosen (simulationWithArmOver poses it so again).
std::unique_ptr<sim::Simulation> armOverTableSimulation(const workcell::CellSimulation& cell,
                                                        const arm::Kinematics& kinematics, const sim::Scene& scene,
                                                        sim::SimulationOptions sim_options, double min_height,
                                                        std::mt19937_64& random, ArmOverPose* posed = nullptr);

/// The simulation of `scene` with the arm standing at `pose.arm` and its fingers sent to
/// `pose.fingers` (the caller runs the half second they take).
/// @throws std::invalid_argument when the joint or finger count does not fit the cell's arm
/// and gripper.
std::unique_ptr<sim::Simulation> simulationWithArmOver(const sim::Scene& scene, sim::SimulationOptions sim_options,
                                                       const ArmOverPose& pose);

/// Puts `count` links lying across nodes of `scene` (each over a node on the table not used yet,
/// turned at random, up to 3 cm off its middle, dropped from just above it). Only parts placed
/// with "at" are considered (sim::clutteredScene places every part so). Returns how many.
int stackLinksOnNodes(sim::Scene& scene, const std::vector<world::ObjectClass>& classes, int count,
                      std::mt19937_64& random);

}  // namespace costar::trials
