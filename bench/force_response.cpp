// Force control figures (docs/FORCE.md, docs/BENCHMARKS.md "Force control"), in the LBR iiwa cell
// with the 3-finger gripper holding the orbital sander (sim/scenes/polishing.json), judged from
// the simulator's true pad force (the normal forces of the pad's contacts with the workpiece,
// sim/power_tool.h), one run per seed (the seed draws the wrist sensor's bias and noise):
//   step      MoveUntilContact down at 1 cm/s onto the workpiece with 10 N, held 2 s: the
//             force's overshoot (peak over 10 N) and its settling time (from the first touch until
//             it stays within 10 +/- 1 N)
//   tracking  PressAndFollow with 10 N along a curved path (a 3 cm circle's three quarters, 13
//             waypoints, at 3 cm/s): the RMS error of the true force while the path is followed
// Usage: force_response [N seeds, default 10] [first seed, default 5001] [PNG of the first seed's
// step response, optional]. Run from the repository root: build/bench/force_response

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "core/paths.h"
#include "sim/simulation.h"
#include "trials/tool_plot.h"
#include "workcell/workcell.h"

namespace {

using namespace costar;

constexpr double kForce = 10.0;         // N
constexpr double kSettleBand = 1.0;     // N
constexpr double kPadAboveTcp = 0.107;  // m: the grasp 'knob' holds the tool centre point this far above the pad

struct Figures {
  bool ok = false;
  std::string failure;
  double overshoot = 0.0;     // N above kForce at the peak
  double settling = 0.0;      // s
  double tracking_rms = 0.0;  // N, true force
  double sensor_rms = 0.0;    // N, as the operation measured it
  std::vector<sim::PowerToolSample> step_log;
};

std::filesystem::path curveWaypoints(const Eigen::Vector3d& centre) {
  const auto file = std::filesystem::temp_directory_path() / "costar_force_response_waypoints.json";
  std::ofstream out(file);
  out << "{\"waypoints\": [";
  constexpr int kPoints = 13;
  for (int i = 0; i < kPoints; ++i) {
    const double angle = 1.5 * M_PI * i / (kPoints - 1);
    const Eigen::Vector3d p = centre + 0.03 * Eigen::Vector3d(std::cos(angle), std::sin(angle), 0.0);
    out << (i == 0 ? "" : ",") << "{\"name\": \"c" << i << "\", \"frame\": \"world\", \"position\": [" << p.x() << ", "
        << p.y() << ", " << p.z() << "], \"orientation\": [0, 1, 0, 0]}";
  }
  out << "]}";
  return file;
}

double rmsError(const std::vector<sim::PowerToolSample>& log, double from, double to) {
  double sum = 0.0;
  int n = 0;
  for (const sim::PowerToolSample& sample : log) {
    if (sample.time >= from && sample.time <= to) {
      sum += (sample.pad_force - kForce) * (sample.pad_force - kForce);
      ++n;
    }
  }
  return n > 0 ? std::sqrt(sum / n) : 0.0;
}

Figures run(std::uint64_t seed) {
  Figures figures;
  const std::filesystem::path scene = dataRoot() / "sim/scenes/polishing.json";
  const sim::WorkpieceRequest workpiece = sim::loadScene(scene).workpiece.value();
  const world::Pose top = sim::workpieceTop(workpiece);
  const Eigen::Vector3d tcp_on_top = top.translation() + Eigen::Vector3d(0, 0, kPadAboveTcp);
  const auto cell = workcell::makeWorkcell({.name = "iiwa-3f-sim",
                                            .scene = scene,
                                            .seed = seed,
                                            .waypoints = curveWaypoints(tcp_on_top),
                                            .memory_only = true,
                                            .test_oracle_perception = true});
  sim::Simulation& simulation = *cell->simulation();
  const auto now = [&] { return toSeconds(simulation.time().time_since_epoch()); };
  const auto step = [&](const std::string& operation, const component::ParamMap& params) {
    const component::OperationResult result =
        workcell::runOperation(*cell, operation, params, std::chrono::seconds(60));
    if (result.state != component::OperationState::kSuccess && figures.failure.empty()) {
      figures.failure = operation + ": " + result.reason;
    }
    return result.state == component::OperationState::kSuccess;
  };
  if (!step("SmartGrasp", {{"object_class", "orbital_sander"}, {"grasp", "knob"}}) ||
      !step("MoveToPose",
            {{"pose", world::poseFromXyzRpy(tcp_on_top.x(), tcp_on_top.y(), tcp_on_top.z() + 0.03, M_PI, 0, 0)}})) {
    return figures;
  }
  // The step response.
  const double start = now();
  if (!step("MoveUntilContact", {{"direction", "down"}, {"force", kForce}, {"speed", 0.01}})) {
    return figures;
  }
  simulation.stepTo(simulation.time() + std::chrono::seconds(2));
  const double end = now();
  const auto& log = simulation.powerTool()->log();
  double touched = -1.0;
  double peak = 0.0;
  double last_out = -1.0;
  for (const sim::PowerToolSample& sample : log) {
    if (sample.time < start || sample.time > end) {
      continue;
    }
    figures.step_log.push_back(sample);
    if (touched < 0.0 && sample.pad_force > 0.5) {
      touched = sample.time;
    }
    if (touched >= 0.0) {
      peak = std::max(peak, sample.pad_force);
      if (std::abs(sample.pad_force - kForce) > kSettleBand) {
        last_out = sample.time;
      }
    }
  }
  if (touched < 0.0) {
    figures.failure = "the pad never touched the workpiece";
    return figures;
  }
  figures.overshoot = peak - kForce;
  figures.settling = std::max(0.0, last_out - touched);
  if (!step("ReleaseContact", {{"distance", 0.03}})) {
    return figures;
  }
  // Tracking along the curve.
  std::vector<std::string> names;
  for (int i = 0; i < 13; ++i) {
    names.push_back("c" + std::to_string(i));
  }
  double following = -1.0;
  const component::OperationResult pressed = workcell::runOperation(
      *cell, "PressAndFollow", {{"path", component::Value::List(names.begin(), names.end())}, {"force", kForce}},
      std::chrono::seconds(60), [&](const component::OperationResult&) {
        const arm::CartesianState state = simulation.cartesianController().state();
        if (following < 0.0 && state.following && state.arc > 0.0 && state.axis_force > 0.8 * kForce) {
          following = now();
        }
      });
  if (pressed.state != component::OperationState::kSuccess) {
    figures.failure = "PressAndFollow: " + pressed.reason;
    return figures;
  }
  figures.tracking_rms = rmsError(simulation.powerTool()->log(), following, now());
  figures.sensor_rms = pressed.data["force_rms_error_n"].get<double>();
  figures.ok = true;
  return figures;
}

}  // namespace

