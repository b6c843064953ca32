#include <filesystem>

#include "cli/robot_binary.h"
#include "cli/workcell_access.h"
#include "workcell/described_workcell.h"

namespace costar::cli {

std::unique_ptr<workcell::Workcell> openWorkcellFor(const workcell::WorkcellOptions& options, WorkcellUse use) {
  if (auto cell = workcell::makeLightWorkcell(options)) {
    return cell;
  }
  if (!options.inject.empty() || options.faults || !options.remote.empty()) {
    runInRobotBinary();  // the fault injector and DDS live with the robot libraries
  }
  // A robot cell. Its description (written at build time by `costar-robot describe-workcell`)
  // holds its node types for the default scene; another scene may have other object classes.
  if (use == WorkcellUse::kDescribe && options.scene.empty()) {
    const std::filesystem::path file = executableDir() / "workcells" / (options.name + ".json");
    if (std::filesystem::exists(file)) {
      return workcell::makeDescribedWorkcell(workcell::loadWorkcellDescription(file), options);
    }
  }
  runInRobotBinary();
}

std::shared_ptr<faults::Injector> makeFaultInjector(const std::vector<std::string>& /*specs*/, std::uint64_t /*seed*/) {
  runInRobotBinary();  // the fault injector lives with the robot libraries
}

std::string faultSummary(const faults::Injector& /*injector*/) { return {}; }

}  // namespace costar::cli
