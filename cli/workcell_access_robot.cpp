#include "cli/workcell_access.h"

namespace costar::cli {

std::unique_ptr<workcell::Workcell> openWorkcellFor(const workcell::WorkcellOptions& options, WorkcellUse /*use*/) {
  return workcell::makeWorkcell(options);
}

}  // namespace costar::cli
