// Predicator cost as the number of objects grows (10 -> 1,000): an update when one object
// moved (should grow ~linearly in N through bookkeeping, not N^2), a full update (every object
// moved), an on-demand relation, and a query. Figures: docs/BENCHMARKS.md.

#include <benchmark/benchmark.h>

#include "core/paths.h"
#include "predicator/predicator.h"

namespace costar::bench {
namespace {

struct Scene {
  explicit Scene(int count) : predicator(world, world::loadObjectClasses(dataRoot() / "data/objects")) {
    world.update(
        "workcell",
        {{world::Symbol{
             "table_center", "", {}, world::FrameValue{"world", world::Pose(Eigen::Translation3d(0.5, 0, 0))}}},
         {}});
    // Objects on a 12 cm grid (constant density: the area grows with N), nodes and links.
    const int side = static_cast<int>(std::ceil(std::sqrt(count)));
    for (int i = 0; i < count; ++i) {
      positions.emplace_back(0.12 * (i % side), 0.12 * (i / side) - 0.06 * side, 0.025);
    }
    publish();
  }
  void publish() {
    world::Report report;
    for (std::size_t i = 0; i < positions.size(); ++i) {
      const std::string name = (i % 4 == 3 ? "link_" : "node_") + std::to_string(i);
      report.symbols.push_back(
          {name, "", {}, world::FrameValue{"world", world::Pose(Eigen::Translation3d(positions[i]))}});
      report.predicates.push_back({"is_a", {name, i % 4 == 3 ? "link" : "node"}, true, ""});
    }
    world.update("perception", std::move(report));
  }
  world::WorldState world;
  predicator::Predicator predicator;
  std::vector<Eigen::Vector3d> positions;
};

void BM_UpdateOneMoved(benchmark::State& state) {
  Scene scene(static_cast<int>(state.range(0)));
  scene.world.update("predicator", scene.predicator.report());
  std::size_t i = 0;
  for (auto _ : state) {
    state.PauseTiming();
    scene.positions[i++ % scene.positions.size()].x() += 0.001;
    scene.publish();
    state.ResumeTiming();
    scene.world.update("predicator", scene.predicator.report());
  }
  state.counters["relations_recomputed"] = static_cast<double>(scene.predicator.lastRecomputed());
}
BENCHMARK(BM_UpdateOneMoved)->Arg(10)->Arg(100)->Arg(1000)->Unit(benchmark::kMicrosecond);

void BM_UpdateAllMoved(benchmark::State& state) {
  Scene scene(static_cast<int>(state.range(0)));
  for (auto _ : state) {
    state.PauseTiming();
    for (auto& p : scene.positions) {
      p.x() += 0.001;
    }
    scene.publish();
    state.ResumeTiming();
    scene.world.update("predicator", scene.predicator.report());
  }
}
BENCHMARK(BM_UpdateAllMoved)->Arg(10)->Arg(100)->Arg(1000)->Unit(benchmark::kMicrosecond);

void BM_OnDemandRelation(benchmark::State& state) {
  Scene scene(static_cast<int>(state.range(0)));
  scene.world.update("predicator", scene.predicator.report());
  const std::vector<std::string> args{"node_0", "node_1"};
  for (auto _ : state) {
    benchmark::DoNotOptimize(scene.world.holds("left_of", args));
  }
}
BENCHMARK(BM_OnDemandRelation)->Arg(10)->Arg(1000);

void BM_QueryNodesRightOfCenter(benchmark::State& state) {
  Scene scene(static_cast<int>(state.range(0)));
  scene.world.update("predicator", scene.predicator.report());
  for (auto _ : state) {
    benchmark::DoNotOptimize(scene.predicator.match({{"is_a", {"?", "node"}}, {"right_of", {"?", "table_center"}}}));
  }
}
BENCHMARK(BM_QueryNodesRightOfCenter)->Arg(10)->Arg(100)->Arg(1000)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace costar::bench

BENCHMARK_MAIN();
