#pragma once
// TEST-ONLY components: they stand in for robots in the engine's tests, the CLI's tests and
// the examples under examples/test_workcell/. No robot, no physics: a real workcell uses the
// simulated UR5 (sim/) or hardware.

#include <atomic>
#include <functional>
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include "component/operation_table.h"

namespace costar::testing {

/// "test_logger": TestLog(message) records the message and succeeds at once.
class TestLogger final : public component::TableComponent {
 public:
  TestLogger();
  world::Report report() const override { return {}; }
  std::vector<std::string> messages() const;

 private:
  mutable std::mutex mutex_;
  std::vector<std::string> messages_;
};

/// "test_actions": TestAction(result, polls, reason) stays RUNNING for `polls` polls, then
/// returns `result`; TestThrow throws when polled (a component fault). Counts what happens.
class TestActions final : public component::TableComponent {
 public:
  TestActions();
  world::Report report() const override { return {}; }

  std::atomic<int> starts{0};
  std::atomic<int> cancels{0};
  std::atomic<int> completions{0};
};

/// "test_counter": TestCount(counter) adds one to a named counter. Predicate
/// test_count(counter, value) holds for each counter's current value.
class TestCounter final : public component::TableComponent {
 public:
  TestCounter();
  world::Report report() const override;
  int value(const std::string& counter) const;

 private:
  mutable std::mutex mutex_;
  std::map<std::string, int> counters_;
};

/// "test_arm": implements the abstract Arm without a robot. Move(waypoint) takes 3 polls
/// and sets the endpoint to the waypoint; Teach(name) stores the endpoint as a waypoint.
/// Symbols: endpoint and every waypoint; predicate at_waypoint(name).
class TestArm final : public component::TableComponent {
 public:
  TestArm();
  world::Report report() const override;

 private:
  std::unique_ptr<component::RunningOperation> move(const std::string& waypoint);

  mutable std::mutex mutex_;
  world::Pose endpoint_ = world::Pose::Identity();
  std::string at_waypoint_;
  std::map<std::string, world::Pose> waypoints_;
};

/// A part as the simulator has it (for OraclePerception).
struct TruePart {
  std::string name;
  std::string object_class;
  world::Pose pose = world::Pose::Identity();
};

/// "test_oracle_perception": the simulator's true part poses as object symbols and
/// is_a(part, class), standing in for perception when SmartMove is tested apart from it (a
/// simulated cell made with WorkcellOptions::test_oracle_perception). `truth` gives the parts
/// now. No operations.
class OraclePerception final : public component::TableComponent {
 public:
  explicit OraclePerception(std::function<std::vector<TruePart>()> truth);
  world::Report report() const override;

 private:
  std::function<std::vector<TruePart>()> truth_;
};

}  // namespace costar::testing
