#include "cli/sim_commands.h"

#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>

#include "bt/builder.h"
#include "bt/executor.h"
#include "bt/plan_xml.h"
#include "cli/number_options.h"
#include "cli/output_options.h"
#include "core/clock.h"
#include "core/image.h"
#include "sim/simulation.h"
#include "workcell/workcell.h"

namespace costar::cli {

namespace {

struct SnapshotOptions {
  std::string scene;
  std::string out = "scene.png";
  std::string camera = "overview";
  std::string depth_out;
  int width = 1280;
  int height = 960;
  std::uint64_t seed = 0;
  bool seed_given = false;
  // The cell, and a plan run in it before the picture.
  std::string workcell;
  std::string plan;
  std::string waypoints;
  double settle_s = 2.0;
};

/// Colours a depth image (near: yellow, far: blue); black where there is no reading.
RgbImage depthPicture(const camera::RgbdFrame& frame) {
  RgbImage image(frame.intrinsics.width, frame.intrinsics.height);
  double near = 1e9;
  double far = 0;
  for (const auto& p : frame.points) {
    if (std::isfinite(p.z())) {
      near = std::min(near, static_cast<double>(p.z()));
      far = std::max(far, static_cast<double>(p.z()));
    }
  }
  for (int v = 0; v < image.height; ++v) {
    for (int u = 0; u < image.width; ++u) {
      std::uint8_t* pixel = image.at(u, v);
      if (!frame.valid(u, v)) {
        continue;
      }
      const double s = (frame.point(u, v).z() - near) / std::max(far - near, 1e-6);
      pixel[0] = static_cast<std::uint8_t>(255 * (1 - s));
      pixel[1] = static_cast<std::uint8_t>(200 * (1 - s) + 40 * s);
      pixel[2] = static_cast<std::uint8_t>(60 + 180 * s);
    }
  }
  return image;
}

/// What the scene's jig and wire look like now, one line (nothing without a jig).
void printJig(const sim::Simulation& simulation) {
  const std::optional<sim::JigState> jig = simulation.jig();
  if (!jig || !jig->has_wire) {
    return;
  }
  std::printf("wire: %.1f mm out of the clamp, E %.0f GPa, yield strength %.0f MPa; bends",
              jig->draw.wire_length * 1000, jig->draw.youngs_modulus_gpa, jig->draw.yield_strength_mpa);
  for (const sim::MeasuredBend& bend : jig->bends) {
    std::printf(" %.1f (drawing %.0f, out of plane %.1f)", bend.angle_deg, bend.target_deg, bend.out_of_plane_deg);
  }
  std::printf(" degrees; held %d, let go %d, pulled out %d times, slid %.1f mm in the fingers", jig->grip.holds,
              jig->grip.releases, jig->grip.pulled_out, jig->grip.max_slip * 1000);
  for (const sim::PinState& pin : jig->pins) {
    std::printf("; pin %s pushed with up to %.0f N, moved %.1f mm", pin.name.c_str(), pin.max_force,
                pin.slipped * 1000);
  }
  std::printf("\n");
}

/// The workcell of the options with the scene, the plan run in it (its outcome printed), the
/// world left to settle. Returns the plan's exit code (0: none, or SUCCESS; 1: FAILURE; 2:
/// invalid).
int runPlanInCell(const SnapshotOptions& options, workcell::Workcell& cell) {
  if (options.plan.empty()) {
    return 0;
  }
  const bt::Plan plan = bt::loadPlan(options.plan);
  if (auto diagnostics = bt::validatePlan(plan, cell.nodes()); !diagnostics.empty()) {
    throw bt::PlanError(std::move(diagnostics));
  }
  bt::Tree tree = bt::buildTree(plan, cell.nodes(), cell.clock());
  bt::Executor executor(tree, cell.clock(), {.time_limit = std::chrono::minutes(10)});
  executor.setBeforeTick([&cell] { cell.beforeTick(); });
  const bt::RunResult run = executor.run();
  std::printf("ran %s: %s after %.1f s simulated%s%s\n", options.plan.c_str(),
              run.status == bt::Status::kSuccess ? "SUCCESS" : "FAILURE", toSeconds(run.elapsed),
              run.status == bt::Status::kSuccess ? "" : (" at " + run.failure_path + ": ").c_str(),
              run.status == bt::Status::kSuccess ? "" : run.failure_reason.c_str());
  return run.status == bt::Status::kSuccess ? 0 : 1;
}

int snapshot(const SnapshotOptions& options) {
  try {
    const sim::Scene scene = sim::loadScene(options.scene);
    std::unique_ptr<workcell::Workcell> cell;
    std::unique_ptr<sim::Simulation> own;
    sim::Simulation* simulation = nullptr;
    int code = 0;
    if (!options.workcell.empty() || !options.plan.empty()) {
      workcell::WorkcellOptions cell_options;
      cell_options.name = options.workcell.empty() ? cell_options.name : options.workcell;
      cell_options.scene = options.scene;
      if (options.seed_given) {
        cell_options.seed = options.seed;
      }
      cell_options.waypoints = options.waypoints;
      cell_options.memory_only = true;
      cell = workcell::makeWorkcell(cell_options);
      simulation = cell->simulation();
      if (simulation == nullptr) {
        throw std::runtime_error("workcell '" + cell_options.name + "' is not simulated: nothing to picture");
      }
      code = runPlanInCell(options, *cell);
      if (!options.plan.empty()) {
        simulation->stepTo(simulation->time() + checkedDuration(options.settle_s, "--settle"));
      }
    } else {
      sim::SimulationOptions sim_options;
      if (options.seed_given) {
        sim_options.placement_seed = options.seed;
      }
      own = sim::Simulation::create(scene, sim_options);
      simulation = own.get();
    }
    printJig(*simulation);
    writePng(options.out, simulation->renderImage(options.camera, options.width, options.height));
    std::printf("wrote %s (%dx%d, camera '%s', %zu parts)\n", options.out.c_str(), options.width, options.height,
                options.camera.c_str(), simulation->parts().size());
    if (!options.depth_out.empty()) {
      const camera::RgbdFrame frame = simulation->captureRgbd(options.seed_given ? options.seed : scene.seed);
      writePng(options.depth_out, depthPicture(frame));
      std::printf("wrote %s (depth of the RGB-D camera with sensor noise, %zu of %d pixels valid)\n",
                  options.depth_out.c_str(), frame.validCount(), frame.intrinsics.width * frame.intrinsics.height);
    }
    return code;
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  }
}

}  // namespace

void addSimCommands(CLI::App& app, int& exit_code) {
  CLI::App* sim = app.add_subcommand("sim", "The simulated UR5 workcell on its own");
  sim->require_subcommand(1);
  auto options = std::make_shared<SnapshotOptions>();
  CLI::App* snap = sim->add_subcommand("snapshot", "Render a scene to a PNG a person can look at");
  snap->add_option("scene", options->scene, "scene file (e.g. sim/scenes/assembly.json)")
      ->required()
      ->check(CLI::ExistingFile);
  snap->add_option("-o,--out", options->out, "PNG to write")->capture_default_str()->check(aFileName());
  snap->add_option("--camera", options->camera, "overview, rgbd, or jig (straight above a scene's bending jig)")
      ->check(CLI::IsMember({"overview", "rgbd", "jig"}))
      ->capture_default_str();
  snap->add_option("--depth", options->depth_out, "also write the RGB-D camera's noisy depth as a PNG");
  snap->add_option("--width", options->width, "image width (at most 1280)")->check(CLI::Range(16, 1280));
  snap->add_option("--height", options->height, "image height (at most 960)")->check(CLI::Range(16, 960));
  snap->add_option("--seed", options->seed, "placement seed (default: the scene's)")
      ->check(wholeNumber())
      ->each([options](const std::string&) { options->seed_given = true; });
  snap->add_option("-w,--workcell", options->workcell,
                   "the simulated cell (workcells/NAME.json; default: the UR5 on its own, or ur5-sim with --plan)");
  snap->add_option("--plan", options->plan, "run this plan in the cell first, then let the world settle")
      ->check(CLI::ExistingFile);
  snap->add_option("--waypoints", options->waypoints, "the plan's taught waypoints (read only)")
      ->check(CLI::ExistingFile);
  snap->add_option("--settle", options->settle_s, "simulated seconds after the plan, before the picture")
      ->check(numberIn(0, 600, false, " s"))
      ->capture_default_str();
  snap->callback([options, &exit_code] { exit_code = snapshot(*options); });
}

}  // namespace costar::cli
