#include "testing/test_components.h"

#include <stdexcept>

namespace costar::testing {

using component::FinishedOperation;
using component::OperationResult;
using component::ParamSpec;
using component::RunningOperation;
using component::ValueType;

// --- TestLogger ------------------------------------------------------------------------

TestLogger::TestLogger() {
  component::OperationTable operations;
  operations.add({"TestLog",
                  "TEST ONLY: records a message.",
                  {{"message", ValueType::kString, "text to record", {}}},
                  component::OperationKind::kKnowledge},
                 [this](const component::ParamMap& params) {
                   std::lock_guard lock(mutex_);
                   messages_.push_back(params.at("message").asString());
                   return std::make_unique<FinishedOperation>(OperationResult::success());
                 });
  declare({.name = "test_logger", .type = "TestLogger"}, std::move(operations));
}

std::vector<std::string> TestLogger::messages() const {
  std::lock_guard lock(mutex_);
  return messages_;
}

// --- TestActions -----------------------------------------------------------------------

namespace {

class ScriptedOperation final : public RunningOperation {
 public:
  ScriptedOperation(TestActions& owner, long long polls, bool succeed, std::string reason)
      : owner_(owner), polls_left_(polls), succeed_(succeed), reason_(std::move(reason)) {}
  OperationResult poll() override {
    if (polls_left_-- > 0) {
      return OperationResult::running();
    }
    ++owner_.completions;
    return succeed_ ? OperationResult::success() : OperationResult::failure(reason_);
  }
  void cancel() override { ++owner_.cancels; }

 private:
  TestActions& owner_;
  long long polls_left_;
  bool succeed_;
  std::string reason_;
};

class ThrowingOperation final : public RunningOperation {
 public:
  OperationResult poll() override { throw std::runtime_error("simulated component fault"); }
  void cancel() override {}
};

}  // namespace

TestActions::TestActions() {
  ParamSpec result{
      "result", ValueType::kString, "what the action returns", std::string("success"), {"success", "failure"}};
  ParamSpec polls{"polls", ValueType::kInt, "polls spent RUNNING before the result", 0LL};
  polls.min = 0;
  ParamSpec reason{"reason", ValueType::kString, "failure reason", std::string("scripted failure")};
  component::OperationTable operations;
  operations.add({"TestAction", "TEST ONLY: runs for some polls, then succeeds or fails.", {result, polls, reason}},
                 [this](const component::ParamMap& params) {
                   ++starts;
                   return std::make_unique<ScriptedOperation>(*this, params.at("polls").asInt(),
                                                              params.at("result").asString() == "success",
                                                              params.at("reason").asString());
                 });
  operations.add({"TestThrow", "TEST ONLY: the component throws (a fault).", {}}, [this](const component::ParamMap&) {
    ++starts;
    return std::make_unique<ThrowingOperation>();
  });
  declare({.name = "test_actions", .type = "TestActions"}, std::move(operations));
}

// --- TestCounter -----------------------------------------------------------------------

TestCounter::TestCounter() {
  component::OperationTable operations;
  operations.add({"TestCount",
                  "TEST ONLY: adds one to a named counter.",
                  {{"counter", ValueType::kString, "counter name", {}}},
                  component::OperationKind::kKnowledge},
                 [this](const component::ParamMap& params) {
                   std::lock_guard lock(mutex_);
                   ++counters_[params.at("counter").asString()];
                   return std::make_unique<FinishedOperation>(OperationResult::success());
                 });
  declare({.name = "test_counter",
           .type = "TestCounter",
           .predicates = {{"test_count", 2, "test_count(counter, n): the counter's value is n"}}},
          std::move(operations));
}

world::Report TestCounter::report() const {
  std::lock_guard lock(mutex_);
  world::Report report;
  for (const auto& [name, value] : counters_) {
    report.predicates.push_back({"test_count", {name, std::to_string(value)}, true, ""});
  }
  return report;
}

int TestCounter::value(const std::string& counter) const {
  std::lock_guard lock(mutex_);
  const auto it = counters_.find(counter);
  return it == counters_.end() ? 0 : it->second;
}

// --- TestArm ---------------------------------------------------------------------------

namespace {

class TimedOperation final : public RunningOperation {
 public:
  TimedOperation(int polls, std::function<void()> on_done) : polls_left_(polls), on_done_(std::move(on_done)) {}
  OperationResult poll() override {
    if (polls_left_-- > 0) {
      return OperationResult::running();
    }
    on_done_();
    return OperationResult::success();
  }
  void cancel() override {}

