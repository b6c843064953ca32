#pragma once
// `costar sim ...`: the simulated workcell on its own (pictures, checks).

#include <CLI/CLI.hpp>

namespace costar::cli {

void addSimCommands(CLI::App& app, int& exit_code);

}  // namespace costar::cli
