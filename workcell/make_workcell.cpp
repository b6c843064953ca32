// makeWorkcell: the light cells from costar_workcell_base, the robot cells from here.

#include <stdexcept>

#include "faults/injector.h"
#include "workcell/grippers.h"
#include "workcell/sim_cell_description.h"
#include "workcell/sim_workcell.h"
#include "workcell/workcell.h"

namespace costar::workcell {

std::unique_ptr<Workcell> makeWorkcell(const WorkcellOptions& given) {
  WorkcellOptions options = given;
  if (!options.faults && !options.inject.empty()) {
    options.faults = faults::Injector::fromText(options.inject, options.seed.value_or(1));
  }
  if (options.faults && options.name == "test") {
    const std::shared_ptr<faults::Injector> faults = options.faults;
    auto cell = makeTestWorkcell([&faults](auto component) { return faults->wrap(std::move(component)); },
                                 [&faults](const Clock& clock) { faults->attach(clock); });
    faults->checkTargets();
    return cell;
  }
  if (options.faults && options.name == "none") {
    options.faults->checkTargets();  // it has nothing that can fail
    return makeBareWorkcell();
  }
  WorkcellOptions light = options;
  light.faults = nullptr;
  light.inject.clear();
  if (auto cell = makeLightWorkcell(light)) {
    return cell;
  }
  // A robot cell makeLightWorkcell knows by name: a simulated cell of workcells/NAME.json.
  const SimCellDescription cell = loadSimCellDescription(simCellFile(options.name));
  try {
    gripperModel(cell.gripper);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error("workcell description '" + cell.file.string() + "': gripper: " + e.what());
  }
  return makeSimWorkcell(cell, options);
}

}  // namespace costar::workcell
