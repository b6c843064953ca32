#include "cli/workcell_access.h"

#include "faults/injector.h"

namespace costar::cli {

std::unique_ptr<workcell::Workcell> openWorkcellFor(const workcell::WorkcellOptions& options, WorkcellUse /*use*/) {
  return workcell::makeWorkcell(options);
}

std::shared_ptr<faults::Injector> makeFaultInjector(const std::vector<std::string>& specs, std::uint64_t seed) {
  return faults::Injector::fromText(specs, seed);
}

std::string faultSummary(const faults::Injector& injector) { return injector.summary(); }

}  // namespace costar::cli
