#pragma once
// `costar perception ...`: set-up (collect, train) and evaluation of perception.

#include <CLI/CLI.hpp>

namespace costar::cli {

void addPerceptionCommands(CLI::App& app, int& exit_code);

}  // namespace costar::cli
