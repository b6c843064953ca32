#pragma once
// Leaves that connect the behavior tree to components: OperationNode runs an operation of a
// component; PredicateCondition tests a predicate of the world state.

#include <functional>
#include <nlohmann/json.hpp>

#include "bt/node.h"
#include "component/component.h"

namespace costar::component {

/// Starts its operation on the first tick of a run, polls it on later ticks, and cancels it
/// when halted. An exception from the component becomes a FAILURE with its message.
/// `on_completion` runs when the operation completes, before the next node is ticked (the
/// registry refreshes the world state there, so a condition right after sees the effect).
/// `stopped` says why the cell stopped (empty while it runs): then the node cancels its
/// operation and fails with that reason instead of starting or polling it.
class OperationNode final : public bt::LeafNode {
 public:
  OperationNode(std::string id, std::string name, Component& component, ParamMap params,
                std::function<void()> on_completion = {}, std::function<std::string()> stopped = {});
  const ParamMap& params() const { return params_; }
  /// The last result reported by the operation (reason, data), for observers.
  const OperationResult& lastResult() const { return last_result_; }

 private:
  bt::Status onTick() override;
  void onHalt() override;
  bt::Status finish(OperationResult result);

  Component& component_;
  ParamMap params_;
  std::function<void()> on_completion_;
  std::function<std::string()> stopped_;
  OperationResult last_result_;
  OperationId operation_ = 0;
  bool active_ = false;
};

/// SUCCESS when predicate(args) holds (or does not hold, with expected=false), else FAILURE
/// naming the predicate. Never RUNNING.
class PredicateCondition final : public bt::LeafNode {
 public:
  PredicateCondition(std::string id, std::string name, const world::WorldState& world, std::string predicate,
                     std::vector<std::string> args, bool expected);

 private:
  bt::Status onTick() override;

  const world::WorldState& world_;
  std::string predicate_;
  std::vector<std::string> args_;
  bool expected_;
  bool wildcard_ = false;
  std::string failure_text_;
};

}  // namespace costar::component
