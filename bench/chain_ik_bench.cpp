// The general serial-chain inverse kinematics (arm/chain_kinematics.h) on every robot described
// in format costar-robot-description/1 (robots/*/NAME.json: the iiwa 14, the Panda, ...),
// against KDL's Levenberg-Marquardt solver (ChainIkSolverPos_LMA through planning::RobotModel on
// the URDF generated from the same file), on the same random reachable poses from the same
// random seeds, in the same run. Run from the repository root: build/bench/chain_ik_bench
//
// Poses: the flange poses of 2,048 configurations drawn uniformly within the joint limits; seeds
// drawn the same way (seed 20261, not a seed the tests use). Times are the process's CPU time
// (the machine is shared: wall time would count other processes), so solves_per_s is per CPU
// second. Counters: solved (the fraction of poses answered within the limits and within 1e-6 m
// and 1e-6 rad; KDL's within 1e-4 m and 1e-3 rad, its own stopping rule being looser).

#include <benchmark/benchmark.h>

#include <filesystem>
#include <iostream>
#include <optional>
#include <random>
#include <vector>

#include "arm/chain_kinematics.h"
#include "arm/robot_description.h"
#include "core/paths.h"
#include "planning/robot_model.h"

namespace costar::bench {
namespace {

constexpr int kPoseCount = 2048;

struct Workload {
  arm::RobotDescription robot;
  std::shared_ptr<const arm::ChainKinematics> chain;
  std::vector<world::Pose> poses;
  std::vector<arm::JointVector> seeds;   // random, anywhere within the limits
  std::vector<arm::JointVector> nudged;  // the answer moved by up to 0.05 rad per joint
};

Workload makeWorkload(const std::filesystem::path& file) {
  Workload work;
  work.robot = arm::loadRobotDescription(file);
  work.chain = std::make_shared<arm::ChainKinematics>(arm::readChainGeometry(file), work.robot.limits);
  const arm::JointLimits& limits = work.robot.limits;
  std::mt19937_64 random(20261);
  const auto draw = [&](int j) {
    return std::uniform_real_distribution<double>(limits.min_position[j], limits.max_position[j])(random);
  };
  for (int k = 0; k < kPoseCount; ++k) {
    arm::JointVector q(limits.size());
    arm::JointVector seed(limits.size());
    arm::JointVector nudged(limits.size());
    for (int j = 0; j < q.size(); ++j) {
      q[j] = draw(j);
      seed[j] = draw(j);
      nudged[j] = std::clamp(q[j] + std::uniform_real_distribution<double>(-0.05, 0.05)(random), limits.min_position[j],
                             limits.max_position[j]);
    }
    work.poses.push_back(work.chain->forward(q));
    work.seeds.push_back(seed);
    work.nudged.push_back(nudged);
  }
  return work;
}

double solvedFraction(const Workload& work, const std::vector<std::optional<arm::JointVector>>& answers,
                      std::int64_t iterations, double position_tolerance, double angle_tolerance) {
  const std::size_t visited = std::min<std::size_t>(answers.size(), static_cast<std::size_t>(iterations));
  std::size_t solved = 0;
  for (std::size_t k = 0; k < visited; ++k) {
    if (!answers[k]) {
      continue;
    }
    bool within = true;
    for (int j = 0; j < answers[k]->size(); ++j) {
      within = within && (*answers[k])[j] >= work.robot.limits.min_position[j] - 1e-9 &&
               (*answers[k])[j] <= work.robot.limits.max_position[j] + 1e-9;
    }
    const world::Pose reached = work.chain->forward(*answers[k]);
    solved += within && (reached.translation() - work.poses[k].translation()).norm() < position_tolerance &&
              world::rotationAngle(reached, work.poses[k]) < angle_tolerance;
  }
  return static_cast<double>(solved) / static_cast<double>(visited);
}

void chainSolves(benchmark::State& state, const Workload& work, bool tracking) {
  std::vector<std::optional<arm::JointVector>> answers(work.poses.size());
  std::size_t next = 0;
  for (auto _ : state) {
    answers[next] = work.chain->inverseNearest(work.poses[next], tracking ? work.nudged[next] : work.seeds[next]);
    benchmark::DoNotOptimize(answers[next]);
    next = (next + 1) % work.poses.size();
  }
  state.counters["solves_per_s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["solved"] = solvedFraction(work, answers, state.iterations(), 1e-6, 1e-6);
}

void kdlSolves(benchmark::State& state, const Workload& work, const std::filesystem::path& urdf) {
  const planning::RobotModel model =
      planning::RobotModel::fromUrdf(urdf.string(), work.robot.urdf_base_link, work.robot.urdf_tool_link);
  std::vector<std::optional<arm::JointVector>> answers(work.poses.size());
  std::size_t next = 0;
  for (auto _ : state) {
    const Eigen::VectorXd seed = Eigen::Map<const Eigen::VectorXd>(work.seeds[next].data(), work.seeds[next].size());
    const std::optional<Eigen::VectorXd> q = model.inverse(work.poses[next], seed, 10, next);
    answers[next] = q ? std::optional<arm::JointVector>(arm::JointVector::fromEigen(*q)) : std::nullopt;
    next = (next + 1) % work.poses.size();
  }
  state.counters["solves_per_s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["solved"] = solvedFraction(work, answers, state.iterations(), 1e-4, 1e-3);
}

}  // namespace
}  // namespace costar::bench

int main(int argc, char** argv) {
  using namespace costar;
  // Every robot in format costar-robot-description/1 (a "format" field), by listing robots/.
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::directory_iterator(dataRoot() / "robots")) {
    const std::filesystem::path file = entry.path() / (entry.path().filename().string() + ".json");
    if (entry.is_directory() && std::filesystem::is_regular_file(file)) {
      files.push_back(file);
    }
  }
  std::sort(files.begin(), files.end());
  static std::vector<bench::Workload> workloads;
  workloads.reserve(files.size());
  for (const auto& file : files) {
    try {
      workloads.push_back(bench::makeWorkload(file));
    } catch (const std::exception& error) {
      std::cerr << "skipping " << file.string() << ": " << error.what() << "\n";
    }
  }
  for (const bench::Workload& work : workloads) {
    const std::string name = work.robot.name;
    benchmark::RegisterBenchmark(("BM_Chain/" + name + "/random_seed").c_str(),
                                 [&work](benchmark::State& state) { bench::chainSolves(state, work, false); })
        ->MeasureProcessCPUTime()
        ->MinTime(1.0);
    benchmark::RegisterBenchmark(("BM_Chain/" + name + "/tracking").c_str(),
                                 [&work](benchmark::State& state) { bench::chainSolves(state, work, true); })
        ->MeasureProcessCPUTime()
        ->MinTime(1.0);
    const std::filesystem::path urdf = std::filesystem::path(COSTAR_GENERATED_DIR) / "robots" / name / (name + ".urdf");
    benchmark::RegisterBenchmark(("BM_KdlLma10Restarts/" + name + "/random_seed").c_str(),
                                 [&work, urdf](benchmark::State& state) { bench::kdlSolves(state, work, urdf); })
        ->MeasureProcessCPUTime()
        ->Iterations(1024)
        ->Unit(benchmark::kMicrosecond);
  }
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
