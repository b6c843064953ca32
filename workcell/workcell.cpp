#include "workcell/workcell.h"

#include <stdexcept>

#include <cstdlib>

#include "faults/injector.h"
#include "testing/test_components.h"
#include "workcell/ur5_sim_workcell.h"

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

std::filesystem::path defaultWaypointFile(const std::string& workcell) {
  return stateDir() / workcell / "waypoints.json";
}

namespace {

/// Built-in nodes only: no components, simulated clock.
class BareWorkcell final : public Workcell {
 public:
  BareWorkcell() : Workcell(std::make_unique<SimClock>()) { registerNodes(); }
  std::string name() const override { return "none"; }
  std::string description() const override { return "no components: built-in nodes only"; }
};

/// TEST ONLY: the components of testing/ (a logger, scripted actions, a counter, an arm
/// without a robot) on a simulated clock.
class TestWorkcell final : public Workcell {
 public:
  explicit TestWorkcell(std::shared_ptr<faults::Injector> faults = {})
      : Workcell(std::make_unique<SimClock>()), faults_(std::move(faults)) {
    if (faults_) {
      faults_->attach(clock());
    }
    const auto add = [this](std::shared_ptr<component::Component> component) {
      components().add(faults_ ? faults_->wrap(std::move(component)) : std::move(component));
    };
    add(std::make_shared<testing::TestLogger>());
    add(std::make_shared<testing::TestActions>());
    add(std::make_shared<testing::TestCounter>());
    add(std::make_shared<testing::TestArm>());
    if (faults_) {
      faults_->checkTargets();
    }
    registerNodes();
  }
  std::string name() const override { return "test"; }
  std::string description() const override {
    return "TEST ONLY: test components (logger, scripted actions, counter, an arm without a robot)";
  }

 private:
  std::shared_ptr<faults::Injector> faults_;
};

}  // namespace

std::vector<WorkcellInfo> knownWorkcells() {
  return {{"ur5-sim", "simulated UR5 with a 2-finger gripper and an RGB-D camera (MuJoCo); the default"},
          {"test", TestWorkcell().description()},
          {"none", BareWorkcell().description()}};
}

std::unique_ptr<Workcell> makeWorkcell(const WorkcellOptions& options) {
  const std::string& name = options.name;
  if (name == "ur5-sim") {
    return makeUr5SimWorkcell(options);
  }
  if (name == "test") {
    return std::make_unique<TestWorkcell>(options.faults);
  }
  if (name == "none") {
    if (options.faults) {
      options.faults->checkTargets();  // it has nothing that can fail
    }
    return std::make_unique<BareWorkcell>();
  }
  std::string known;
  for (const auto& info : knownWorkcells()) {
    known += (known.empty() ? "" : ", ") + info.name;
  }
  throw std::invalid_argument("unknown workcell '" + name + "' (known: " + known + ")");
}

}  // namespace costar::workcell
