// Perception benchmarks (docs/BENCHMARKS.md, "Perception"): DetectObjects on one 640 x 480
// frame set of 15 frames with 6 parts (4 nodes, 2 links, two of them touching), stage by stage
// and whole; persistenceUpdate against brute-force matching; setCanonicalOrientation.
// Run from the repository root: build/bench/perception_bench

#include <benchmark/benchmark.h>

#include <algorithm>
#include <ctime>
#include <memory>
#include <random>
#include <vector>

#include "core/paths.h"
#include "perception/canonical_orientation.h"
#include "perception/features.h"
#include "perception/median_filter.h"
#include "perception/perception_component.h"
#include "perception/persistence.h"
#include "perception/pipeline.h"
#include "perception/segmentation.h"
#include "perception/workspace.h"
#include "sim/simulation.h"

namespace {

using namespace costar;
using namespace costar::perception;

/// The frames and the pipeline, made once.
struct Fixture {
  std::vector<camera::RgbdFrame> frames;
  std::shared_ptr<Pipeline> pipeline;

  static Fixture& get() {
    static Fixture fixture;
    return fixture;
  }

 private:
  Fixture() {
    pipeline = loadPipeline(PerceptionConfig{});
    const sim::Scene scene = sim::parseScene(R"({"seed": 5, "parts": [
        {"class": "node", "color": "red", "at": [0.42, -0.22, 15]},
        {"class": "node", "color": "green", "at": [0.40693, -0.17122, 15]},
        {"class": "node", "color": "blue", "at": [0.62, 0.05, -40]},
        {"class": "node", "color": "yellow", "at": [0.35, 0.25, 70]},
        {"class": "link", "color": "wood", "at": [0.55, -0.25, 100]},
        {"class": "link", "color": "grey", "at": [0.5, 0.2, 30]}]})",
                                             "perception benchmark");
    auto simulation = sim::Simulation::create(scene);
    for (int i = 0; i < 15; ++i) {
      simulation->stepTo(simulation->time() + std::chrono::nanoseconds(33'333'333));
      frames.push_back(simulation->captureRgbd(100 + static_cast<std::uint64_t>(i)));
    }
  }
};

/// CPU seconds of the whole process (every thread) so far.
double processCpuSeconds() {
  timespec now{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &now);
  return static_cast<double>(now.tv_sec) + 1e-9 * static_cast<double>(now.tv_nsec);
}

void BM_DetectObjects(benchmark::State& state) {
  Fixture& f = Fixture::get();
  std::size_t found = 0;
  PipelineResult last;
  StageTimes sum;
  int runs = 0;
  // CPU time of all threads per detection: on a machine other work loads, the wall time measures
  // the load; run with OMP_WAIT_POLICY=passive so that OpenMP's idle threads do not spin it up.
  std::vector<double> cpu;
  for (auto _ : state) {
    const double cpu_start = processCpuSeconds();
    const PipelineResult result = f.pipeline->detect(f.frames);
    cpu.push_back(processCpuSeconds() - cpu_start);
    found = result.detections.size();
    benchmark::DoNotOptimize(found);
    const StageTimes& t = result.times;
    sum.median += t.median;
    sum.crop += t.crop;
    sum.normals += t.normals;
    sum.features += t.features;
    sum.classification += t.classification;
    sum.pose += t.pose;
    sum.recognition += t.recognition;
    sum.refinement += t.refinement;
    ++runs;
    last = result;
  }
  std::sort(cpu.begin(), cpu.end());
  state.counters["cpu_ms_median"] = cpu.empty() ? 0.0 : 1000.0 * cpu[cpu.size() / 2];
  state.counters["objects"] = static_cast<double>(found);
  state.counters["clusters"] = last.pose_clusters;
  state.counters["orr_runs"] = last.pose_runs;
  state.counters["hypotheses"] = last.pose_candidates;
  state.counters["checked"] = last.pose_checked;
  state.counters["points"] = last.workspace_points;
  // Mean stage times (ms) over the runs.
  const auto ms = [runs](double seconds) { return 1000.0 * seconds / std::max(1, runs); };
  state.counters["1_median"] = ms(sum.median);
  state.counters["2_crop"] = ms(sum.crop);
  state.counters["3a_normals"] = ms(sum.normals);
  state.counters["3b_features"] = ms(sum.features);
  state.counters["3c_svm"] = ms(sum.classification);
  state.counters["4_pose"] = ms(sum.pose);
  state.counters["4_orr_cpu"] = ms(sum.recognition);
  state.counters["4_icp_cpu"] = ms(sum.refinement);
}
BENCHMARK(BM_DetectObjects)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_Stage1_MedianFilter15(benchmark::State& state) {
  Fixture& f = Fixture::get();
  const PixelRect region =
      workspaceRegion(f.frames.back().intrinsics, f.frames.back().camera_pose, f.pipeline->options().workspace);
  for (auto _ : state) {
    benchmark::DoNotOptimize(medianFrame(f.frames, region, static_cast<int>(state.range(0))));
  }
}
BENCHMARK(BM_Stage1_MedianFilter15)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_Stage2_Crop(benchmark::State& state) {
  Fixture& f = Fixture::get();
  const camera::RgbdFrame median = medianFrame(f.frames);
  for (auto _ : state) {
    benchmark::DoNotOptimize(cropWorkspace(median, f.pipeline->options().workspace));
  }
}
BENCHMARK(BM_Stage2_Crop)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_Stage3_NormalsFeaturesSvm(benchmark::State& state) {
  Fixture& f = Fixture::get();
  const camera::RgbdFrame median = medianFrame(f.frames);
  const WorkspaceCloud workspace = cropWorkspace(median, f.pipeline->options().workspace);
  for (auto _ : state) {
    WorkspaceCloud copy = workspace;
    estimateNormals(median, copy.cloud);
    benchmark::DoNotOptimize(segmentPoints(copy.cloud, f.pipeline->classifier(), f.pipeline->options().segmentation));
  }
  state.counters["points"] = static_cast<double>(workspace.cloud.size());
}
BENCHMARK(BM_Stage3_NormalsFeaturesSvm)->Unit(benchmark::kMillisecond)->UseRealTime();

