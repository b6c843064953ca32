#pragma once
// A CoSTAR component C = <I, O, p, s, u> (the paper, Sec. III-A): continuous input and
// output data, the predicates p and symbols s it produces, and the operations u it offers.
//
// Operations are asynchronous (start -> poll -> cancel) and identified by a number, with
// parameters and results that serialize to JSON: a component behaves the same whether it
// runs in the executor's process or behind a process boundary.

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "component/value.h"
#include "world/world_state.h"

namespace costar::component {

/// How the editor shows an operation (the paper's Fig. 5 colours).
enum class OperationKind {
  kRobotAction,  // acts on the world: green
  kKnowledge,    // updates or queries knowledge (DetectObjects, ...): purple
  /// For other components only (SmartMove moves the arm along a path it planned): no node type,
  /// not offered to plans or in the editor.
  kInternal,
};

struct OperationSpec {
  std::string name;
  std::string description;
  std::vector<ParamSpec> params;
  OperationKind kind = OperationKind::kRobotAction;
  /// Checks across parameters that would make the operation fail at once (a grasp not taught
  /// for the chosen class, a place with neither target): empty when valid, else the problem.
  /// Plan validation (the editor's Check, costar run) calls it with every port's value.
  std::function<std::string(const ParamMap& params)> check;

  const ParamSpec* param(std::string_view param_name) const;
  /// The checks across parameters: every `less_than` of its parameters, then `check`. Empty
  /// when valid, else the first problem.
  std::string checkParams(const ParamMap& values) const;
  /// Whether checkParams has anything to check.
  bool checksAcrossParams() const;
};

struct SymbolDecl {
  std::string name;
  world::SymbolKind kind = world::SymbolKind::kFrame;
  std::string description;
};

struct PredicateDecl {
  std::string name;
  /// Number of arguments (symbol names).
  std::size_t arity = 0;
  std::string description;
  /// Its arguments are numbers (force_above(15): newtons), not symbol names: plans are checked
  /// for a finite number of 0 or more.
  bool numeric_arguments = false;
};

/// Everything a component declares about itself.
struct ComponentDescription {
  /// Instance name, unique in a workcell ("arm", "gripper").
  std::string name;
  /// Concrete type ("UR5", "Robotiq2F85").
  std::string type;
  /// Abstract components it implements ("Arm"); their requirements are checked.
  std::vector<std::string> implements;
  /// Continuous input and output streams (I and O); never seen by task plans.
  std::vector<std::string> inputs;
  std::vector<std::string> outputs;
  std::vector<OperationSpec> operations;
  std::vector<SymbolDecl> symbols;
  std::vector<PredicateDecl> predicates;

  const OperationSpec* operation(std::string_view operation_name) const;
};

enum class OperationState { kRunning, kSuccess, kFailure };
const char* toString(OperationState state);

struct OperationResult {
  OperationState state = OperationState::kRunning;
  /// Why it failed (or what happened), in words a user can act on.
  std::string reason;
  /// Structured detail, e.g. SmartMove's candidates with costs and rejection reasons.
  nlohmann::json data;

  static OperationResult running() { return {}; }
  static OperationResult success(nlohmann::json data = {}) { return {OperationState::kSuccess, {}, std::move(data)}; }
  static OperationResult failure(std::string reason, nlohmann::json data = {}) {
    return {OperationState::kFailure, std::move(reason), std::move(data)};
  }
};

nlohmann::json toJson(const OperationResult& result);
OperationResult resultFromJson(const nlohmann::json& json);

using OperationId = std::uint64_t;

class Component {
 public:
  Component() = default;
  Component(const Component&) = delete;
  Component& operator=(const Component&) = delete;
  virtual ~Component() = default;

  virtual const ComponentDescription& description() const = 0;

  /// Starts `operation` (declared in description()) with parameters already checked against
  /// its ParamSpecs. @throws std::exception when it cannot start; the message is the reason.
  virtual OperationId start(const std::string& operation, const ParamMap& params) = 0;
  /// State of a started operation. Once it is SUCCESS or FAILURE the id is forgotten.
  /// @throws std::exception for an unknown id.
  virtual OperationResult poll(OperationId id) = 0;
  /// Stops an operation; the robot decelerates and stops. Unknown ids are ignored.
  virtual void cancel(OperationId id) = 0;

  /// The component's current symbols and predicates.
  virtual world::Report report() const = 0;
};

/// One started operation of a LocalComponent.
class RunningOperation {
 public:
  virtual ~RunningOperation() = default;
  virtual OperationResult poll() = 0;
  virtual void cancel() = 0;
};

/// An operation whose result is known when it starts.
class FinishedOperation final : public RunningOperation {
 public:
  explicit FinishedOperation(OperationResult result) : result_(std::move(result)) {}
  OperationResult poll() override { return result_; }
  void cancel() override {}

 private:
  OperationResult result_;
};

/// An operation of another component, started now, followed as one's own (SmartMove moves the
/// arm with its FollowJointPath, Calibrate likewise): poll and cancel go to that component.
/// @throws std::exception from the constructor when the operation cannot start.
class DelegatedOperation final : public RunningOperation {
 public:
  DelegatedOperation(Component& component, const std::string& operation, const ParamMap& params)
      : component_(component), id_(component.start(operation, params)) {}
  OperationResult poll() override { return component_.poll(id_); }
  void cancel() override { component_.cancel(id_); }

 private:
  Component& component_;
  OperationId id_;
};

/// Base for components living in the executor's process: keeps the id bookkeeping, so a
/// subclass only creates RunningOperation objects. Thread-safe.
class LocalComponent : public Component {
 public:
  OperationId start(const std::string& operation, const ParamMap& params) final;
  OperationResult poll(OperationId id) final;
  void cancel(OperationId id) final;

 protected:
  /// Creates the operation. @throws std::exception when it cannot start.
  virtual std::unique_ptr<RunningOperation> begin(const std::string& operation, const ParamMap& params) = 0;

 private:
  std::mutex mutex_;
  std::map<OperationId, std::unique_ptr<RunningOperation>> running_;
  OperationId next_id_ = 1;
};

}  // namespace costar::component
