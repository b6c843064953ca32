// Semantics of every built-in node: what it returns, what it ticks, what it halts, what a
// FAILURE says. docs/BEHAVIOR_TREES.md is the table these tests check.

#include <gtest/gtest.h>

#include "bt/test/test_support.h"

namespace costar::bt {
namespace {

using testing::TestTree;
using Events = std::vector<std::string>;

Status tickUntilDone(TestTree& t, int max_ticks = 1000) {
  for (int i = 0; i < max_ticks; ++i) {
    const Status status = t.tree.tick();
    if (isCompleted(status)) {
      return status;
    }
    t.clock.advanceBy(std::chrono::milliseconds(10));
  }
  return Status::kRunning;
}

// --- Sequence ---------------------------------------------------------------------------

TEST(Sequence, SucceedsWhenEveryChildSucceedsInOneTick) {
  TestTree t(R"(<Sequence><TestLeaf name="a"/><TestLeaf name="b"/></Sequence>)");
  EXPECT_EQ(t.tree.tick(), Status::kSuccess);
  EXPECT_EQ(t.log.events, (Events{"a:start", "a:success", "b:start", "b:success"}));
  // Completed children are back to IDLE for the next run.
  for (const TreeNode* node : t.tree.nodes()) {
    if (node != &t.tree.root()) {
      EXPECT_EQ(node->status(), Status::kIdle) << node->path();
    }
  }
}

TEST(Sequence, ResumesAtTheRunningChildWithoutRetickingEarlierOnes) {
  TestTree t(R"(<Sequence><TestLeaf name="a"/><TestLeaf name="b" ticks="2"/></Sequence>)");
  EXPECT_EQ(t.tree.tick(), Status::kRunning);
  EXPECT_EQ(t.tree.tick(), Status::kRunning);
  EXPECT_EQ(t.tree.tick(), Status::kSuccess);
  EXPECT_EQ(t.log.count("a:start"), 1);
  EXPECT_EQ(t.log.count("b:start"), 1);
}

TEST(Sequence, FailureCarriesTheFailingChildsPathAndReasonAndRestartsNextRun) {
  TestTree t(R"(<Sequence><TestLeaf name="a"/>
                <TestLeaf name="grasp" results="failure;success" reason="no reachable candidate"/>
                <TestLeaf name="c"/></Sequence>)");
  EXPECT_EQ(t.tree.tick(), Status::kFailure);
  EXPECT_EQ(t.tree.root().failureOrigin().path(), R"(main/Sequence[1]/TestLeaf "grasp")");
  EXPECT_EQ(t.tree.root().failureReason(), "no reachable candidate");
  EXPECT_EQ(t.log.count("c:start"), 0);
  EXPECT_EQ(t.tree.tick(), Status::kSuccess);  // restarts from the first child
  EXPECT_EQ(t.log.count("a:start"), 2);
}

TEST(Sequence, HaltCancelsTheRunningChildAndRestartsFromTheFirst) {
  TestTree t(R"(<Sequence><TestLeaf name="a"/><TestLeaf name="b" ticks="5"/></Sequence>)");
  EXPECT_EQ(t.tree.tick(), Status::kRunning);
  t.tree.halt();
  EXPECT_EQ(t.log.count("b:halt"), 1);
  EXPECT_EQ(t.tree.root().status(), Status::kIdle);
  EXPECT_EQ(t.tree.tick(), Status::kRunning);
  EXPECT_EQ(t.log.count("a:start"), 2);
}

// --- SequenceWithMemory -------------------------------------------------------------------

TEST(SequenceWithMemory, RetriesTheFailedChildWithoutRedoingEarlierOnes) {
  TestTree t(R"(<SequenceWithMemory><TestLeaf name="a"/>
                <TestLeaf name="b" results="failure;success"/></SequenceWithMemory>)");
  EXPECT_EQ(t.tree.tick(), Status::kFailure);
  EXPECT_EQ(t.tree.tick(), Status::kSuccess);
  EXPECT_EQ(t.log.count("a:start"), 1);
  EXPECT_EQ(t.log.count("b:start"), 2);
}

TEST(SequenceWithMemory, KeepsItsPlaceAcrossAHaltButNotAcrossAReset) {
  TestTree t(R"(<SequenceWithMemory><TestLeaf name="a"/><TestLeaf name="b" ticks="3"/></SequenceWithMemory>)");
  EXPECT_EQ(t.tree.tick(), Status::kRunning);
  t.tree.halt();
  EXPECT_EQ(t.log.count("b:halt"), 1);
  EXPECT_EQ(t.tree.tick(), Status::kRunning);
  EXPECT_EQ(t.log.count("a:start"), 1);  // resumed at b
  t.tree.reset();
  EXPECT_EQ(t.tree.tick(), Status::kRunning);
  EXPECT_EQ(t.log.count("a:start"), 2);  // started over
}

// --- ReactiveSequence ---------------------------------------------------------------------

TEST(ReactiveSequence, RechecksConditionsEveryTickAndHaltsTheActionWhenOneFails) {
  TestTree t(R"(<ReactiveSequence>
                  <TestCondition name="tool_in_place" results="success;success;failure" reason="tool moved"/>
                  <TestLeaf name="polish" ticks="10"/>
                </ReactiveSequence>)");
  EXPECT_EQ(t.tree.tick(), Status::kRunning);
  EXPECT_EQ(t.tree.tick(), Status::kRunning);
  EXPECT_EQ(t.tree.tick(), Status::kFailure);
  EXPECT_EQ(t.log.count("tool_in_place:start"), 3);
  EXPECT_EQ(t.log.count("polish:start"), 1);
  EXPECT_EQ(t.log.count("polish:halt"), 1);
  EXPECT_EQ(t.tree.root().failureReason(), "tool moved");
}

// --- Fallback -----------------------------------------------------------------------------

TEST(Fallback, StopsAtTheFirstSuccess) {
  TestTree t(R"(<Fallback><TestLeaf name="a" results="failure"/><TestLeaf name="b"/>
                <TestLeaf name="c"/></Fallback>)");
  EXPECT_EQ(t.tree.tick(), Status::kSuccess);
  EXPECT_EQ(t.log.count("c:start"), 0);
}

TEST(Fallback, FailsWithTheLastChildsReasonWhenAllFail) {
  TestTree t(R"(<Fallback><TestLeaf name="a" results="failure" reason="first"/>
                <TestLeaf name="b" results="failure" reason="second"/></Fallback>)");
  EXPECT_EQ(t.tree.tick(), Status::kFailure);
  EXPECT_EQ(t.tree.root().failureReason(), "second");
  EXPECT_EQ(t.tree.root().failureOrigin().name(), "b");
}

TEST(Fallback, ResumesAtTheRunningChild) {
  TestTree t(R"(<Fallback><TestLeaf name="a" results="failure"/><TestLeaf name="b" ticks="2"/></Fallback>)");
  EXPECT_EQ(t.tree.tick(), Status::kRunning);
  EXPECT_EQ(t.tree.tick(), Status::kRunning);
  EXPECT_EQ(t.tree.tick(), Status::kSuccess);
  EXPECT_EQ(t.log.count("a:start"), 1);
}

// --- ReactiveFallback ---------------------------------------------------------------------

TEST(ReactiveFallback, AHigherPriorityChildThatSucceedsPreemptsTheRunningOne) {
  TestTree t(R"(<ReactiveFallback>
                  <TestCondition name="done" results="failure;failure;success"/>
                  <TestLeaf name="work" ticks="10"/>
                </ReactiveFallback>)");
  EXPECT_EQ(t.tree.tick(), Status::kRunning);
  EXPECT_EQ(t.tree.tick(), Status::kRunning);
  EXPECT_EQ(t.tree.tick(), Status::kSuccess);
  EXPECT_EQ(t.log.count("work:halt"), 1);
}

// --- Parallel ---------------------------------------------------------------------------

TEST(Parallel, SucceedsWhenEnoughChildrenSucceedAndHaltsTheRest) {
  TestTree t(R"(<Parallel success_count="2"><TestLeaf name="a" ticks="1"/>
                <TestLeaf name="b" ticks="2"/><TestLeaf name="c" ticks="9"/></Parallel>)");
  EXPECT_EQ(t.tree.tick(), Status::kRunning);
  EXPECT_EQ(t.tree.tick(), Status::kRunning);  // a done
  EXPECT_EQ(t.tree.tick(), Status::kSuccess);  // b done: 2 successes
  EXPECT_EQ(t.log.count("c:halt"), 1);
  EXPECT_EQ(t.log.count("a:start"), 1);  // completed children are not re-ticked
}

TEST(Parallel, DefaultNeedsAllChildrenAndFailsOnTheFirstFailure) {
  TestTree t(R"(<Parallel><TestLeaf name="a" ticks="5"/>
                <TestLeaf name="b" ticks="1" results="failure" reason="b broke"/></Parallel>)");
  EXPECT_EQ(t.tree.tick(), Status::kRunning);
  EXPECT_EQ(t.tree.tick(), Status::kFailure);
  EXPECT_EQ(t.tree.root().failureReason(), "b broke");
  EXPECT_EQ(t.log.count("a:halt"), 1);
}

TEST(Parallel, FailsAsSoonAsSuccessBecomesImpossible) {
  TestTree t(R"(<Parallel success_count="-1" failure_count="2"><TestLeaf name="a" ticks="5"/>
                <TestLeaf name="b" results="failure"/></Parallel>)");
  // Needs both successes; b failed, so success is impossible even though 1 < failure_count.
  EXPECT_EQ(t.tree.tick(), Status::kFailure);
  EXPECT_EQ(t.log.count("a:halt"), 1);
}

TEST(Parallel, NegativeCountsAreRelativeToTheNumberOfChildren) {
  TestTree t(R"(<Parallel success_count="-2" failure_count="-1"><TestLeaf name="a"/>
                <TestLeaf name="b" results="failure"/><TestLeaf name="c"/></Parallel>)");
  EXPECT_EQ(t.tree.tick(), Status::kSuccess);  // 2 of 3 succeeded
}

// --- Iterator ---------------------------------------------------------------------------

TEST(Iterator, RunsEveryChildOnceIgnoringFailures) {
  TestTree t(R"(<Iterator><TestLeaf name="a" results="failure" reason="a failed"/>
                <TestLeaf name="b" ticks="1"/><TestLeaf name="c" results="failure"/></Iterator>)");
  testing::RecordingObserver observer;
  t.tree.addObserver(&observer);
  EXPECT_EQ(t.tree.tick(), Status::kRunning);
  EXPECT_EQ(t.tree.tick(), Status::kSuccess);
  EXPECT_EQ(t.log.events, (Events{"a:start", "a:failure", "b:start", "b:success", "c:start", "c:failure"}));
  // The ignored failures are still reported, with their reasons.
  ASSERT_EQ(observer.reasons.size(), 2u);
  EXPECT_EQ(observer.reasons[0], "a failed");
}

// --- simple decorators ------------------------------------------------------------------

TEST(Inverter, SwapsSuccessAndFailureAndExplainsIt) {
  TestTree t1(R"(<Inverter><TestLeaf/></Inverter>)");
  EXPECT_EQ(t1.tree.tick(), Status::kFailure);
  EXPECT_NE(t1.tree.root().failureReason().find("inverted"), std::string_view::npos);
  EXPECT_EQ(t1.tree.root().failureOrigin().id(), "Inverter");
  TestTree t2(R"(<Inverter><TestLeaf results="failure" ticks="1"/></Inverter>)");
  EXPECT_EQ(t2.tree.tick(), Status::kRunning);
  EXPECT_EQ(t2.tree.tick(), Status::kSuccess);
}

TEST(ForceSuccessAndForceFailure, OverrideTheCompletedResultOnly) {
  TestTree t1(R"(<ForceSuccess><TestLeaf results="failure" ticks="1"/></ForceSuccess>)");
  EXPECT_EQ(t1.tree.tick(), Status::kRunning);
  EXPECT_EQ(t1.tree.tick(), Status::kSuccess);
  TestTree t2(R"(<ForceFailure><TestLeaf/></ForceFailure>)");
  EXPECT_EQ(t2.tree.tick(), Status::kFailure);
  TestTree t3(R"(<ForceFailure><TestLeaf results="failure" reason="own"/></ForceFailure>)");
  EXPECT_EQ(t3.tree.tick(), Status::kFailure);
  EXPECT_EQ(t3.tree.root().failureReason(), "own");
}

// --- Repeat / RepeatRuns -------------------------------------------------------------------

TEST(Repeat, CountsRunsNotTicks) {
  TestTree t(R"(<Repeat num_cycles="3"><TestLeaf name="a" ticks="2"/></Repeat>)");
  EXPECT_EQ(tickUntilDone(t), Status::kSuccess);
  EXPECT_EQ(t.log.count("a:start"), 3);
  EXPECT_EQ(t.log.count("a:success"), 3);
}

TEST(Repeat, AFailureEndsTheLoopWithThatFailure) {
  TestTree t(R"(<Repeat num_cycles="5"><TestLeaf name="a" results="success;failure" reason="dropped"/></Repeat>)");
  EXPECT_EQ(tickUntilDone(t), Status::kFailure);
  EXPECT_EQ(t.log.count("a:start"), 2);
  EXPECT_EQ(t.tree.root().failureReason(), "dropped");
}

TEST(Repeat, ForeverKeepsRunningUntilHaltedAndNeverBlocksATick) {
  TestTree t(R"(<Repeat num_cycles="-1"><TestLeaf name="a"/></Repeat>)");
  for (int i = 0; i < 100; ++i) {
    EXPECT_EQ(t.tree.tick(), Status::kRunning);
    // Each run completed synchronously; the loop asks for another tick instead of spinning.
    EXPECT_TRUE(t.tree.context().takeImmediateTickRequest());
  }
  EXPECT_EQ(t.log.count("a:success"), 100);
  t.tree.halt();
  EXPECT_EQ(t.tree.root().status(), Status::kIdle);
}

TEST(Repeat, HaltingTheLoopCancelsTheRunningChildAndRestartsTheCount) {
  TestTree t(R"(<Repeat num_cycles="2"><TestLeaf name="a" ticks="1"/></Repeat>)");
  EXPECT_EQ(t.tree.tick(), Status::kRunning);
  EXPECT_EQ(t.tree.tick(), Status::kRunning);  // run 1 done
  EXPECT_EQ(t.tree.tick(), Status::kRunning);  // run 2 started
  t.tree.halt();
  EXPECT_EQ(t.log.count("a:halt"), 1);
  EXPECT_EQ(tickUntilDone(t), Status::kSuccess);
  EXPECT_EQ(t.log.count("a:success"), 3);  // 1 before the halt + 2 after
}

TEST(RepeatRuns, CountsFailedRunsTooAndThenSucceeds) {
  TestTree t(R"(<RepeatRuns num_runs="3"><TestLeaf name="a" results="failure;success;failure"/></RepeatRuns>)");
  EXPECT_EQ(tickUntilDone(t), Status::kSuccess);
  EXPECT_EQ(t.log.count("a:start"), 3);
  EXPECT_EQ(t.log.count("a:failure"), 2);
}

// --- Reset --------------------------------------------------------------------------------

TEST(Reset, ReturnsTheChildsValueAndResetsItsMemoryOnFailure) {
  // Without the Reset, SequenceWithMemory would retry "check" without redoing "pick".
  TestTree t(R"(<Reset num_resets="2"><SequenceWithMemory>
                  <TestLeaf name="pick"/>
                  <TestCondition name="check" results="failure;success" reason="tool out of position"/>
                </SequenceWithMemory></Reset>)");
  EXPECT_EQ(t.tree.tick(), Status::kFailure);
  EXPECT_EQ(t.tree.root().failureReason(), "tool out of position");
  EXPECT_EQ(t.tree.tick(), Status::kSuccess);
  EXPECT_EQ(t.log.count("pick:start"), 2);  // started over after the reset
}

TEST(Reset, AfterNResetsPassesFailureOnWithoutTickingTheChild) {
  TestTree t(R"(<Reset num_resets="2"><TestLeaf name="a" results="failure" reason="broken"/></Reset>)");
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(t.tree.tick(), Status::kFailure);
  }
  EXPECT_EQ(t.log.count("a:start"), 3);  // 2 resets + the run that exhausted the budget
  for (int i = 0; i < 5; ++i) {
    EXPECT_EQ(t.tree.tick(), Status::kFailure);
    EXPECT_EQ(t.tree.root().failureReason(), "broken");
  }
  EXPECT_EQ(t.log.count("a:start"), 3);  // latched: child no longer ticked
  t.tree.reset();                        // an ancestor's reset restores the budget
  EXPECT_EQ(t.tree.tick(), Status::kFailure);
  EXPECT_EQ(t.log.count("a:start"), 4);
}

TEST(Reset, MinusOneResetsForever) {
  TestTree t(R"(<Reset num_resets="-1"><TestLeaf name="a" results="failure"/></Reset>)");
  for (int i = 0; i < 50; ++i) {
    EXPECT_EQ(t.tree.tick(), Status::kFailure);
  }
  EXPECT_EQ(t.log.count("a:start"), 50);
}

TEST(Reset, HaltPassesToTheRunningChild) {
  TestTree t(R"(<Reset num_resets="1"><TestLeaf name="a" ticks="3"/></Reset>)");
  EXPECT_EQ(t.tree.tick(), Status::kRunning);
  t.tree.halt();
  EXPECT_EQ(t.log.count("a:halt"), 1);
}

// --- Timeout --------------------------------------------------------------------------------

TEST(Timeout, HaltsAChildThatTakesTooLongAndSaysSo) {
  TestTree t(R"(<Timeout msec="50"><TestLeaf name="slow" ticks="100"/></Timeout>)");
  EXPECT_EQ(tickUntilDone(t), Status::kFailure);
  EXPECT_EQ(t.log.count("slow:halt"), 1);
  EXPECT_EQ(t.tree.root().failureOrigin().id(), "Timeout");
  EXPECT_NE(t.tree.root().failureReason().find("within 50 ms"), std::string_view::npos);
  EXPECT_EQ(t.clock.now().time_since_epoch(), std::chrono::milliseconds(50));
}

TEST(Timeout, PassesOnTheResultOfAChildThatCompletesInTime) {
  TestTree t(R"(<Timeout msec="50"><TestLeaf name="quick" ticks="3" results="failure" reason="own"/></Timeout>)");
  EXPECT_EQ(tickUntilDone(t), Status::kFailure);
  EXPECT_EQ(t.tree.root().failureReason(), "own");
  EXPECT_EQ(t.log.count("quick:halt"), 0);
}

// --- RetryUntilSuccessful -------------------------------------------------------------------

TEST(RetryUntilSuccessful, RetriesUntilTheChildSucceeds) {
  TestTree t(
      R"(<RetryUntilSuccessful num_attempts="5"><TestLeaf name="a" results="failure;failure;success"/></RetryUntilSuccessful>)");
  EXPECT_EQ(tickUntilDone(t), Status::kSuccess);
  EXPECT_EQ(t.log.count("a:start"), 3);
}

TEST(RetryUntilSuccessful, FailsWithTheLastReasonWhenAttemptsRunOut) {
  TestTree t(
      R"(<RetryUntilSuccessful num_attempts="2"><TestLeaf name="a" results="failure" reason="slipped"/></RetryUntilSuccessful>)");
  EXPECT_EQ(tickUntilDone(t), Status::kFailure);
  EXPECT_EQ(t.log.count("a:start"), 2);
  EXPECT_EQ(t.tree.root().failureReason(), "slipped");
}

// --- SubTree, leaves ----------------------------------------------------------------------

TEST(SubTree, IsTransparentAndNamedByItsIdInPaths) {
  TestTree t(
      R"(<Sequence><SubTree ID="assemble"/></Sequence>)",
      R"(<BehaviorTree ID="assemble"><Sequence><TestLeaf/><TestLeaf name="grasp link" results="failure" reason="no reachable candidate"/></Sequence></BehaviorTree>)");
  EXPECT_EQ(t.tree.tick(), Status::kFailure);
  EXPECT_EQ(t.tree.root().failureOrigin().path(), R"(main/Sequence[1]/assemble/Sequence[1]/TestLeaf "grasp link")");
}

TEST(Leaves, AlwaysSuccessAlwaysFailureAndSleepOnTheClock) {
  TestTree t1("<AlwaysSuccess/>");
  EXPECT_EQ(t1.tree.tick(), Status::kSuccess);
  TestTree t2("<AlwaysFailure/>");
  EXPECT_EQ(t2.tree.tick(), Status::kFailure);
  EXPECT_EQ(t2.tree.root().failureReason(), "AlwaysFailure");
  TestTree t3(R"(<Sleep msec="30"/>)");
  EXPECT_EQ(t3.tree.tick(), Status::kRunning);
  t3.clock.advanceBy(std::chrono::milliseconds(29));
  EXPECT_EQ(t3.tree.tick(), Status::kRunning);
  t3.clock.advanceBy(std::chrono::milliseconds(1));
  EXPECT_EQ(t3.tree.tick(), Status::kSuccess);
}

// --- Observer, paths ------------------------------------------------------------------------

TEST(Observer, ReportsEveryTransitionInOrder) {
  TestTree t(R"(<Sequence><TestLeaf name="a" ticks="1"/><AlwaysFailure/></Sequence>)");
  testing::RecordingObserver observer;
  t.tree.addObserver(&observer);
  EXPECT_EQ(t.tree.tick(), Status::kRunning);
  EXPECT_EQ(t.tree.tick(), Status::kFailure);
  EXPECT_EQ(observer.transitions,
            (Events{R"(main/Sequence[1]/TestLeaf "a":IDLE->RUNNING)", "main/Sequence[1]:IDLE->RUNNING",
                    R"(main/Sequence[1]/TestLeaf "a":RUNNING->SUCCESS)",
                    "main/Sequence[1]/AlwaysFailure[2]:IDLE->FAILURE", R"(main/Sequence[1]/TestLeaf "a":SUCCESS->IDLE)",
                    "main/Sequence[1]/AlwaysFailure[2]:FAILURE->IDLE", "main/Sequence[1]:RUNNING->FAILURE"}));
  EXPECT_EQ(observer.reasons, (Events{"AlwaysFailure", "AlwaysFailure"}));
}

TEST(Tree, NodesAreInPreOrderWithUids) {
  TestTree t(R"(<Sequence><Inverter><AlwaysFailure/></Inverter><Sleep msec="1"/></Sequence>)");
  ASSERT_EQ(t.tree.nodes().size(), 4u);
  for (std::size_t i = 0; i < t.tree.nodes().size(); ++i) {
    EXPECT_EQ(t.tree.nodes()[i]->uid(), i);
  }
  EXPECT_EQ(t.tree.nodes()[2]->path(), "main/Sequence[1]/Inverter[1]/AlwaysFailure[1]");
  EXPECT_EQ(t.tree.nodes()[3]->parent(), &t.tree.root());
}

}  // namespace
}  // namespace costar::bt
