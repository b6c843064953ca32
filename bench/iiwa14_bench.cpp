// LBR iiwa 14 inverse kinematics: the analytic arm-angle solver of costar_arm (SrsKinematics)
// against KDL's Levenberg-Marquardt solver (ChainIkSolverPos_LMA, through planning::RobotModel on
// the URDF generated from robots/iiwa14/iiwa14.json), on the same random reachable poses, in the
// same run. Run from the repository root: build/bench/iiwa14_bench
//
// Poses: the flange poses of 4,096 configurations drawn uniformly within the joint limits
// (seed 20260, not a seed the tests use), so every pose is reachable within limits.
// Counters: solves_per_s; solved (the fraction of poses for which the solver returned a
// configuration within limits that reaches the pose within 1e-6 m and 1e-6 rad, checked after
// timing, each pose at least once; KDL's within 1e-4 m and 1e-3 rad, see BM_Iiwa14KdlLma);
// allocations_per_solve for the analytic solver.

#include <benchmark/benchmark.h>

#include <numbers>
#include <optional>
#include <random>
#include <vector>

#include "arm/robot_description.h"
#include "arm/srs_kinematics.h"
#include "bench/alloc_counter.h"
#include "planning/robot_model.h"

namespace costar::bench {
namespace {

using arm::Joints7;
using arm::SrsKinematics;
using arm::SrsLimits;

/// The iiwa 14 as robots/iiwa14/iiwa14.json describes it.
const arm::SrsArmDescription& iiwa14() {
  static const arm::SrsArmDescription description = arm::readSrsArmDescription(arm::robotDescriptionFile("iiwa14"));
  return description;
}

constexpr int kPoseCount = 4096;

Joints7 home() {
  Joints7 q;
  q << 0, 30, 0, -80, 0, 70, 0;
  return q * std::numbers::pi / 180.0;
}

struct Workload {
  std::vector<Joints7> configurations;
  std::vector<world::Pose> poses;
  std::vector<Joints7> nudged;  // each configuration moved by up to 0.05 rad per joint
};

const Workload& workload() {
  static const Workload work = [] {
    const SrsKinematics kinematics(iiwa14().geometry);
    const SrsLimits limits = iiwa14().limits;
    std::mt19937_64 random(20260);
    std::uniform_real_distribution<double> nudge(-0.05, 0.05);
    Workload result;
    for (int k = 0; k < kPoseCount; ++k) {
      Joints7 q;
      for (int i = 0; i < 7; ++i) {
        q[i] = std::uniform_real_distribution<double>(limits.lower[i], limits.upper[i])(random);
      }
      result.configurations.push_back(q);
      result.poses.push_back(kinematics.forward(q));
      Joints7 seed = q;
      for (int i = 0; i < 7; ++i) {
        seed[i] = std::clamp(seed[i] + nudge(random), limits.lower[i], limits.upper[i]);
      }
      result.nudged.push_back(seed);
    }
    return result;
  }();
  return work;
}

/// The fraction of poses whose last answer is within limits and reaches the pose within
/// `position_tolerance` (m) and `angle_tolerance` (rad).
double solvedFraction(const std::vector<std::optional<Joints7>>& answers, std::int64_t iterations,
                      double position_tolerance = 1e-6, double angle_tolerance = 1e-6) {
  const SrsKinematics kinematics(iiwa14().geometry);
  const SrsLimits limits = iiwa14().limits;
  const Workload& work = workload();
  const std::size_t visited = std::min<std::size_t>(answers.size(), static_cast<std::size_t>(iterations));
  std::size_t solved = 0;
  for (std::size_t k = 0; k < visited; ++k) {
    if (answers[k] && limits.contains(*answers[k])) {
      const world::Pose reached = kinematics.forward(*answers[k]);
      solved += (reached.translation() - work.poses[k].translation()).norm() < position_tolerance &&
                world::rotationAngle(reached, work.poses[k]) < angle_tolerance;
    }
  }
  return static_cast<double>(solved) / static_cast<double>(visited);
}

// The analytic solver from one fixed seed (home) for every pose: most poses are far from the
// seed, so this is the full search over the 8 branches and their feasible arm angles.
void BM_Iiwa14AnalyticNearestFromHome(benchmark::State& state) {
  const SrsKinematics kinematics(iiwa14().geometry);
  const SrsLimits limits = iiwa14().limits;
  const Workload& work = workload();
  const Joints7 seed = home();
  std::vector<std::optional<Joints7>> answers(work.poses.size());
  std::size_t next = 0;
  const std::uint64_t allocations_before = allocations();
  for (auto _ : state) {
    answers[next] = kinematics.inverseNearest(work.poses[next], seed, limits);
    benchmark::DoNotOptimize(answers[next]);
    next = (next + 1) % work.poses.size();
  }
  const double solves = static_cast<double>(state.iterations());
  state.counters["solves_per_s"] = benchmark::Counter(solves, benchmark::Counter::kIsRate);
  state.counters["allocations_per_solve"] = static_cast<double>(allocations() - allocations_before) / solves;
  state.counters["solved"] = solvedFraction(answers, state.iterations());
}
BENCHMARK(BM_Iiwa14AnalyticNearestFromHome)->MinTime(1.0);

// The usual call in a Cartesian move: the seed is the current configuration, near the answer.
void BM_Iiwa14AnalyticNearestTracking(benchmark::State& state) {
  const SrsKinematics kinematics(iiwa14().geometry);
  const SrsLimits limits = iiwa14().limits;
  const Workload& work = workload();
  std::vector<std::optional<Joints7>> answers(work.poses.size());
  std::size_t next = 0;
  const std::uint64_t allocations_before = allocations();
  for (auto _ : state) {
    answers[next] = kinematics.inverseNearest(work.poses[next], work.nudged[next], limits);
    benchmark::DoNotOptimize(answers[next]);
    next = (next + 1) % work.poses.size();
  }
  const double solves = static_cast<double>(state.iterations());
  state.counters["solves_per_s"] = benchmark::Counter(solves, benchmark::Counter::kIsRate);
  state.counters["allocations_per_solve"] = static_cast<double>(allocations() - allocations_before) / solves;
  state.counters["solved"] = solvedFraction(answers, state.iterations());
}
BENCHMARK(BM_Iiwa14AnalyticNearestTracking)->MinTime(1.0);

// All (up to 8) closed-form solutions at one arm angle, limits not applied.
void BM_Iiwa14AnalyticAllAtArmAngle(benchmark::State& state) {
  const SrsKinematics kinematics(iiwa14().geometry);
  const Workload& work = workload();
  std::array<Joints7, SrsKinematics::kMaxSolutions> solutions;
  std::size_t next = 0;
  std::int64_t count = 0;
  for (auto _ : state) {
    count += kinematics.inverse(work.poses[next], 0.3, solutions);
    benchmark::DoNotOptimize(solutions);
    next = (next + 1) % work.poses.size();
  }
  const double solves = static_cast<double>(state.iterations());
  state.counters["solves_per_s"] = benchmark::Counter(solves, benchmark::Counter::kIsRate);
  state.counters["solutions_per_pose"] = static_cast<double>(count) / solves;
}
BENCHMARK(BM_Iiwa14AnalyticAllAtArmAngle)->MinTime(1.0);

// KDL's LMA (planning::RobotModel: eps 1e-6, at most 500 iterations, answers within the joint
// limits only), started from home; arg 0 = one try, arg 10 = then up to 10 random restarts.
void BM_Iiwa14KdlLma(benchmark::State& state) {
  const planning::RobotModel model = planning::RobotModel::fromUrdf(COSTAR_IIWA14_URDF, "iiwa_link_0", "tool0");
  const int restarts = static_cast<int>(state.range(0));
  const Workload& work = workload();
  const Eigen::VectorXd seed = home();
  std::vector<std::optional<Joints7>> answers(work.poses.size());
  std::size_t next = 0;
  for (auto _ : state) {
    const std::optional<Eigen::VectorXd> q = model.inverse(work.poses[next], seed, restarts, next);
    answers[next] = q ? std::optional<Joints7>(Joints7(*q)) : std::nullopt;
    next = (next + 1) % work.poses.size();
  }
  state.counters["solves_per_s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  // KDL stops at an error of 1e-6 (its own norm): counted as solved within 1e-4 m and 1e-3 rad,
  // as bench/arm_bench.cpp does for the UR5.
  state.counters["solved"] = solvedFraction(answers, state.iterations(), 1e-4, 1e-3);
}
BENCHMARK(BM_Iiwa14KdlLma)->Arg(0)->Iterations(kPoseCount)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Iiwa14KdlLma)->Arg(10)->Iterations(1024)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace costar::bench

BENCHMARK_MAIN();
