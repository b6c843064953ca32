// costar-robot: every costar command, with the robot libraries (simulator, perception,
// planning). The light `costar` (light_main.cpp) runs the commands that need none of them and
// hands the others to this executable (robot_binary.h).

#include <CLI/CLI.hpp>

#include "cli/calibrate_command.h"
#include "cli/describe_command.h"
#include "cli/host_command.h"
#include "cli/perception_commands.h"
#include "cli/plan_commands.h"
#include "cli/serve_command.h"
#include "cli/sim_commands.h"
#include "cli/stop_signals.h"
#include "cli/teach_command.h"
#include "cli/trials_command.h"

int main(int argc, char** argv) {
  costar::cli::ignoreBrokenPipes();
  CLI::App app{
      "costar: build task plans as behavior trees of robot operations (DetectObjects, SmartMove, Close "
      "gripper, ...) and run them on a workcell (CoSTAR, ICRA 2017)."};
  app.set_version_flag("--version", "costar 0.1.0");
  app.require_subcommand(1);
  int exit_code = 0;
  costar::cli::addPlanCommands(app, exit_code);
  costar::cli::addDescribeWorkcellCommand(app, exit_code);  // hidden: for the build
  costar::cli::addSimCommands(app, exit_code);
  costar::cli::addPerceptionCommands(app, exit_code);
  costar::cli::addTeachCommand(app, exit_code);
  costar::cli::addSmartMoveCommands(app, exit_code);
  costar::cli::addTrialsCommand(app, exit_code);
  costar::cli::addCalibrateCommand(app, exit_code);
  costar::cli::addServeCommand(app, exit_code);
  costar::cli::addHostCommand(app, exit_code);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& error) {
    const int code = app.exit(error);
    return code == 0 ? 0 : 2;
  }
  return exit_code;
}
