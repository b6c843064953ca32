#include "cli/describe_command.h"

#include <iostream>

#include "cli/output_options.h"
#include "core/files.h"
#include "sim/simulation.h"
#include "workcell/described_workcell.h"

namespace costar::cli {

namespace {

struct DescribeOptions {
  std::string workcell = "ur5-sim";
  std::string out;
};

int describe(const DescribeOptions& options) {
  try {
    // No waypoint file: a user's waypoints are read when the description is used.
    const auto cell = workcell::makeWorkcell({.name = options.workcell, .memory_only = true});
    std::vector<std::string> classes;
    if (sim::Simulation* simulation = cell->simulation()) {
      for (const auto& object_class : simulation->objectClasses()) {
        classes.push_back(object_class.name);
      }
    }
    const std::string text = workcell::toJson(workcell::describeWorkcell(*cell, std::move(classes))).dump(1) + "\n";
    if (options.out.empty()) {
      std::cout << text;
      return 0;
    }
    writeOutputFile(options.out, text);
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  }
}

}  // namespace

void addDescribeWorkcellCommand(CLI::App& app, int& exit_code) {
  auto options = std::make_shared<DescribeOptions>();
  CLI::App* command = app.add_subcommand(
      "describe-workcell",
      "Write a workcell's description (node types, frames, object classes) as JSON; the build stores the "
      "simulated UR5 cell's, so that `costar validate` needs no simulator");
  command->group("");  // for the build, not for users
  command->add_option("-w,--workcell", options->workcell, "workcell")->capture_default_str();
  command->add_option("-o,--out", options->out, "write to FILE instead of standard output")->check(aFileName());
  command->callback([options, &exit_code] { exit_code = describe(*options); });
}

}  // namespace costar::cli
