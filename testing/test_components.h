#pragma once
// TEST-ONLY components: they stand in for robots in the engine's tests, the CLI's tests and
// the examples under examples/test_workcell/. No robot, no physics: a real workcell uses the
// simulated UR5 (sim/) or hardware.

#include <atomic>
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include "component/component.h"

namespace costar::testing {

/// "test_logger": TestLog(message) records the message and succeeds at once.
class TestLogger final : public component::LocalComponent {
 public:
  TestLogger();
  const component::ComponentDescription& description() const override { return description_; }
  world::Report report() const override { return {}; }
  std::vector<std::string> messages() const;

 private:
  std::unique_ptr<component::RunningOperation> begin(const std::string& operation,
                                                     const component::ParamMap& params) override;
  component::ComponentDescription description_;
  mutable std::mutex mutex_;
  std::vector<std::string> messages_;
};

/// "test_actions": TestAction(result, polls, reason) stays RUNNING for `polls` polls, then
/// returns `result`; TestThrow throws when polled (a component fault). Counts what happens.
class TestActions final : public component::LocalComponent {
 public:
  TestActions();
  const component::ComponentDescription& description() const override { return description_; }
  world::Report report() const override { return {}; }

  std::atomic<int> starts{0};
  std::atomic<int> cancels{0};
  std::atomic<int> completions{0};

 private:
  std::unique_ptr<component::RunningOperation> begin(const std::string& operation,
                                                     const component::ParamMap& params) override;
  component::ComponentDescription description_;
};

/// "test_counter": TestCount(counter) adds one to a named counter. Predicate
/// test_count(counter, value) holds for each counter's current value.
class TestCounter final : public component::LocalComponent {
 public:
  TestCounter();
  const component::ComponentDescription& description() const override { return description_; }
  world::Report report() const override;
  int value(const std::string& counter) const;

 private:
  std::unique_ptr<component::RunningOperation> begin(const std::string& operation,
                                                     const component::ParamMap& params) override;
  component::ComponentDescription description_;
  mutable std::mutex mutex_;
  std::map<std::string, int> counters_;
};

/// "test_arm": implements the abstract Arm without a robot. Move(waypoint) takes 3 polls
/// and sets the endpoint to the waypoint; Teach(name) stores the endpoint as a waypoint.
/// Symbols: endpoint and every waypoint; predicate at_waypoint(name).
class TestArm final : public component::LocalComponent {
 public:
  TestArm();
  const component::ComponentDescription& description() const override { return description_; }
  world::Report report() const override;

 private:
  std::unique_ptr<component::RunningOperation> begin(const std::string& operation,
                                                     const component::ParamMap& params) override;
  component::ComponentDescription description_;
  mutable std::mutex mutex_;
  world::Pose endpoint_ = world::Pose::Identity();
  std::string at_waypoint_;
  std::map<std::string, world::Pose> waypoints_;
};

}  // namespace costar::testing