 private:
  int polls_left_;
  std::function<void()> on_done_;
};

}  // namespace

TestArm::TestArm() {
  ParamSpec waypoint{"waypoint", ValueType::kString, "waypoint to move to", {}};
  waypoint.choices_from = "waypoint";
  component::OperationTable operations;
  operations.add({"Move", "TEST ONLY: moves the endpoint to a waypoint (3 polls).", {waypoint}},
                 [this](const component::ParamMap& params) { return move(params.at("waypoint").asString()); });
  operations.add({"Teach",
                  "TEST ONLY: saves the endpoint as a named waypoint.",
                  {{"waypoint", ValueType::kString, "name for the new waypoint", {}}},
                  component::OperationKind::kKnowledge},
                 [this](const component::ParamMap& params) {
                   std::lock_guard lock(mutex_);
                   waypoints_[params.at("waypoint").asString()] = endpoint_;
                   at_waypoint_ = params.at("waypoint").asString();
                   return std::make_unique<FinishedOperation>(OperationResult::success());
                 });
  operations.add({"SetEndpoint",
                  "TEST ONLY: jogs the endpoint to a pose.",
                  {{"pose", ValueType::kPose, "x;y;z;roll;pitch;yaw (m, deg)", {}}}},
                 [this](const component::ParamMap& params) {
                   std::lock_guard lock(mutex_);
                   endpoint_ = params.at("pose").asPose();
                   at_waypoint_.clear();
                   return std::make_unique<FinishedOperation>(OperationResult::success());
                 });
  component::ComponentDescription description;
  description.name = "test_arm";
  description.type = "TestArm";
  description.implements = {"Arm"};
  description.symbols = {{"endpoint", world::SymbolKind::kFrame, "the arm's tool frame"}};
  description.predicates = {{"at_waypoint", 1, "at_waypoint(w): the endpoint is at waypoint w"}};
  waypoints_["home"] = world::Pose(Eigen::Translation3d(0.3, 0.0, 0.5));
  declare(std::move(description), std::move(operations));
}

world::Report TestArm::report() const {
  std::lock_guard lock(mutex_);
  world::Report report;
  report.symbols.push_back({"endpoint", "", {}, world::FrameValue{"world", endpoint_}});
  for (const auto& [name, pose] : waypoints_) {
    report.symbols.push_back({name, "", {}, world::FrameValue{"world", pose}});
  }
  if (!at_waypoint_.empty()) {
    report.predicates.push_back({"at_waypoint", {at_waypoint_}, true, ""});
  }
  return report;
}

std::unique_ptr<RunningOperation> TestArm::move(const std::string& name) {
  std::lock_guard lock(mutex_);
  const auto it = waypoints_.find(name);
  if (it == waypoints_.end()) {
    return std::make_unique<FinishedOperation>(OperationResult::failure("unknown waypoint '" + name + "'"));
  }
  at_waypoint_.clear();
  const world::Pose target = it->second;
  return std::make_unique<TimedOperation>(3, [this, target, name] {
    std::lock_guard done_lock(mutex_);
    endpoint_ = target;
    at_waypoint_ = name;
  });
}

// --- OraclePerception ------------------------------------------------------------------

OraclePerception::OraclePerception(std::function<std::vector<TruePart>()> truth) : truth_(std::move(truth)) {
  declare({.name = "test_oracle_perception",
           .type = "TestOraclePerception",
           .predicates = {{"is_a", 2, "TEST ONLY: is_a(part, class) from ground truth"}}},
          {});
}

world::Report OraclePerception::report() const {
  world::Report report;
  for (const TruePart& part : truth_()) {
    report.symbols.push_back({part.name, "", {}, world::FrameValue{"world", part.pose}});
    report.predicates.push_back({"is_a", {part.name, part.object_class}, true, ""});
  }
  return report;
}

}  // namespace costar::testing
