// The 3-finger adaptive gripper on its test bench (sim/gripper_bench.h): the physics' real-time
// factor with the gripper holding a part, and one whole pick (SetMode, approach, Close, lift,
// hold 2 s) per iteration, with the simulated Close time as a counter. Figures:
// docs/BENCHMARKS.md, section "3-finger adaptive gripper".

#include <benchmark/benchmark.h>

#include "core/paths.h"
#include "sim/gripper_bench.h"
#include "smartmove/grasps.h"

namespace costar::bench {
namespace {

/// One simulated second per iteration with the node squeezed in Basic mode, lifted.
void BM_GripperPhysicsHolding(benchmark::State& state) {
  sim::GripperBenchOptions options;
  auto bench = sim::GripperBench::create(options);
  const double grasp_z = bench->partRestHeight() + bench->gripper().tcp.z();
  bench->moveFlange(Eigen::Vector3d(0, 0, grasp_z), 0.0, 0.3);
  bench->stepTo(bench->time() + std::chrono::seconds(2));
  bench->driver().commandFingers({1.0, 1.0, 1.0}, 0.8, 40.0);
  bench->stepTo(bench->time() + std::chrono::seconds(2));
  bench->moveFlange(Eigen::Vector3d(0, 0, grasp_z + 0.05), 0.0, 0.05);
  bench->stepTo(bench->time() + std::chrono::seconds(2));
  for (auto _ : state) {
    bench->stepTo(bench->time() + std::chrono::seconds(1));
  }
  state.counters["realtime_factor"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["lifted_mm"] = (bench->partPose().translation().z() - bench->partRestHeight()) * 1000;
}
BENCHMARK(BM_GripperPhysicsHolding)->Unit(benchmark::kMillisecond);

/// One whole pick per iteration: mode (0 basic, 1 pinch, 2 wide, 3 scissor) x part (0 node, 1 link).
void BM_GripperPick(benchmark::State& state) {
  const auto mode = gripper::kGripperModes[static_cast<std::size_t>(state.range(0))];
  const std::string part = state.range(1) == 0 ? "node" : "link";
  const smartmove::GraspLibrary grasps(dataRoot() / "data/grasps.json", {}, smartmove::kAdaptiveGripper);
  sim::GripperTrialOptions options;
  options.bench.part_class = part;
  options.mode = mode;
  options.tcp_in_part = grasps.find(part, std::string(gripper::toString(mode)))->tcp_in_object;
  double close_seconds = 0.0;
  double simulated = 0.0;
  int successes = 0;
  for (auto _ : state) {
    const sim::GripperTrialResult result = sim::runGripperTrial(options);
    close_seconds += result.close_seconds;
    simulated += result.simulated_seconds;
    successes += result.success ? 1 : 0;
  }
  const auto n = static_cast<double>(state.iterations());
  state.SetLabel(part + " " + std::string(gripper::toString(mode)));
  state.counters["close_s"] = close_seconds / n;
  state.counters["simulated_s"] = simulated / n;
  state.counters["success"] = successes / n;
  state.counters["realtime_factor"] = benchmark::Counter(simulated, benchmark::Counter::kIsRate);
}
BENCHMARK(BM_GripperPick)->ArgsProduct({{0, 1, 2, 3}, {0, 1}})->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace costar::bench

BENCHMARK_MAIN();
