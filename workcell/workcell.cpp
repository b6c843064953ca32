#include "workcell/workcell.h"

#include <stdexcept>

#include "testing/test_components.h"

namespace costar::workcell {

Workcell::Workcell(std::unique_ptr<Clock> clock) : clock_(std::move(clock)), nodes_(bt::builtinRegistry()) {}

void Workcell::registerNodes() { components_.registerNodes(nodes_); }

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
  TestWorkcell() : Workcell(std::make_unique<SimClock>()) {
    components().add(std::make_shared<testing::TestLogger>());
    components().add(std::make_shared<testing::TestActions>());
    components().add(std::make_shared<testing::TestCounter>());
    components().add(std::make_shared<testing::TestArm>());
    registerNodes();
  }
  std::string name() const override { return "test"; }
  std::string description() const override {
    return "TEST ONLY: test components (logger, scripted actions, counter, an arm without a robot)";
  }
};

}  // namespace

std::vector<WorkcellInfo> knownWorkcells() {
  return {{"test", TestWorkcell().description()}, {"none", BareWorkcell().description()}};
}

std::unique_ptr<Workcell> makeWorkcell(const std::string& name) {
  if (name == "test") {
    return std::make_unique<TestWorkcell>();
  }
  if (name == "none") {
    return std::make_unique<BareWorkcell>();
  }
  std::string known;
  for (const auto& info : knownWorkcells()) {
    known += (known.empty() ? "" : ", ") + info.name;
  }
  throw std::invalid_argument("unknown workcell '" + name + "' (known: " + known + ")");
}

}  // namespace costar::workcell
