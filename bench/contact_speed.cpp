// The guarded approach's peak force against its speed (docs/FORCE.md "Contact at speed",
// docs/BENCHMARKS.md "Force control"): in each simulated cell, from 4 cm above the table with the
// tool pointing down, MoveUntilContact down with 10 N (max_force 40 N, distance 0.5 m) at each
// speed, then 1 s more of pressing. Judged from the simulator's true wrench at the flange (no
// bias, no noise; zeroed at rest before the approach), sampled at every 2 ms physics step:
//   peak      the largest force (N) from the approach's start until 1 s after the operation ended
//   held      the force 1 s after it ended
//   result    the operation's outcome (and the force it named when it failed)
//   moving    whether the cell reported arm_moving when the operation ended
// Usage: contact_speed [seed, default 11] [cells, comma-separated, default all four]
// [speeds m/s, comma-separated, default 0.002,0.01,0.03,0.05,0.1]. Run from the repository root:
// build/bench/contact_speed

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

#include "core/paths.h"
#include "sim/simulation.h"
#include "workcell/workcell.h"

namespace {

using namespace costar;

constexpr double kForce = 10.0;       // N
constexpr double kMaxForce = 40.0;    // N
constexpr double kStartAbove = 0.04;  // m above the table's touch, measured at 0.01 m/s

std::vector<std::string> split(const std::string& text) {
  std::vector<std::string> parts;
  std::stringstream stream(text);
  std::string part;
  while (std::getline(stream, part, ',')) {
    parts.push_back(part);
  }
  return parts;
}

struct Figures {
  std::string result;
  double peak = 0.0;
  double held = 0.0;
  double travel = 0.0;
  bool moving_at_end = false;
};

Figures run(const std::string& name, std::uint64_t seed, double speed, double start_z) {
  Figures figures;
  const auto cell = workcell::makeWorkcell({.name = name,
                                            .scene = dataRoot() / "sim/scenes/one_node.json",
                                            .seed = seed,
                                            .memory_only = true,
                                            .test_oracle_perception = true});
  sim::Simulation& simulation = *cell->simulation();
  const component::OperationResult moved = workcell::runOperation(
      *cell, "MoveToPose", {{"pose", world::poseFromXyzRpy(0.4, 0.3, start_z, M_PI, 0, 0)}}, std::chrono::seconds(60));
  if (moved.state != component::OperationState::kSuccess) {
    figures.result = "MoveToPose: " + moved.reason;
    return figures;
  }
  simulation.stepTo(simulation.time() + std::chrono::milliseconds(500));
  const Eigen::Vector3d rest = simulation.trueFlangeWrench().force;
  const double z0 = simulation.tcpPose().translation().z();
  const auto sample = [&] {
    figures.peak = std::max(figures.peak, (simulation.trueFlangeWrench().force - rest).norm());
  };
  const component::OperationResult result = workcell::runOperation(
      *cell, "MoveUntilContact",
      {{"direction", "down"}, {"force", kForce}, {"speed", speed}, {"distance", 0.5}, {"max_force", kMaxForce}},
      std::chrono::seconds(120), [&](const component::OperationResult&) { sample(); }, std::chrono::milliseconds(2));
  sample();
  cell->beforeTick();
  figures.moving_at_end = cell->components().world().holds("arm_moving", {});
  figures.travel = z0 - simulation.tcpPose().translation().z();
  if (result.state == component::OperationState::kSuccess) {
    figures.result = "SUCCESS";
  } else {
    figures.result = "FAILURE: " + result.reason;
  }
  const TimePoint end = simulation.time() + std::chrono::seconds(1);
  while (simulation.time() < end) {
    simulation.stepTo(simulation.time() + simulation.timestep());
    sample();
  }
  figures.held = (simulation.trueFlangeWrench().force - rest).norm();
  return figures;
}

}  // namespace

int main(int argc, char** argv) {
  const std::uint64_t seed = argc > 1 ? std::strtoull(argv[1], nullptr, 10) : 11;
  const std::vector<std::string> cells = split(argc > 2 ? argv[2] : "ur5-sim,iiwa-sim,iiwa-3f-sim,panda-sim");
  std::vector<double> speeds;
  for (const std::string& speed : split(argc > 3 ? argv[3] : "0.002,0.01,0.03,0.05,0.1")) {
    speeds.push_back(std::atof(speed.c_str()));
  }
  std::printf("%-12s %8s %8s %8s %9s %7s  %s\n", "cell", "m/s", "peak N", "held N", "travel m", "moving", "result");
  for (const std::string& name : cells) {
    // Where the tool touches the table, found at a slow approach, so that every speed starts
    // kStartAbove above it.
    const Figures probe = run(name, seed, 0.01, 0.06);
    const double start_z = 0.06 - probe.travel + kStartAbove;
    for (const double speed : speeds) {
      const Figures figures = run(name, seed, speed, start_z);
      std::printf("%-12s %8.3f %8.1f %8.1f %9.3f %7s  %s\n", name.c_str(), speed, figures.peak, figures.held,
                  figures.travel, figures.moving_at_end ? "true" : "false", figures.result.c_str());
      std::fflush(stdout);
    }
  }
  return 0;
}
