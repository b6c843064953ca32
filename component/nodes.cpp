#include "component/nodes.h"

#include <algorithm>

namespace costar::component {

OperationNode::OperationNode(std::string id, std::string name, Component& component, ParamMap params,
                             std::function<void()> on_completion, std::function<std::string()> stopped)
    : bt::LeafNode(std::move(id), std::move(name)),
      component_(component),
      params_(std::move(params)),
      on_completion_(std::move(on_completion)),
      stopped_(std::move(stopped)) {}

bt::Status OperationNode::finish(OperationResult result) {
  active_ = false;
  last_result_ = std::move(result);
  if (on_completion_) {
    on_completion_();
  }
  if (last_result_.state == OperationState::kSuccess) {
    return bt::Status::kSuccess;
  }
  return fail(last_result_.reason.empty() ? id() + " failed without giving a reason" : last_result_.reason);
}

bt::Status OperationNode::onTick() {
  if (stopped_) {
    if (const std::string reason = stopped_(); !reason.empty()) {
      onHalt();  // cancels the operation, best effort
      return finish(OperationResult::failure("the cell stopped: " + reason));
    }
  }
  if (!active_) {
    try {
      operation_ = component_.start(id(), params_);
      active_ = true;
    } catch (const std::exception& e) {
      return finish(OperationResult::failure(std::string("could not start: ") + e.what()));
    }
  }
  OperationResult result;
  try {
    result = component_.poll(operation_);
  } catch (const std::exception& e) {
    onHalt();  // the operation may still be running (a motion): cancel it, best effort
    return finish(OperationResult::failure(component_.description().name + " failed: " + e.what()));
  }
  if (result.state == OperationState::kRunning) {
    last_result_ = std::move(result);
    return bt::Status::kRunning;
  }
  return finish(std::move(result));
}

void OperationNode::onHalt() {
  if (active_) {
    active_ = false;
    try {
      component_.cancel(operation_);
    } catch (const std::exception&) {
      // Cancelling is best effort: the component is gone or the operation already ended.
    }
  }
}

PredicateCondition::PredicateCondition(std::string id, std::string name, const world::WorldState& world,
                                       std::string predicate, std::vector<std::string> args, bool expected)
    : bt::LeafNode(std::move(id), std::move(name)),
      world_(world),
      predicate_(std::move(predicate)),
      args_(std::move(args)),
      expected_(expected) {
  wildcard_ = std::find(args_.begin(), args_.end(), world::WorldState::kWildcard) != args_.end();
  const std::string key = world::predicateKey(predicate_, args_);
  failure_text_ = wildcard_ ? (expected_ ? "no symbol satisfies " + key : "some symbol satisfies " + key)
                            : key + (expected_ ? " is false" : " is true");
}

bt::Status PredicateCondition::onTick() {
  const bool holds = wildcard_ ? !world_.match(predicate_, args_).empty() : world_.holds(predicate_, args_);
  if (holds == expected_) {
    return bt::Status::kSuccess;
  }
  return fail(failure_text_);
}

}  // namespace costar::component
