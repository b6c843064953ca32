// How fast the simulated workcell runs: real-time factor of the physics (parts settled, arm
// holding or moving), and the cost of one RGB-D frame (render + noise). Target: >= 20x real
// time headless, camera frames included when asked. Figures: docs/BENCHMARKS.md.

#include <benchmark/benchmark.h>

#include <cmath>
#include <string>

#include "arm/robot_description.h"
#include "arm/trajectory.h"
#include "core/paths.h"
#include "sim/simulation.h"
#include "workcell/grippers.h"
#include "workcell/sim_cell_description.h"

namespace costar::bench {
namespace {

std::unique_ptr<sim::Simulation> assembly() {
  return sim::Simulation::create(sim::loadScene(dataRoot() / "sim/scenes/assembly.json"));
}

/// A cell's simulation (workcells/NAME.json: its arm, gripper and cell) with `scene` (default:
/// the cell's, the assembly's).
std::unique_ptr<sim::Simulation> cellAssembly(const std::string& name, const std::string& scene = {}) {
  const workcell::SimCellDescription cell = workcell::loadSimCellDescription(workcell::simCellFile(name));
  const workcell::GripperModel& gripper = workcell::gripperModel(cell.gripper);
  sim::SimulationOptions options;
  options.robot = arm::loadRobotDescription(arm::robotDescriptionFile(cell.robot));
  options.robot_base = cell.robot_base;
  options.cell_model = cell.cell_model;
  options.gripper_model = dataRoot() / gripper.mjcf;
  options.adaptive_gripper = gripper.adaptive;
  return sim::Simulation::create(sim::loadScene(scene.empty() ? cell.scene : dataRoot() / scene), options);
}

/// Swings the arm between its home and `away` at full speed within `limits`, for ever.
void swing(sim::Simulation& simulation, const arm::JointVector& away, const arm::JointLimits& limits) {
  const arm::JointVector a = simulation.armPositions();
  const auto out = std::make_shared<arm::JointTrajectory>(arm::JointTrajectory::pointToPoint(a, away, limits, 1.0));
  const auto back = std::make_shared<arm::JointTrajectory>(arm::JointTrajectory::pointToPoint(away, a, limits, 1.0));
  const Duration period = out->duration() + back->duration();
  simulation.setArmSetpointSource([out, back, period](TimePoint t) {
    const Duration phase = Duration(t.time_since_epoch().count() % period.count());
    const arm::TrajectoryPoint p = phase < out->duration() ? out->sample(phase) : back->sample(phase - out->duration());
    return sim::ArmSetpoint{p.position, p.velocity, p.acceleration};
  });
}

/// One simulated second per iteration; reports the real-time factor.
void simulateSeconds(benchmark::State& state, sim::Simulation& simulation) {
  for (auto _ : state) {
    simulation.stepTo(simulation.time() + std::chrono::seconds(1));
  }
  state.counters["realtime_factor"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}

void BM_PhysicsArmHolding(benchmark::State& state) {
  const auto simulation = assembly();
  simulateSeconds(state, *simulation);
}
BENCHMARK(BM_PhysicsArmHolding)->Unit(benchmark::kMillisecond);

void BM_PhysicsArmMoving(benchmark::State& state) {
  const auto simulation = assembly();
  // Swing the arm back and forth over the table at full speed.
  const arm::JointVector a = sim::Simulation::homeConfiguration();
  arm::JointVector b = a;
  b[0] = -1.5;
  b[1] = -1.8;
  const arm::JointLimits limits = arm::loadRobotDescription(arm::robotDescriptionFile("ur5")).limits;
  const auto out = std::make_shared<arm::JointTrajectory>(arm::JointTrajectory::pointToPoint(a, b, limits, 1.0));
  const auto back = std::make_shared<arm::JointTrajectory>(arm::JointTrajectory::pointToPoint(b, a, limits, 1.0));
  const Duration period = out->duration() + back->duration();
  simulation->setArmSetpointSource([&](TimePoint t) {
    const Duration phase = Duration(t.time_since_epoch().count() % period.count());
    const arm::TrajectoryPoint p = phase < out->duration() ? out->sample(phase) : back->sample(phase - out->duration());
    return sim::ArmSetpoint{p.position, p.velocity, p.acceleration};
  });
  simulateSeconds(state, *simulation);
}
BENCHMARK(BM_PhysicsArmMoving)->Unit(benchmark::kMillisecond);

/// The iiwa arm of cell `name` held still, or swung between its home and a pose over the table.
void iiwaPhysics(benchmark::State& state, const std::string& name, bool swinging) {
  const auto simulation = cellAssembly(name);
  if (swinging) {
    const arm::RobotDescription iiwa = arm::loadRobotDescription(arm::robotDescriptionFile("iiwa14"));
    arm::JointVector away = iiwa.home;
    away[0] = -1.2;
    away[1] = 0.6;
    swing(*simulation, away, iiwa.limits);
  }
  simulateSeconds(state, *simulation);
}

void BM_PhysicsArmHolding_Iiwa(benchmark::State& state) { iiwaPhysics(state, "iiwa-sim", false); }
BENCHMARK(BM_PhysicsArmHolding_Iiwa)->Unit(benchmark::kMillisecond);

void BM_PhysicsArmMoving_Iiwa(benchmark::State& state) { iiwaPhysics(state, "iiwa-sim", true); }
BENCHMARK(BM_PhysicsArmMoving_Iiwa)->Unit(benchmark::kMillisecond);

// The iiwa with the 3-finger adaptive gripper (workcells/iiwa-3f-sim.json): three fingers of
// three phalanges, a scissor axis and their tendons on the flange.
void BM_PhysicsArmHolding_Iiwa3f(benchmark::State& state) { iiwaPhysics(state, "iiwa-3f-sim", false); }
BENCHMARK(BM_PhysicsArmHolding_Iiwa3f)->Unit(benchmark::kMillisecond);

void BM_PhysicsArmMoving_Iiwa3f(benchmark::State& state) { iiwaPhysics(state, "iiwa-3f-sim", true); }
BENCHMARK(BM_PhysicsArmMoving_Iiwa3f)->Unit(benchmark::kMillisecond);

// The wire-bending scene (sim/scenes/wire_bending.json, docs/WIRE_BENDING.md) on the 3-finger
// iiwa: the jig, its pins and the wire's chain of capsules on two hinges each, plastic.
void BM_PhysicsWire_Iiwa3f(benchmark::State& state) {
  const auto simulation = cellAssembly("iiwa-3f-sim", "sim/scenes/wire_bending.json");
  simulateSeconds(state, *simulation);
}
BENCHMARK(BM_PhysicsWire_Iiwa3f)->Unit(benchmark::kMillisecond);

/// One frame as a plan's DetectObjects takes its last one: colour and depth, noise on 2 threads.
/// "CPU" is the main thread's; the /process_time variant counts every thread (Mesa's
/// llvmpipe rasterizes on its own threads).
void BM_CaptureRgbdFrame(benchmark::State& state) {
  const auto simulation = assembly();
  simulation->captureRgbd(0);  // the first frame compiles shaders
  std::uint64_t seed = 1;
  for (auto _ : state) {
    benchmark::DoNotOptimize(simulation->captureRgbd(seed++).points.data());
  }
}
BENCHMARK(BM_CaptureRgbdFrame)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_CaptureRgbdFrame)->Unit(benchmark::kMillisecond)->UseRealTime()->MeasureProcessCPUTime();

/// A frame without colour, as DetectObjects takes all but its last one (the same points).
void BM_CaptureDepthFrame(benchmark::State& state) {
  const auto simulation = assembly();
  simulation->captureRgbd(0, false);
  std::uint64_t seed = 1;
  for (auto _ : state) {
    benchmark::DoNotOptimize(simulation->captureRgbd(seed++, false).points.data());
  }
}
BENCHMARK(BM_CaptureDepthFrame)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_CaptureDepthFrame)->Unit(benchmark::kMillisecond)->UseRealTime()->MeasureProcessCPUTime();

/// The render alone as a picture for people takes it: colour only (with the shadow pass, which
/// camera frames leave out), no depth read-back, no noise.
void BM_RenderColourOnly(benchmark::State& state) {
  const auto simulation = assembly();
  simulation->renderImage("rgbd", 640, 480);
  for (auto _ : state) {
    benchmark::DoNotOptimize(simulation->renderImage("rgbd", 640, 480).pixels.data());
  }
}
BENCHMARK(BM_RenderColourOnly)->Unit(benchmark::kMillisecond)->UseRealTime()->MeasureProcessCPUTime();

/// The Kinect-v1 noise model alone on the workcell's clean depth image, on 1 and 2 threads.
void BM_DepthNoise(benchmark::State& state) {
  sim::SimulationOptions options;
  options.depth_noise.enabled = false;
  const auto simulation = sim::Simulation::create(sim::loadScene(dataRoot() / "sim/scenes/assembly.json"), options);
  const camera::RgbdFrame clean = simulation->captureRgbd(0, false);
  std::vector<float> depth(clean.points.size());
  for (std::size_t i = 0; i < depth.size(); ++i) {
    depth[i] = std::isfinite(clean.points[i].z()) ? clean.points[i].z() : 0.0f;
  }
  std::vector<Eigen::Vector3f> points;
  std::uint64_t seed = 1;
  for (auto _ : state) {
    sim::noisyPointCloud(depth, clean.intrinsics, sim::DepthNoiseOptions{}, seed++, points,
                         static_cast<int>(state.range(0)));
    benchmark::DoNotOptimize(points.data());
  }
}
BENCHMARK(BM_DepthNoise)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime()->MeasureProcessCPUTime();

void BM_LoadWorkcell(benchmark::State& state) {
  for (auto _ : state) {
    benchmark::DoNotOptimize(assembly().get());
  }
}
BENCHMARK(BM_LoadWorkcell)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace costar::bench

BENCHMARK_MAIN();
