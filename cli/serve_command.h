#pragma once
// `costar serve`: the task editor (a web page) and its HTTP + WebSocket API.

#include <CLI/CLI.hpp>

namespace costar::cli {

/// Adds `serve` to `app`; it sets `exit_code` when it ends.
void addServeCommand(CLI::App& app, int& exit_code);

}  // namespace costar::cli
