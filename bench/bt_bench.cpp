// Engine overhead: ns per node tick on reference trees, and heap allocations per run in
// steady state (target: none). Figures and commands: docs/BENCHMARKS.md.

#include <benchmark/benchmark.h>

#include "bench/alloc_counter.h"
#include "bench/reference_trees.h"
#include "bt/builder.h"
#include "bt/plan_xml.h"

namespace costar::bench {
namespace {

using bt::Status;

/// Runs the tree to completion `state.iterations()` times; reports ns per node tick and
/// allocations per run (after one warm-up run).
void runToCompletion(benchmark::State& state, const bt::Plan& plan, bt::TreeObserver* observer = nullptr,
                     Duration advance_per_tick = Duration(0)) {
  SimClock clock;
  bt::Tree tree = bt::buildTree(plan, bt::builtinRegistry(), clock);
  if (observer != nullptr) {
    tree.addObserver(observer);
  }
  const auto run_once = [&] {
    while (tree.tick() == Status::kRunning) {
      if (!tree.context().takeImmediateTickRequest()) {
        clock.advanceBy(advance_per_tick);
      }
    }
  };
  run_once();  // warm-up: strings and buffers reach their steady size
  const std::uint64_t ticks_before = tree.context().nodeTicks();
  const std::uint64_t allocations_before = allocations();
  for (auto _ : state) {
    run_once();
  }
  const double node_ticks = static_cast<double>(tree.context().nodeTicks() - ticks_before);
  const double runs = static_cast<double>(state.iterations());
  state.counters["node_ticks_per_run"] = node_ticks / runs;
  state.counters["time_per_node_tick"] =
      benchmark::Counter(node_ticks, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  state.counters["allocs_per_run"] = static_cast<double>(allocations() - allocations_before) / runs;
}

void BM_Mixed1000Leaves(benchmark::State& state) { runToCompletion(state, mixedTree1000()); }
BENCHMARK(BM_Mixed1000Leaves);

void BM_Deep100Levels(benchmark::State& state) { runToCompletion(state, deepTree100()); }
BENCHMARK(BM_Deep100Levels);

void BM_WideParallel1000(benchmark::State& state) { runToCompletion(state, wideParallel1000(false)); }
BENCHMARK(BM_WideParallel1000);

/// 1,000 children RUNNING for 5 ticks of 10 ms, then succeeding.
void BM_WideParallel1000Running(benchmark::State& state) {
  runToCompletion(state, wideParallel1000(true), nullptr, std::chrono::milliseconds(10));
}
BENCHMARK(BM_WideParallel1000Running);

/// The mixed tree with an observer that does nothing: the cost of reporting transitions.
class NullObserver final : public bt::TreeObserver {
 public:
  void onTransition(TimePoint, const bt::TreeNode&, Status, Status) override { benchmark::ClobberMemory(); }
};

void BM_Mixed1000LeavesObserved(benchmark::State& state) {
  NullObserver observer;
  runToCompletion(state, mixedTree1000(), &observer);
}
BENCHMARK(BM_Mixed1000LeavesObserved);

/// Parse, validate and instantiate the reference plan file (a one-off cost per run).
void BM_LoadReferencePlan(benchmark::State& state) {
  const bt::NodeRegistry registry = bt::builtinRegistry();
  SimClock clock;
  for (auto _ : state) {
    bt::Tree tree = bt::buildTree(bt::loadPlan("bench/plans/reference_1000_leaves.xml"), registry, clock);
    benchmark::DoNotOptimize(tree.nodes().size());
  }
}
BENCHMARK(BM_LoadReferencePlan)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace costar::bench

BENCHMARK_MAIN();
