#include "testing/test_components.h"

#include <stdexcept>

namespace costar::testing {

using component::FinishedOperation;
using component::OperationResult;
using component::OperationSpec;
using component::ParamSpec;
using component::RunningOperation;
using component::ValueType;

// --- TestLogger ------------------------------------------------------------------------

TestLogger::TestLogger() {
  description_.name = "test_logger";
  description_.type = "TestLogger";
  description_.operations = {{"TestLog",
                              "TEST ONLY: records a message.",
                              {{"message", ValueType::kString, "text to record", {}}},
                              component::OperationKind::kKnowledge}};
}

std::vector<std::string> TestLogger::messages() const {
  std::lock_guard lock(mutex_);
  return messages_;
}

std::unique_ptr<RunningOperation> TestLogger::begin(const std::string&, const component::ParamMap& params) {
  std::lock_guard lock(mutex_);
  messages_.push_back(params.at("message").asString());
  return std::make_unique<FinishedOperation>(OperationResult::success());
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
  description_.name = "test_actions";
  description_.type = "TestActions";
  ParamSpec result{
      "result", ValueType::kString, "what the action returns", std::string("success"), {"success", "failure"}};
  ParamSpec polls{"polls", ValueType::kInt, "polls spent RUNNING before the result", 0LL};
  polls.min = 0;
  ParamSpec reason{"reason", ValueType::kString, "failure reason", std::string("scripted failure")};
  description_.operations = {
      {"TestAction", "TEST ONLY: runs for some polls, then succeeds or fails.", {result, polls, reason}},
      {"TestThrow", "TEST ONLY: the component throws (a fault).", {}}};
}

std::unique_ptr<RunningOperation> TestActions::begin(const std::string& operation, const component::ParamMap& params) {
  ++starts;
  if (operation == "TestThrow") {
    return std::make_unique<ThrowingOperation>();
  }
  return std::make_unique<ScriptedOperation>(
      *this, params.at("polls").asInt(), params.at("result").asString() == "success", params.at("reason").asString());
}

// --- TestCounter -----------------------------------------------------------------------

TestCounter::TestCounter() {
  description_.name = "test_counter";
  description_.type = "TestCounter";
  description_.operations = {{"TestCount",
                              "TEST ONLY: adds one to a named counter.",
                              {{"counter", ValueType::kString, "counter name", {}}},
                              component::OperationKind::kKnowledge}};
  description_.predicates = {{"test_count", 2, "test_count(counter, n): the counter's value is n"}};
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

std::unique_ptr<RunningOperation> TestCounter::begin(const std::string&, const component::ParamMap& params) {
  std::lock_guard lock(mutex_);
  ++counters_[params.at("counter").asString()];
  return std::make_unique<FinishedOperation>(OperationResult::success());
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
  description_.name = "test_arm";
  description_.type = "TestArm";
  description_.implements = {"Arm"};
  ParamSpec waypoint{"waypoint", ValueType::kString, "waypoint to move to", {}};
  waypoint.choices_from = "waypoint";
  description_.operations = {{"Move", "TEST ONLY: moves the endpoint to a waypoint (3 polls).", {waypoint}},
                             {"Teach",
                              "TEST ONLY: saves the endpoint as a named waypoint.",
                              {{"waypoint", ValueType::kString, "name for the new waypoint", {}}},
                              component::OperationKind::kKnowledge},
                             {"SetEndpoint",
                              "TEST ONLY: jogs the endpoint to a pose.",
                              {{"pose", ValueType::kPose, "x;y;z;roll;pitch;yaw (m, deg)", {}}}}};
  description_.symbols = {{"endpoint", world::SymbolKind::kFrame, "the arm's tool frame"}};
  description_.predicates = {{"at_waypoint", 1, "at_waypoint(w): the endpoint is at waypoint w"}};
  waypoints_["home"] = world::Pose(Eigen::Translation3d(0.3, 0.0, 0.5));
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

std::unique_ptr<RunningOperation> TestArm::begin(const std::string& operation, const component::ParamMap& params) {
  std::lock_guard lock(mutex_);
  if (operation == "Teach") {
    waypoints_[params.at("waypoint").asString()] = endpoint_;
    at_waypoint_ = params.at("waypoint").asString();
    return std::make_unique<FinishedOperation>(OperationResult::success());
  }
  if (operation == "SetEndpoint") {
    endpoint_ = params.at("pose").asPose();
    at_waypoint_.clear();
    return std::make_unique<FinishedOperation>(OperationResult::success());
  }
  const std::string name = params.at("waypoint").asString();
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

}  // namespace costar::testing
