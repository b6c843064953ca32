#pragma once
// The components of a workcell: checks them against the abstract components they claim to
// implement, turns their operations into behavior-tree node types, and aggregates their
// symbols and predicates into the world state a plan sees.

#include <functional>
#include <map>
#include <memory>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "bt/registry.h"
#include "component/abstract.h"
#include "component/component.h"
#include "world/world_state.h"

namespace costar::component {

/// A component that cannot join the workcell: what it lacks or what collides.
class ComponentError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class ComponentRegistry {
 public:
  /// Knows the abstract Arm, Gripper and PowerTool.
  ComponentRegistry();
  ComponentRegistry(const ComponentRegistry&) = delete;
  ComponentRegistry& operator=(const ComponentRegistry&) = delete;

  void addAbstract(AbstractComponent abstract);

  /// Adds a component.
  /// @throws ComponentError if its name is taken, an operation name is offered by another
  /// component, it claims an unknown abstract component, or it lacks any operation, symbol
  /// or predicate that an abstract component it implements requires (all named).
  void add(std::shared_ptr<Component> component);

  Component* find(std::string_view name) const;
  const std::vector<std::shared_ptr<Component>>& components() const { return components_; }
  /// The component that offers `operation`, or nullptr.
  Component* provider(std::string_view operation) const;
  /// Every predicate declared by any component, by name.
  const std::map<std::string, PredicateDecl, std::less<>>& predicates() const { return predicates_; }

  /// Adds a node type per operation (ID = operation name) and the CheckPredicate condition
  /// to `nodes`. The nodes refer to this registry, which must outlive trees built from them.
  void registerNodes(bt::NodeRegistry& nodes);

  /// Pulls every component's report into world(). A predicate its source did not declare is
  /// dropped, with a warning logged once. A component whose report throws (it stopped
  /// answering, or its driver's readings cannot be trusted) stops the cell: see stopCell().
  void refreshWorld();

  /// The safety stop: from now on every operation node fails at its next tick with
  /// `reason` (cancelling its operation), and the on-stop hook runs once (the workcell stops
  /// the arm there). The first reason is kept until resetStop().
  void stopCell(const std::string& reason);
  /// Why the cell stopped; empty while it runs.
  const std::string& stopReason() const { return stop_reason_; }
  /// Clears the stop (after a person has dealt with its cause).
  void resetStop() { stop_reason_.clear(); }
  /// Called once per stop, with the reason.
  void setOnStop(std::function<void(const std::string&)> hook) { on_stop_ = std::move(hook); }
  world::WorldState& world() { return world_; }
  const world::WorldState& world() const { return world_; }

 private:
  std::map<std::string, AbstractComponent, std::less<>> abstracts_;
  std::vector<std::shared_ptr<Component>> components_;
  std::map<std::string, Component*, std::less<>> providers_;
  std::map<std::string, PredicateDecl, std::less<>> predicates_;
  std::set<std::string> warned_;
  world::WorldState world_;
  std::string stop_reason_;
  std::function<void(const std::string&)> on_stop_;
};

}  // namespace costar::component
