#include "workcell/workcell.h"

#include <algorithm>
#include <cstdlib>
#include <stdexcept>

#include "testing/test_components.h"
#include "workcell/sim_cell_description.h"

namespace costar::workcell {

Workcell::Workcell(std::unique_ptr<Clock> clock) : clock_(std::move(clock)), nodes_(bt::builtinRegistry()) {}

void Workcell::registerNodes() {
  components_.registerNodes(nodes_);
  components_.refreshWorld();
}

namespace {

std::filesystem::path stateDir() {
  if (const char* xdg = std::getenv("XDG_STATE_HOME"); xdg != nullptr && *xdg != '\0') {
    return std::filesystem::path(xdg) / "costar";
  }
  if (const char* home = std::getenv("HOME"); home != nullptr && *home != '\0') {
    return std::filesystem::path(home) / ".local" / "state" / "costar";
  }
  return "costar-state";
}

}  // namespace

std::filesystem::path defaultGraspFile(const std::string& workcell) { return stateDir() / workcell / "grasps.json"; }

component::OperationResult runOperation(Workcell& cell, const std::string& operation, const component::ParamMap& params,
                                        Duration limit,
                                        const std::function<void(const component::OperationResult&)>& progress,
                                        Duration tick) {
  component::Component* component = cell.components().provider(operation);
  if (component == nullptr) {
    throw std::invalid_argument("no component of workcell '" + cell.name() + "' offers the operation '" + operation +
                                "'");
  }
  const component::OperationSpec* spec = component->description().operation(operation);
  // Checked as plan validation checks a node's ports, before anything moves (a hostile tester's
  // `costar calibrate --views 1` moved the arm to its first view, then failed).
  for (const auto& [name, value] : params) {
    const component::ParamSpec* param = spec->param(name);
    if (param == nullptr) {
      return component::OperationResult::failure(operation + " has no parameter '" + name + "'");
    }
    if (const std::string problem = param->check(component::formatValue(value)); !problem.empty()) {
      return component::OperationResult::failure(operation + "'s " + name + ": " + problem);
    }
  }
  component::ParamMap full = params;
  for (const auto& param : spec->params) {
    if (full.find(param.name) == full.end() && param.default_value) {
      full.emplace(param.name, *param.default_value);
    }
  }
  if (const std::string problem = spec->checkParams(full); !problem.empty()) {
    return component::OperationResult::failure(operation + ": " + problem);
  }
  cell.beforeTick();
  const component::OperationId id = component->start(operation, full);
  const TimePoint end = cell.clock().now() + limit;
  for (;;) {
    const component::OperationResult result = component->poll(id);
    if (progress) {
      progress(result);
    }
    if (result.state != component::OperationState::kRunning) {
      cell.beforeTick();
      return result;
    }
    if (cell.clock().now() >= end) {
      component->cancel(id);
      return component::OperationResult::failure(operation + " did not finish within " +
                                                 std::to_string(toSeconds(limit)) + " s");
    }
    cell.clock().sleepUntil(cell.clock().now() + tick);
    cell.beforeTick();
  }
}

std::filesystem::path defaultCalibrationFile(const std::string& workcell) {
  return stateDir() / workcell / "calibration.json";
}

std::filesystem::path defaultWaypointFile(const std::string& workcell) {
  return stateDir() / workcell / "waypoints.json";
}

namespace {

constexpr const char* kTestSummary =
    "TEST ONLY: test components (logger, scripted actions, counter, an arm without a robot)";
constexpr const char* kNoneSummary = "no components: built-in nodes only";

/// Built-in nodes only: no components, simulated clock.
class BareWorkcell final : public Workcell {
 public:
  BareWorkcell() : Workcell(std::make_unique<SimClock>()) { registerNodes(); }
  std::string name() const override { return "none"; }
  std::string description() const override { return kNoneSummary; }
};

/// TEST ONLY: the components of testing/ (a logger, scripted actions, a counter, an arm
/// without a robot) on a simulated clock.
class TestWorkcell final : public Workcell {
 public:
  TestWorkcell(const ComponentWrapper& wrap, const std::function<void(const Clock&)>& attach)
      : Workcell(std::make_unique<SimClock>()) {
    if (attach) {
      attach(clock());
    }
    const auto add = [this, &wrap](std::shared_ptr<component::Component> component) {
      components().add(wrap ? wrap(std::move(component)) : std::move(component));
    };
    add(std::make_shared<testing::TestLogger>());
    add(std::make_shared<testing::TestActions>());
    add(std::make_shared<testing::TestCounter>());
    add(std::make_shared<testing::TestArm>());
    registerNodes();
  }
  std::string name() const override { return "test"; }
  std::string description() const override { return kTestSummary; }
};

}  // namespace

std::vector<WorkcellInfo> knownWorkcells() {
  // The simulated cells of workcells/*.json, the default (ur5-sim) first.
  std::vector<WorkcellInfo> cells;
  for (const auto& [name, label] : simCells()) {
    cells.push_back({name, label});
  }
  std::stable_partition(cells.begin(), cells.end(), [](const WorkcellInfo& cell) { return cell.name == "ur5-sim"; });
  cells.push_back({"test", kTestSummary});
  cells.push_back({"none", kNoneSummary});
  return cells;
}

std::string knownWorkcellNames(bool simulated_only) {
  std::string names;
  for (const WorkcellInfo& cell : knownWorkcells()) {
    if (!simulated_only || (cell.name != "test" && cell.name != "none")) {
      names += (names.empty() ? "" : ", ") + cell.name;
    }
  }
  return names;
}

std::unique_ptr<Workcell> makeTestWorkcell(const ComponentWrapper& wrap,
                                           const std::function<void(const Clock&)>& attach) {
  return std::make_unique<TestWorkcell>(wrap, attach);
}

std::unique_ptr<Workcell> makeBareWorkcell() { return std::make_unique<BareWorkcell>(); }

void refuseSimulationOptionsOfLightCells(const WorkcellOptions& options) {
  if ((options.name == "test" || options.name == "none") && (!options.scene.empty() || options.camera_move)) {
    // A hostile tester's `-w none --scene bad.json` ran without a word about the scene.
    throw std::invalid_argument("the '" + options.name + "' workcell has no simulation: " +
                                (options.scene.empty() ? "--camera-move" : "a scene (--scene)") +
                                " applies to the simulated cells only (" + knownWorkcellNames(true) + ")");
  }
}

std::unique_ptr<Workcell> makeLightWorkcell(const WorkcellOptions& options) {
  const std::string& name = options.name;
  if (options.faults || !options.inject.empty() || !options.remote.empty()) {
    return nullptr;  // faults and remote components: makeWorkcell (costar_workcell links them)
  }
  if (name == "test") {
    return std::make_unique<TestWorkcell>(ComponentWrapper{}, nullptr);
  }
  if (name == "none") {
    return std::make_unique<BareWorkcell>();
  }
  requireKnownWorkcell(name);
  return nullptr;  // a robot cell: makeWorkcell() builds it
}

void requireKnownWorkcell(const std::string& name) {
  std::string known;
  for (const auto& info : knownWorkcells()) {
    if (info.name == name) {
      return;
    }
    known += (known.empty() ? "" : ", ") + info.name;
  }
  throw std::invalid_argument("unknown workcell '" + name + "' (known: " + known + ")");
}

}  // namespace costar::workcell
