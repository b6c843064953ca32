#pragma once
// A workcell: the clock, the components and the node types a plan runs against. The CLI
// and the server pick one by name ("test" today; the simulated UR5 cell comes with sim/).

#include <memory>
#include <string>
#include <vector>

#include "bt/registry.h"
#include "component/registry.h"
#include "core/clock.h"

namespace costar::workcell {

class Workcell {
 public:
  Workcell(const Workcell&) = delete;
  Workcell& operator=(const Workcell&) = delete;
  virtual ~Workcell() = default;

  virtual std::string name() const = 0;
  virtual std::string description() const = 0;

  Clock& clock() { return *clock_; }
  component::ComponentRegistry& components() { return components_; }
  /// Built-in nodes plus one node type per operation of the components.
  const bt::NodeRegistry& nodes() const { return nodes_; }

  /// Called by the executor before every tick: refreshes the world state.
  virtual void beforeTick() { components_.refreshWorld(); }

 protected:
  explicit Workcell(std::unique_ptr<Clock> clock);
  /// Call once the components are added: registers their node types.
  void registerNodes();

 private:
  std::unique_ptr<Clock> clock_;
  component::ComponentRegistry components_;
  bt::NodeRegistry nodes_;
};

struct WorkcellInfo {
  std::string name;
  std::string description;
};

/// The workcells this build knows.
std::vector<WorkcellInfo> knownWorkcells();

/// Creates a workcell by name. @throws std::invalid_argument naming the known ones.
std::unique_ptr<Workcell> makeWorkcell(const std::string& name);

}  // namespace costar::workcell
