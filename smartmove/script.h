#pragma once
// The step engine of SmartMove's operations: a short script of steps, each an operation of
// another component (the arm's FollowJointPath, the gripper's Open and Close) started when the
// previous one succeeded, with steps that back off when a step fails (the tool lifted clear of
// a part it missed). SmartGrasp, SmartRelease and SmartPush are such scripts.

#include <cstddef>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "component/component.h"
#include "predicator/pattern.h"
#include "world/pose.h"

namespace costar::smartmove {

class Script final : public component::RunningOperation {
 public:
  struct Step {
    std::string what;
    std::function<std::unique_ptr<component::RunningOperation>()> start;
    /// Checks the step's result; empty when the script may go on.
    std::function<std::string(const component::OperationResult&)> check;
    /// A failure of this step is noted in the script's reason and the next step runs (a step
    /// of backing off that helps but is not needed, e.g. opening fingers that a part blocks).
    bool may_fail = false;
  };

  /// `data` goes with the script's result, success or failure.
  Script(std::vector<Step> steps, nlohmann::json data);

  /// When a step from `from` to `to` fails, `backing_off` steps run before the failure is
  /// reported (e.g. the tool lifted clear of a part it missed), their outcome added to it.
  void backOff(std::size_t from, std::size_t to, std::vector<Step> backing_off, std::string done_note);

  component::OperationResult poll() override;
  void cancel() override;

 private:
  /// Steps that run once the script has failed (backing off), then the failure.
  component::OperationResult fail(std::string reason, bool may_back_off = true);
  component::OperationResult finish(component::OperationResult result);

  std::vector<Step> steps_;
  std::size_t next_ = 0;
  std::unique_ptr<component::RunningOperation> current_;
  nlohmann::json data_;
  std::size_t back_off_from_ = 0;
  std::size_t back_off_to_ = 0;
  std::vector<Step> back_off_;
  std::string back_off_note_;
  std::optional<std::string> failure_;
  std::string notes_;  // failures of steps that may fail
};

/// Parses the operation's `predicates` parameter into `patterns`; the problem (prefixed
/// "predicates: ") when it cannot.
std::optional<std::string> parsePredicates(const component::ParamMap& params,
                                           std::vector<predicator::Pattern>& patterns);

/// An operation that fails at once with `reason`.
std::unique_ptr<component::RunningOperation> failed(std::string reason, nlohmann::json data = {});

/// `metres` straight up in the world (applied on the left of a pose).
inline world::Pose up(double metres) { return world::Pose(Eigen::Translation3d(0, 0, metres)); }

/// The declared defaults of `component`'s `operation`'s parameters (a gripper's speeds are in
/// its own units: m/s for a 2-finger gripper, strokes/s for the adaptive one).
component::ParamMap declaredDefaults(const component::Component& component, const std::string& operation);

}  // namespace costar::smartmove
