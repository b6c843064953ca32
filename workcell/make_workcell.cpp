// makeWorkcell: the light cells from costar_workcell_base, the robot cells from here.

#include <chrono>
#include <set>
#include <stdexcept>

#include "core/json_file.h"
#include "dds/remote_component.h"
#include "faults/injector.h"
#include "workcell/grippers.h"
#include "workcell/sim_cell_description.h"
#include "workcell/sim_workcell.h"
#include "workcell/workcell.h"

namespace costar::workcell {
namespace {

/// How long the executor waits for the host of a remote component when the cell is built.
constexpr std::chrono::seconds kHostWait{5};

/// The "test" cell with the components named in `options.remote` served by hosts elsewhere
/// (a simulated cell's are in lockstep with its simulation: workcell/sim_workcell.cpp):
/// proxies (dds::RemoteComponent) in their place, wrapped by the fault injector like the others.
std::unique_ptr<Workcell> makeCellWithRemoteComponents(const WorkcellOptions& options) {
  const std::string where = options.remote.string();
  if (options.name != "test") {
    throw std::invalid_argument(where + ": the '" + options.name + "' cell has no components to serve elsewhere");
  }
  nlohmann::json json;
  try {
    json = core::readJsonFile(options.remote);
  } catch (const core::JsonSyntaxError& error) {
    throw std::invalid_argument(where + ": " + error.what());
  }
  const dds::RemoteConfig remote = dds::remoteConfigFromJson(json, where);
  const auto client = dds::RemoteClient::create(remote);
  std::set<std::string> found;
  const std::shared_ptr<faults::Injector> faults = options.faults;
  auto cell = makeTestWorkcell(
      [&](std::shared_ptr<component::Component> component) {
        const std::string name = component->description().name;
        if (remote.isRemote(name)) {
          found.insert(name);
          component = client->connect(name, kHostWait);
        }
        return faults ? faults->wrap(std::move(component)) : component;
      },
      [&faults](const Clock& clock) {
        if (faults) {
          faults->attach(clock);
        }
      });
  for (const auto& name : remote.components) {
    if (!found.contains(name)) {
      throw std::invalid_argument(where + ": components: the " + options.name + " cell has no component '" + name +
                                  "'");
    }
  }
  if (faults) {
    faults->checkTargets();
  }
  return cell;
}

}  // namespace

std::unique_ptr<Workcell> makeWorkcell(const WorkcellOptions& given) {
  WorkcellOptions options = given;
  if (!options.faults && !options.inject.empty()) {
    options.faults = faults::Injector::fromText(options.inject, options.seed.value_or(1));
  }
  if (!options.remote.empty() && (options.name == "test" || options.name == "none")) {
    return makeCellWithRemoteComponents(options);
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
