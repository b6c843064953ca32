// costar: teach a collaborative robot a task as a behavior tree, and run it.
//
// This executable links no robot library: it runs plans on the cells without a robot and
// validates plans (a robot cell from its stored description); every other command runs in
// costar-robot (main.cpp), which it replaces itself with (robot_binary.h). So `costar --help`,
// `costar validate` and `costar run -w none` start in milliseconds.

#include <CLI/CLI.hpp>
#include <set>
#include <string>

#include "cli/plan_commands.h"
#include "cli/robot_binary.h"
#include "cli/robot_commands.h"
#include "cli/stop_signals.h"

int main(int argc, char** argv) {
  costar::cli::ignoreBrokenPipes();
  costar::cli::rememberCommandLine(argc, argv);
  CLI::App app{costar::cli::kAppDescription};
  app.set_version_flag("--version", costar::cli::kVersion);
  app.require_subcommand(1);
  int exit_code = 0;
  costar::cli::addPlanCommands(app, exit_code);
  std::set<std::string> here;
  for (const CLI::App* command : app.get_subcommands({})) {
    here.insert(command->get_name());
  }
  // The command is the first word that is not an option (the only global options, --help and
  // --version, end the parse): anything but a plan command is costar-robot's, which also
  // gives the error for a misspelt one.
  for (int i = 1; i < argc; ++i) {
    if (argv[i][0] != '-') {
      if (!here.contains(argv[i])) {
        costar::cli::runInRobotBinary();
      }
      break;
    }
  }
  for (const auto& command : costar::cli::kRobotCommands) {
    app.add_subcommand(command.name, command.description);  // for the help; never parsed here
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& error) {
    const int code = app.exit(error);
    return code == 0 ? 0 : 2;
  }
  return exit_code;
}