/// The classifier alone: the SVM's decision for every voxel of the benchmark's frame.
void BM_Stage3c_SvmPredict(benchmark::State& state) {
  Fixture& f = Fixture::get();
  const camera::RgbdFrame median = medianFrame(f.frames);
  WorkspaceCloud workspace = cropWorkspace(median, f.pipeline->options().workspace);
  estimateNormals(median, workspace.cloud);
  const VoxelFeatures voxels = computeFeatures(workspace.cloud, f.pipeline->options().segmentation.features);
  for (auto _ : state) {
    benchmark::DoNotOptimize(f.pipeline->classifier().predict(voxels.features));
  }
  state.counters["voxels"] = static_cast<double>(voxels.features.rows());
  state.counters["support_vectors"] = static_cast<double>(f.pipeline->classifier().supportVectorCount());
}
BENCHMARK(BM_Stage3c_SvmPredict)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_Stages2to4_DetectFiltered(benchmark::State& state) {
  Fixture& f = Fixture::get();
  const camera::RgbdFrame median = medianFrame(f.frames);
  for (auto _ : state) {
    benchmark::DoNotOptimize(f.pipeline->detectFiltered(median));
  }
}
BENCHMARK(BM_Stages2to4_DetectFiltered)->Unit(benchmark::kMillisecond)->UseRealTime();

// --- persistenceUpdate --------------------------------------------------------------------------

std::vector<world::ObjectClass> benchmarkClasses() { return world::loadObjectClasses(dataRoot() / "data/objects"); }

/// n objects on a grid 10 cm apart (two classes), then the same objects moved by up to 1 cm.
std::pair<std::vector<Detection>, std::vector<Detection>> scatter(int n) {
  std::mt19937 random(1);
  std::uniform_real_distribution<double> jitter(-0.007, 0.007);
  std::vector<Detection> before;
  const int side = static_cast<int>(std::ceil(std::sqrt(n)));
  for (int i = 0; i < n; ++i) {
    Detection d;
    d.object_class = i % 3 == 0 ? "link" : "node";
    d.pose = world::poseFromXyzRpy(0.1 * (i % side), 0.1 * (i / side), 0.025, 0, 0, 0.01 * i);
    before.push_back(d);
  }
  std::vector<Detection> after = before;
  for (auto& d : after) {
    d.pose.translation() += Eigen::Vector3d(jitter(random), jitter(random), 0);
  }
  std::shuffle(after.begin(), after.end(), random);
  return {before, after};
}

void BM_PersistenceUpdate(benchmark::State& state) {
  const auto [before, after] = scatter(static_cast<int>(state.range(0)));
  PersistenceFilter filter(benchmarkClasses());
  filter.update(before);
  bool flip = false;
  for (auto _ : state) {
    benchmark::DoNotOptimize(filter.update(flip ? before : after).size());
    flip = !flip;
  }
  state.SetComplexityN(state.range(0));
}
// Wall time: from 2,048 detections the update uses two threads ("CPU" is the calling thread's).
BENCHMARK(BM_PersistenceUpdate)
    ->RangeMultiplier(10)
    ->Range(10, 10000)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Complexity(benchmark::oNLogN);
BENCHMARK(BM_PersistenceUpdate)->Arg(10000)->Unit(benchmark::kMillisecond)->UseRealTime()->MeasureProcessCPUTime();

/// The reference: each detection against every previous object of its class, one match each.
void BM_PersistenceBruteForce(benchmark::State& state) {
  const auto [before, after] = scatter(static_cast<int>(state.range(0)));
  for (auto _ : state) {
    std::vector<bool> taken(before.size(), false);
    int matched = 0;
    for (const auto& d : after) {
      double best = 0.03 * 0.03;
      int which = -1;
      for (std::size_t p = 0; p < before.size(); ++p) {
        if (!taken[p] && before[p].object_class == d.object_class) {
          const double squared = (before[p].pose.translation() - d.pose.translation()).squaredNorm();
          if (squared < best) {
            best = squared;
            which = static_cast<int>(p);
          }
        }
      }
      if (which >= 0) {
        taken[static_cast<std::size_t>(which)] = true;
        ++matched;
      }
    }
    benchmark::DoNotOptimize(matched);
  }
}
BENCHMARK(BM_PersistenceBruteForce)->RangeMultiplier(10)->Range(10, 10000)->Unit(benchmark::kMillisecond);

void BM_CanonicalOrientationNode(benchmark::State& state) {
  const auto classes = benchmarkClasses();
  const world::ObjectClass& node = classes[1].name == "node" ? classes[1] : classes[0];
  world::Pose pose = world::poseFromXyzRpy(0.5, 0, 0.025, 0.01, 0.02, 0.7);
  for (auto _ : state) {
    benchmark::DoNotOptimize(setCanonicalOrientation(pose, node));
  }
}
BENCHMARK(BM_CanonicalOrientationNode);

}  // namespace

BENCHMARK_MAIN();
