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

/// The cell's simulation of `scene` with the arm posed over the table (armOverTable; the tool
/// centre point `min_height` or more above it, no arm or gripper geom touching the table), the
/// fingers sent somewhere between open and closed (they get there in about half a second of
/// simulated time, which the caller runs); null when 50 poses failed.
std::unique_ptr<sim::Simulation> armOverTableSimulation(const workcell::CellSimulation& cell,
                                                        const arm::Kinematics& kinematics, const sim::Scene& scene,
                                                        sim::SimulationOptions sim_options, double min_height,
                                                        std::mt19937_64& random);

/// Puts `count` links lying across nodes of `scene` (each over a node on the table not used yet,
/// turned at random, up to 3 cm off its middle, dropped from just above it). Only parts placed
/// with "at" are considered (sim::clutteredScene places every part so). Returns how many.
int stackLinksOnNodes(sim::Scene& scene, const std::vector<world::ObjectClass>& classes, int count,
                      std::mt19937_64& random);

}  // namespace costar::trials
