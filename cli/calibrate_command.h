#pragma once

#include <CLI/CLI.hpp>

namespace costar::cli {

/// costar calibrate [marker | eval]: the workcell's camera calibration (calibration/).
void addCalibrateCommand(CLI::App& app, int& exit_code);

}  // namespace costar::cli
