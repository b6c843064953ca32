#include "cli/sim_commands.h"

#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>

#include "core/image.h"
#include "sim/simulation.h"

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

int snapshot(const SnapshotOptions& options) {
  try {
    sim::SimulationOptions sim_options;
    if (options.seed_given) {
      sim_options.placement_seed = options.seed;
    }
    const sim::Scene scene = sim::loadScene(options.scene);
    const auto simulation = sim::Simulation::create(scene, sim_options);
    writePng(options.out, simulation->renderImage(options.camera, options.width, options.height));
    std::printf("wrote %s (%dx%d, camera '%s', %zu parts)\n", options.out.c_str(), options.width, options.height,
                options.camera.c_str(), simulation->parts().size());
    if (!options.depth_out.empty()) {
      const camera::RgbdFrame frame = simulation->captureRgbd(options.seed_given ? options.seed : scene.seed);
      writePng(options.depth_out, depthPicture(frame));
      std::printf("wrote %s (depth of the RGB-D camera with sensor noise, %zu of %d pixels valid)\n",
                  options.depth_out.c_str(), frame.validCount(), frame.intrinsics.width * frame.intrinsics.height);
    }
    return 0;
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
  snap->add_option("-o,--out", options->out, "PNG to write")->capture_default_str();
  snap->add_option("--camera", options->camera, "overview or rgbd")
      ->check(CLI::IsMember({"overview", "rgbd"}))
      ->capture_default_str();
  snap->add_option("--depth", options->depth_out, "also write the RGB-D camera's noisy depth as a PNG");
  snap->add_option("--width", options->width, "image width (at most 1280)")->check(CLI::Range(16, 1280));
  snap->add_option("--height", options->height, "image height (at most 960)")->check(CLI::Range(16, 960));
  snap->add_option("--seed", options->seed, "placement seed (default: the scene's)")
      ->each([options](const std::string&) { options->seed_given = true; });
  snap->callback([options, &exit_code] { exit_code = snapshot(*options); });
}

}  // namespace costar::cli
