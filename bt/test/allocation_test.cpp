// The engine's promise: no heap allocation per tick in steady state, whatever the tree does
// (succeed, fail with a reason, run, loop, halt). Counted, not timed.

#include <gtest/gtest.h>

#include "bench/alloc_counter.h"
#include "bench/reference_trees.h"
#include "bt/builder.h"

namespace costar::bt {
namespace {

std::uint64_t allocationsForRuns(const Plan& plan, int runs, Duration advance = Duration(0)) {
  SimClock clock;
  Tree tree = buildTree(plan, builtinRegistry(), clock);
  const auto run_once = [&] {
    while (tree.tick() == Status::kRunning) {
      if (!tree.context().takeImmediateTickRequest()) {
        clock.advanceBy(advance);
      }
    }
  };
  run_once();  // warm-up
  const std::uint64_t before = bench::allocations();
  for (int i = 0; i < runs; ++i) {
    run_once();
  }
  return bench::allocations() - before;
}

TEST(Allocation, NoneInSteadyStateOnTheReferenceTrees) {
  EXPECT_EQ(allocationsForRuns(bench::mixedTree1000(), 20), 0u);
  EXPECT_EQ(allocationsForRuns(bench::deepTree100(), 20), 0u);
  EXPECT_EQ(allocationsForRuns(bench::wideParallel1000(false), 20), 0u);
  EXPECT_EQ(allocationsForRuns(bench::wideParallel1000(true), 5, std::chrono::milliseconds(10)), 0u);
}

TEST(Allocation, NoneWhenHaltingAndRestartingRunningLoops) {
  using bench::node;
  const Plan plan = bench::planOf(
      node("Fallback", {node("Timeout", {node("Repeat", {node("Sleep", {}, {{"msec", "5"}})}, {{"num_cycles", "-1"}})},
                             {{"msec", "30"}}),
                        node("Reset", {node("Inverter", {node("AlwaysSuccess")})}, {{"num_resets", "-1"}})}));
  // The Timeout fails (it composes its reason once, then reuses the string), Reset resets.
  EXPECT_EQ(allocationsForRuns(plan, 20, std::chrono::milliseconds(10)), 0u);
}

TEST(Allocation, NoneInTheNodesAddedFromBehaviorTreeCpp) {
  using bench::node;
  const auto sleep = [] { return node("Sleep", {}, {{"msec", "5"}}); };
  const Plan plan = bench::planOf(node(
      "Sequence", {node("AsyncSequence", {node("AlwaysSuccess"),
                                          node("Delay", {node("AlwaysSuccess")}, {{"delay_msec", "5"}}), sleep()}),
                   node("AsyncFallback", {node("AlwaysFailure"), node("AlwaysSuccess")}),
                   node("ParallelAll", {sleep(), node("AlwaysFailure")}, {{"max_failures", "2"}}),
                   node("IfThenElse", {node("AlwaysFailure"), node("AlwaysFailure"), sleep()}),
                   node("WhileDoElse", {node("AlwaysSuccess"), sleep()}),
                   node("ForceSuccess", {node("TryCatch", {sleep(), node("AlwaysFailure"), sleep()})}),
                   node("ForceSuccess", {node("Timeout", {node("KeepRunningUntilFailure", {node("AlwaysSuccess")})},
                                              {{"msec", "20"}})}),
                   node("RunOnce", {node("AlwaysSuccess")}), node("RunOnce", {sleep()}, {{"then_skip", "false"}})}));
  EXPECT_EQ(allocationsForRuns(plan, 20, std::chrono::milliseconds(5)), 0u);
}

}  // namespace
}  // namespace costar::bt
