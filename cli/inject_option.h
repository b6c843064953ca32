#pragma once
// `--inject KIND:TARGET@WHEN` for the commands that run plans (costar run, costar trials).

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

namespace costar::cli {

/// Adds --inject (repeatable); each spec is parsed when the command line is read, so a bad one
/// is refused with the grammar before anything runs.
void addInjectOption(CLI::App* command, std::vector<std::string>& specs);

}  // namespace costar::cli
