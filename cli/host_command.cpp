#include "cli/host_command.h"

#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iostream>

#include "cli/output_options.h"
#include "cli/robot_commands.h"
#include "cli/stop_signals.h"
#include "core/paths.h"
#include "dds/host.h"
#include "dds/lockstep.h"
#include "trials/host_campaign.h"
#include "workcell/remote_sim.h"
#include "workcell/workcell.h"

namespace costar::cli {
namespace {

struct HostOptions {
  std::vector<std::string> components;
  std::string workcell = "ur5-sim";
  dds::RemoteConfig remote;
};

/// A simulated cell's components, in lockstep with the simulation of the executor that uses
/// them: they read its clock on rt/clock and reach its gripper and camera through it.
int hostSimulated(const HostOptions& options) {
  dds::RemoteConfig remote = options.remote;
  remote.lockstep = true;
  dds::SimulatorLink link(remote);
  workcell::RemoteSimComponents components(options.workcell, options.components, link);
  dds::ComponentHost::Lockstep lockstep;
  lockstep.new_run = [&](std::uint64_t executor) {
    link.setExecutor(executor);
    return components.make();
  };
  lockstep.reach_time = [&](std::int64_t stamp_ns) { link.reachTime(stamp_ns); };
  lockstep.prepare = [&](const std::string& prepared_json) { link.prepare(prepared_json); };
  lockstep.prepared_used = [&] { return link.preparedUsed(); };
  dds::ComponentHost component_host(remote, components.make(), lockstep);
  link.setHost(component_host.id());
  std::cerr << "costar host: serving";
  for (const auto& name : options.components) {
    std::cerr << " " << name;
  }
  std::cerr << " of " << options.workcell << " in lockstep with the simulation of the executor on DDS domain "
            << remote.domain << ", partition '" << remote.partition << "', interface '" << remote.network_interface
            << "' (pid " << ::getpid() << "); Ctrl-C stops\n";
  component_host.serve(StopSignals::stopRequested());
  std::cerr << "costar host: stopped by " << StopSignals::name(StopSignals::received()) << "\n";
  return 0;
}

int host(const HostOptions& options) {
  try {
    StopSignals signals;
    if (options.workcell != "test" && options.workcell != "none") {
      workcell::requireKnownWorkcell(options.workcell);
      return hostSimulated(options);
    }
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
    // The cell's world is refreshed every cycle.
    component_host.serve(StopSignals::stopRequested(), [&] { cell->beforeTick(); });
    std::cerr << "costar host: stopped by " << StopSignals::name(StopSignals::received()) << "\n";
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  }
}

}  // namespace

/// The liveness campaign (trials/host_campaign.h): this executable is the host.
int hostCampaign(trials::HostCampaignOptions options, const std::filesystem::path& json_file) {
  try {
    char self[4096] = {};
    const ssize_t length = ::readlink("/proc/self/exe", self, sizeof(self) - 1);
    if (length <= 0) {
      throw std::runtime_error("cannot find this executable (/proc/self/exe)");
    }
    options.host_command = {std::string(self, static_cast<std::size_t>(length)), "host"};
    if (options.plan.empty()) {
      options.plan = dataRoot() / "examples/ur5/assemble_structure.xml";
    }
    std::cerr << "costar host-campaign: " << options.count << " run(s) of " << options.plan.string() << " on "
              << options.workcell << ", the host of";
    for (const auto& name : options.components) {
      std::cerr << " " << name;
    }
    std::cerr << " killed (SIGKILL) at a moment drawn from seeds " << options.seed << "..\n";
    const trials::HostCampaignSummary summary =
        trials::runHostCampaign(options, [&](const trials::HostKillRun& run, int done) {
          std::cerr << "[" << done << "/" << options.count << "] seed " << run.seed << " " << run.phase << " ("
                    << run.node << " at " << run.kill_at_s << " s): " << run.outcome;
          if (run.noticed_s >= 0) {
            std::cerr << ", FAILURE " << run.noticed_s << " s after the kill";
          }
          std::cerr << ": " << run.reason << "\n";
        });
    std::cout << summary.text();
    if (!json_file.empty()) {
      std::ofstream(json_file) << summary.toJson().dump(2) << "\n";
    }
    const bool all =
        std::all_of(summary.runs.begin(), summary.runs.end(), [](const trials::HostKillRun& run) { return run.met(); });
    return all ? 0 : 1;
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  }
}

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

  auto campaign = std::make_shared<trials::HostCampaignOptions>();
  auto json_file = std::make_shared<std::filesystem::path>();
  CLI::App* kill = app.add_subcommand(kRobotCommands.back().name, kRobotCommands.back().description);
  kill->add_option("plan", campaign->plan, "the plan (default examples/ur5/assemble_structure.xml)");
  kill->add_option("-w,--workcell", campaign->workcell, "simulated workcell")->capture_default_str();
  kill->add_option("-n,--count", campaign->count, "runs in all, the phases in turn")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  kill->add_option("--seed", campaign->seed, "run i uses seed + i")->capture_default_str();
  kill->add_option("--phases", campaign->phases, "detect, move, between")->capture_default_str();
  kill->add_option("--domain", campaign->domain, "DDS domain of the runs")
      ->check(CLI::Range(0, 232))
      ->capture_default_str();
  kill->add_option("--deadline", campaign->deadline_s, "s of wall time from the kill to the FAILURE")
      ->capture_default_str();
  kill->add_option("--waypoints", campaign->waypoints, "a waypoint file the plan reads: must stay unchanged")
      ->check(CLI::ExistingFile);
  kill->add_option("--json", *json_file, "write every run and the summary here")->check(aFileName());
  kill->callback([campaign, json_file, &exit_code] { exit_code = hostCampaign(*campaign, *json_file); });
}

}  // namespace costar::cli
