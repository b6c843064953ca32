#include "cli/serve_command.h"

#include <iostream>

#include "cli/number_options.h"
#include "server/serve.h"

namespace costar::cli {

void addServeCommand(CLI::App& app, int& exit_code) {
  auto options = std::make_shared<server::ServeOptions>();
  CLI::App* serve = app.add_subcommand(
      "serve", "Serve the task editor (a web page) and its API: build, run and watch plans on a workcell");
  serve->add_option("-w,--workcell", options->workcell.name, "workcell to run on: " + workcell::knownWorkcellNames())
      ->capture_default_str();
  serve->add_option("--scene", options->workcell.scene, "simulated workcells: scene file")->check(CLI::ExistingFile);
  serve->add_option("--seed", options->workcell.seed, "simulated workcells: seed of part placement and sensor noise")
      ->check(wholeNumber());
  serve->add_option("--waypoints", options->workcell.waypoints,
                    "waypoint file (default " + workcell::defaultWaypointFile("<workcell>").string() + ")");
  serve
      ->add_option("--address", options->address,
                   "address to listen on; anything but loopback makes every request need the token")
      ->capture_default_str();
  serve->add_option("-p,--port", options->port, "port (0: any free port)")->capture_default_str();
  serve->add_option(
      "--store", options->store,
      "SQLite store of plans, subtrees and run logs (default " + server::defaultStoreFile("<workcell>").string() + ")");
  serve->add_option("--token-file", options->token_file,
                    "read the API token from FILE (mode 0600), or create it there; default: a new random token, "
                    "printed");
  serve->add_option("--web-root", options->web_root, "folder of the built page (default web/dist)");
  serve
      ->add_option("--pace", options->pace,
                   "simulated seconds per wall second in simulated cells (0: runs as fast as possible)")
      ->check(numberIn(0.0, 1000.0))
      ->capture_default_str();
  serve->add_option("--stream-rate", options->stream_hz, "snapshots per second on the live stream")
      ->check(numberIn(1.0, 100.0, false, " Hz"))
      ->capture_default_str();
  serve->add_flag("--test-endpoints", options->test_endpoints,
                  "TEST ONLY: expose the simulator's true state at /api/test/ground_truth (end-to-end tests)");
  serve->footer(
      "Open the printed address in a browser. Every request that changes anything or moves the robot needs the\n"
      "token (Authorization: Bearer TOKEN). See docs/EDITOR.md.");
  serve->callback([options, &exit_code] { exit_code = server::runServe(*options, std::cout, std::cerr); });
}

}  // namespace costar::cli
