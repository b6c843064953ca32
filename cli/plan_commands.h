#pragma once
// `costar run`, `costar validate`, `costar nodes`, `costar workcells`.

#include <CLI/CLI.hpp>

namespace costar::cli {

/// Adds the plan commands to `app`. Each sets `exit_code` when it runs.
void addPlanCommands(CLI::App& app, int& exit_code);

}  // namespace costar::cli
