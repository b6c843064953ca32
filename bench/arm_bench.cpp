// UR5 inverse kinematics: the closed form of costar_arm against KDL's Levenberg-Marquardt
// solver (ChainIkSolverPos_LMA) on the same random reachable poses, in the same run.
// Run from the repository root: build/bench/arm_bench
//
// Counters: solves_per_s (poses solved per second); for the closed form, solutions_per_pose
// and allocations_per_solve; for KDL, first_try_success (the solver, started once from a fixed
// seed, reports convergence and the result reaches the pose within 1e-4 m and 1e-3 rad) and
// converged (the solver's own verdict alone).

#include <benchmark/benchmark.h>

#include <filesystem>
#include <kdl/chain.hpp>
#include <kdl/chainiksolverpos_lma.hpp>
#include <kdl/frames.hpp>
#include <kdl/jntarray.hpp>
#include <kdl/segment.hpp>
#include <numbers>
#include <random>
#include <vector>

#include "arm/chain_kinematics.h"
#include "arm/robot_description.h"
#include "arm/ur5_kinematics.h"
#include "bench/alloc_counter.h"

namespace costar::bench {
namespace {

/// The UR5's joints.
constexpr int kJointCount = arm::Ur5Kinematics::kJointCount;

using arm::JointVector;
using arm::Ur5Kinematics;

constexpr int kPoseCount = 4096;

/// The UR5 as robots/ur5/ur5.json describes it.
const Ur5Kinematics& ur5() {
  static const Ur5Kinematics kinematics = [] {
    const std::filesystem::path file = arm::robotDescriptionFile("ur5");
    return Ur5Kinematics(arm::dhParametersOf(arm::readChainGeometry(file)), arm::loadRobotDescription(file).limits);
  }();
  return kinematics;
}

/// Poses reached by random joint configurations (uniform in (-pi, pi], fixed seed): every one
/// is reachable.
const std::vector<world::Pose>& randomReachablePoses() {
  static const std::vector<world::Pose> poses = [] {
    const Ur5Kinematics& kinematics = ur5();
    std::mt19937_64 random(20170529);
    std::uniform_real_distribution<double> angle(-std::numbers::pi, std::numbers::pi);
    std::vector<world::Pose> result;
    for (int k = 0; k < kPoseCount; ++k) {
      JointVector q = JointVector::zero(kJointCount);
      for (double& value : q) {
        value = angle(random);
      }
      result.push_back(kinematics.forward(q));
    }
    return result;
  }();
  return poses;
}

void BM_Ur5ClosedFormInverse(benchmark::State& state) {
  const Ur5Kinematics& kinematics = ur5();
  const std::vector<world::Pose>& poses = randomReachablePoses();
  std::array<JointVector, Ur5Kinematics::kMaxSolutions> solutions;
  std::size_t next = 0;
  std::int64_t solution_count = 0;
  const std::uint64_t allocations_before = allocations();
  for (auto _ : state) {
    const int count = kinematics.inverse(poses[next], solutions);
    benchmark::DoNotOptimize(solutions);
    solution_count += count;
    next = (next + 1) % poses.size();
  }
  const double solves = static_cast<double>(state.iterations());
  state.counters["solves_per_s"] = benchmark::Counter(solves, benchmark::Counter::kIsRate);
  state.counters["solutions_per_pose"] = static_cast<double>(solution_count) / solves;
  state.counters["allocations_per_solve"] = static_cast<double>(allocations() - allocations_before) / solves;
}
BENCHMARK(BM_Ur5ClosedFormInverse);

void BM_Ur5ClosedFormInverseNearest(benchmark::State& state) {
  // The usual call in a Cartesian move: the solution nearest the current joint angles, within
  // the UR5's limits, through the Kinematics interface (as the arm and SmartMove call it).
  // Seeds are the generating configurations, nudged.
  const Ur5Kinematics& kinematics = ur5();
  const arm::Kinematics& generic = kinematics;
  const std::vector<world::Pose>& poses = randomReachablePoses();
  std::vector<JointVector> seeds;
  std::mt19937_64 random(7);
  std::uniform_real_distribution<double> nudge(-0.05, 0.05);
  for (const world::Pose& pose : poses) {
    JointVector seed = kinematics.inverse(pose).front();
    for (double& value : seed) {
      value += nudge(random);
    }
    seeds.push_back(seed);
  }
  std::size_t next = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(generic.inverseNearest(poses[next], seeds[next]));
    next = (next + 1) % poses.size();
  }
  state.counters["solves_per_s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_Ur5ClosedFormInverseNearest);

KDL::Chain ur5Chain(const arm::DhParameters& dh) {
  KDL::Chain chain;
  for (int i = 0; i < kJointCount; ++i) {
    chain.addSegment(KDL::Segment(KDL::Joint(KDL::Joint::RotZ), KDL::Frame::DH(dh.a[i], dh.alpha[i], dh.d[i], 0.0)));
  }
  return chain;
}

KDL::Frame toKdl(const world::Pose& pose) {
  const Eigen::Matrix3d& r = pose.linear();
  const Eigen::Vector3d& p = pose.translation();
  return KDL::Frame(KDL::Rotation(r(0, 0), r(0, 1), r(0, 2), r(1, 0), r(1, 1), r(1, 2), r(2, 0), r(2, 1), r(2, 2)),
                    KDL::Vector(p.x(), p.y(), p.z()));
}

void BM_KdlLmaInverse(benchmark::State& state) {
  const Ur5Kinematics& kinematics = ur5();
  const KDL::Chain chain = ur5Chain(kinematics.parameters());
  KDL::ChainIkSolverPos_LMA solver(chain);  // KDL's defaults: eps 1e-5, 500 iterations
  const std::vector<world::Pose>& poses = randomReachablePoses();
  std::vector<KDL::Frame> targets;
  for (const world::Pose& pose : poses) {
    targets.push_back(toKdl(pose));
  }
  // Every solve starts from the same seed, a common "ready" configuration of the UR5.
  KDL::JntArray seed(kJointCount);
  const double ready[kJointCount] = {
      0.0, -std::numbers::pi / 2, std::numbers::pi / 2, -std::numbers::pi / 2, -std::numbers::pi / 2, 0.0};
  for (int j = 0; j < kJointCount; ++j) {
    seed(j) = ready[j];
  }
  KDL::JntArray result(kJointCount);
  std::vector<int> statuses(poses.size(), 0);
  std::vector<JointVector> answers(poses.size(), JointVector::zero(kJointCount));
  std::size_t next = 0;
  for (auto _ : state) {
    statuses[next] = solver.CartToJnt(seed, targets[next], result);
    for (int j = 0; j < kJointCount; ++j) {
      answers[next][j] = result(j);
    }
    next = (next + 1) % poses.size();
  }
  // Checked after timing: the last answer for each pose solved.
  const std::size_t solved = std::min<std::size_t>(poses.size(), static_cast<std::size_t>(state.iterations()));
  std::int64_t converged = 0;
  std::int64_t successes = 0;
  for (std::size_t k = 0; k < solved; ++k) {
    if (statuses[k] >= 0) {
      ++converged;
      const world::Pose reached = kinematics.forward(answers[k]);
      const double position_error = (reached.translation() - poses[k].translation()).norm();
      const double rotation_error = world::rotationAngle(reached, poses[k]);
      successes += position_error < 1e-4 && rotation_error < 1e-3;
    }
  }
  state.counters["solves_per_s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["first_try_success"] = static_cast<double>(successes) / static_cast<double>(solved);
  state.counters["converged"] = static_cast<double>(converged) / static_cast<double>(solved);
}
BENCHMARK(BM_KdlLmaInverse)->Iterations(kPoseCount);  // each pose exactly once

}  // namespace
}  // namespace costar::bench

BENCHMARK_MAIN();
