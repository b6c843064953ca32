#include "cli/host_command.h"

#include <unistd.h>

#include <chrono>
#include <iostream>

#include "cli/stop_signals.h"
#include "dds/host.h"
#include "workcell/workcell.h"

namespace costar::cli {
namespace {

struct HostOptions {
  std::vector<std::string> components;
  std::string workcell = "ur5-sim";
  dds::RemoteConfig remote;
};

int host(const HostOptions& options) {
  try {
    StopSignals signals;
    const auto cell = workcell::makeWorkcell({.name = options.workcell, .memory_only = true});
    std::vector<std::shared_ptr<component::Component>> served;
    for (const auto& name : options.components) {
      std::string known;
      std::shared_ptr<component::Component> found;
      for (const auto& component : cell->components().components()) {
        known += (known.empty() ? "" : ", ") + component->description().name;
        if (component->description().name == name) {
          found = component;
        }
      }
      if (!found) {
        std::cerr << "error: workcell '" << options.workcell << "' has no component '" << name << "' (it has: " << known
                  << ")\n";
        return 2;
      }
      served.push_back(found);
    }
    dds::ComponentHost component_host(options.remote, served);
    std::cerr << "costar host: serving";
    for (const auto& name : options.components) {
      std::cerr << " " << name;
    }
    std::cerr << " of " << options.workcell << " on DDS domain " << options.remote.domain << ", partition '"
              << options.remote.partition << "', interface '" << options.remote.network_interface << "' (pid "
              << ::getpid() << "); Ctrl-C stops\n";
    // The cell's world is refreshed every cycle, and a simulated cell's time follows the wall
    // clock: the host's simulation runs in real time.
    const auto started = std::chrono::steady_clock::now();
    const TimePoint cell_start = cell->clock().now();
    component_host.serve(StopSignals::stopRequested(), [&] {
      if (cell->clock().simulated()) {
        cell->clock().sleepUntil(cell_start + (std::chrono::steady_clock::now() - started));
      }
      cell->beforeTick();
    });
    std::cerr << "costar host: stopped by " << StopSignals::name(StopSignals::received()) << "\n";
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  }
}

}  // namespace

void addHostCommand(CLI::App& app, int& exit_code) {
  auto options = std::make_shared<HostOptions>();
  CLI::App* command =
      app.add_subcommand("host", "Serve components of a workcell to an executor in another process or machine (DDS)");
  command->add_option("components", options->components, "the components to serve (e.g. gripper perception)")
      ->required();
  command->add_option("-w,--workcell", options->workcell, "workcell")->capture_default_str();
  command->add_option("--domain", options->remote.domain, "DDS domain")
      ->check(CLI::Range(0, 232))
      ->capture_default_str();
  command->add_option("--partition", options->remote.partition, "DDS partition")->capture_default_str();
  command
      ->add_option("--interface", options->remote.network_interface,
                   "network interface (lo: this machine only; any other reaches the network, unprotected)")
      ->capture_default_str();
  command->callback([options, &exit_code] { exit_code = host(*options); });
}

}  // namespace costar::cli
