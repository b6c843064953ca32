#pragma once
// `costar trials`: rerun a plan as N randomized trials in simulation and report.

#include <CLI/CLI.hpp>

namespace costar::cli {

void addTrialsCommand(CLI::App& app, int& exit_code);

}  // namespace costar::cli
