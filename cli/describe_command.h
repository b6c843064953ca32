#pragma once
// `costar-robot describe-workcell`: writes a robot cell's description (workcell/described_workcell.h),
// which the light `costar` reads to validate plans without starting the cell. Run at build time.

#include <CLI/CLI.hpp>

namespace costar::cli {

void addDescribeWorkcellCommand(CLI::App& app, int& exit_code);

}  // namespace costar::cli
