// The receiving side: what keeps the cell safe when something breaks. An operation that
// throws, a component that stops answering or dies, a driver whose readings are NaN or stop
// updating: each ends the run as FAILURE with the node's path and a reason naming the broken
// part, within one tick of the fault taking effect.

#include <gtest/gtest.h>

#include <cmath>

#include "bt/builder.h"
#include "bt/executor.h"
#include "bt/plan_xml.h"
#include "faults/injector.h"
#include "faults/test/fakes.h"
#include "gripper/parallel_gripper.h"
#include "workcell/workcell.h"

namespace costar::faults {
namespace {

constexpr const char* kLongAction = R"(<root BTCPP_format="4" main_tree_to_execute="main">
  <BehaviorTree ID="main">
    <Sequence name="job">
      <TestLog message="start"/>
      <TestAction name="long work" polls="300"/>
    </Sequence>
  </BehaviorTree>
</root>)";

struct Outcome {
  bt::RunResult run;
  std::shared_ptr<Injector> faults;
};

Outcome runOnTestCell(const std::string& fault) {
  Outcome outcome;
  outcome.faults = Injector::fromText({fault}, 1);
  const auto cell = workcell::makeWorkcell({.name = "test", .faults = outcome.faults});
  bt::Tree tree = bt::buildTree(bt::loadPlanText(kLongAction, "long.xml"), cell->nodes(), cell->clock());
  bt::Executor executor(tree, cell->clock(), {.time_limit = std::chrono::seconds(10)});
  executor.setBeforeTick([&cell] { cell->beforeTick(); });
  outcome.run = executor.run();
  return outcome;
}

void expectStoppedInTime(const Outcome& outcome, const std::string& words) {
  EXPECT_EQ(outcome.run.status, bt::Status::kFailure);
  EXPECT_NE(outcome.run.failure_path.find("long work"), std::string::npos) << outcome.run.failure_path;
  EXPECT_NE(outcome.run.failure_reason.find(words), std::string::npos) << outcome.run.failure_reason;
  const FaultRecord& record = outcome.faults->records().front();
  ASSERT_TRUE(record.first_effect);
  const double latency = toSeconds(outcome.run.elapsed) - toSeconds(*record.first_effect);
  EXPECT_GE(latency, 0.0);
  EXPECT_LE(latency, 0.02);  // one tick at 100 Hz, or the same tick
}

TEST(ReceivingSide, AnOperationThatThrowsFailsItsNode) {
  expectStoppedInTime(runOnTestCell("throw:test_actions@t=0.5s"), "threw an exception");
}

TEST(ReceivingSide, AComponentThatStopsAnsweringFailsTheRunningNode) {
  expectStoppedInTime(runOnTestCell("hang:test_actions@t=0.5s"), "'test_actions' did not answer");
}

TEST(ReceivingSide, AnyComponentThatDiesStopsTheCell) {
  // test_counter runs nothing: its death is seen in its report and stops the whole cell.
  expectStoppedInTime(runOnTestCell("die:test_counter@t=1.25s"), "the cell stopped: component 'test_counter'");
  expectStoppedInTime(runOnTestCell("hang:test_logger@t=0.7s"), "the cell stopped: component 'test_logger'");
}

TEST(ReceivingSide, AFaultAfterTheEndTakesNoEffect) {
  const Outcome outcome = runOnTestCell("die:test_counter@t=9s");
  EXPECT_EQ(outcome.run.status, bt::Status::kSuccess);
  EXPECT_FALSE(outcome.faults->records().front().activated);
}

TEST(ReceivingSide, TheTestCellRefusesATargetItLacks) {
  EXPECT_THROW(workcell::makeWorkcell({.name = "test", .faults = Injector::fromText({"nan:arm-driver@t=1"}, 1)}),
               FaultSpecError);
}

/// The gripper's readings are checked: NaN, stale or failing readings make its report throw
/// (the registry stops the cell) and fail a finger motion with the reason.
TEST(ReceivingSide, TheGripperDistrustsBadReadings) {
  for (const std::string fault :
       {"nan:gripper-driver@t=0.1s", "hang:gripper-driver@t=0.1s", "throw:gripper-driver@t=0.1s"}) {
    SimClock clock;
    test::GoodFingers fingers(clock);
    auto faults = Injector::fromText({fault}, 1);
    faults->attach(clock);
    gripper::ParallelGripper gripper(faults->wrap(fingers), clock);
    clock.advanceTo(TimePoint(std::chrono::milliseconds(80)));
    EXPECT_NO_THROW(gripper.report());
    // The fake fingers do not move: Close would settle at 0.19 s, after the fault shows.
    const component::OperationId id = gripper.start("Close", {{"speed", 0.1}, {"force", 40.0}});
    component::OperationResult result;
    for (int i = 0; i < 100; ++i) {
      clock.advanceBy(std::chrono::milliseconds(10));
      result = gripper.poll(id);
      if (result.state != component::OperationState::kRunning) {
        break;
      }
    }
    EXPECT_EQ(result.state, component::OperationState::kFailure) << fault;
    EXPECT_NE(result.reason.find("gripper driver"), std::string::npos) << fault << ": " << result.reason;
    // Detected within the reading timeout (50 ms) of the fault.
    EXPECT_LE(toSeconds(clock.now()), 0.1 + 0.05 + 0.011) << fault;
    EXPECT_THROW(gripper.report(), std::runtime_error) << fault;
  }
}

}  // namespace
}  // namespace costar::faults
