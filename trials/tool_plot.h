#pragma once
// Pictures of one polishing trial (docs/FORCE.md): the pad's force over time with the band the
// judge wants, when the tool was on, in the gripper, and taken away; and the workpiece's marked
// area, texel by texel, how long and how hard it was worked. From the simulator's record of the
// power tool (sim/power_tool.h), kept for a batch's first trial.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "sim/power_tool.h"

namespace costar::trials {

struct ToolTrace {
  std::uint64_t seed = 0;
  std::vector<sim::PowerToolSample> log;
  std::optional<sim::Coverage> coverage;
  std::vector<std::string> disturbances;
  /// The force plot's title ("SEED" replaced by the seed) and what its band is.
  std::string title = "Polishing: the pad's force on the workpiece (seed SEED)";
  std::string band_note = "the judge's";
};

/// The force over time, from the log's first sample to its last. @throws std::runtime_error naming the file when it
/// cannot be written.
void writeForcePlot(const ToolTrace& trace, double force, double band, const std::filesystem::path& png);
/// The coverage map. @throws std::runtime_error naming the file when it cannot be written.
void writeCoveragePlot(const ToolTrace& trace, const std::filesystem::path& png);

}  // namespace costar::trials
