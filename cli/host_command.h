#pragma once
// `costar host COMPONENT... -w CELL`: serves components of a workcell from this process to an
// executor in another process or on another machine, over DDS (dds/host.h).

#include <CLI/CLI.hpp>

namespace costar::cli {

/// Adds `host` and `host-campaign` (the liveness campaign of remote components,
/// trials/host_campaign.h) to `app`; each sets `exit_code` when it ends.
void addHostCommand(CLI::App& app, int& exit_code);

}  // namespace costar::cli
