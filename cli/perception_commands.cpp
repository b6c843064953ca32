#include "cli/perception_commands.h"

namespace costar::cli {

// Perception's commands arrive with perception/ (issue 4).
void addPerceptionCommands(CLI::App& /*app*/, int& /*exit_code*/) {}

}  // namespace costar::cli