int main(int argc, char** argv) {
  const int n = argc > 1 ? std::atoi(argv[1]) : 10;
  const std::uint64_t first = argc > 2 ? std::strtoull(argv[2], nullptr, 10) : 5001;
  if (n <= 0 || n > 1000) {
    std::fprintf(stderr, "usage: force_response [N seeds, 1..1000] [first seed] [step.png]\n");
    return 2;
  }
  std::printf("%6s %14s %12s %18s %18s\n", "seed", "overshoot N", "settling s", "tracking RMS N", "(sensor's) N");
  std::vector<double> overshoots;
  std::vector<double> settlings;
  std::vector<double> rms;
  int failed = 0;
  for (int i = 0; i < n; ++i) {
    const std::uint64_t seed = first + static_cast<std::uint64_t>(i);
    const Figures figures = run(seed);
    if (!figures.ok) {
      ++failed;
      std::printf("%6llu  failed: %s\n", static_cast<unsigned long long>(seed), figures.failure.c_str());
      continue;
    }
    std::printf("%6llu %14.2f %12.2f %18.2f %18.2f\n", static_cast<unsigned long long>(seed), figures.overshoot,
                figures.settling, figures.tracking_rms, figures.sensor_rms);
    overshoots.push_back(figures.overshoot);
    settlings.push_back(figures.settling);
    rms.push_back(figures.tracking_rms);
    if (i == 0 && argc > 3) {
      costar::trials::ToolTrace trace;
      trace.seed = seed;
      trace.log = figures.step_log;
      trace.title = "MoveUntilContact: 10 N down at 1 cm/s onto the workpiece (seed SEED)";
      trace.band_note = "settled";
      costar::trials::writeForcePlot(trace, kForce, kSettleBand, argv[3]);
      std::printf("wrote %s\n", argv[3]);
    }
  }
  const auto summary = [](std::vector<double> values) {
    std::sort(values.begin(), values.end());
    double sum = 0.0;
    for (const double value : values) {
      sum += value;
    }
    return values.empty() ? std::string("-")
                          : std::to_string(sum / static_cast<double>(values.size())).substr(0, 5) + " mean, " +
                                std::to_string(values.back()).substr(0, 5) + " worst";
  };
  std::printf("\n%d of %d seeds ran; overshoot %s N; settling %s s; tracking RMS %s N\n", n - failed, n,
              summary(overshoots).c_str(), summary(settlings).c_str(), summary(rms).c_str());
  return failed == 0 ? 0 : 1;
}
