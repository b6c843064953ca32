#pragma once
// `costar teach`: an interactive session to jog the arm, teach and manage waypoints.

#include <CLI/CLI.hpp>

namespace costar::cli {

void addTeachCommand(CLI::App& app, int& exit_code);
/// `costar smartmove teach CLASS NAME --at WAYPOINT`.
void addSmartMoveCommands(CLI::App& app, int& exit_code);

}  // namespace costar::cli
