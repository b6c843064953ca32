// Semantics of the BehaviorTree.CPP v4 built-ins that need no blackboard beyond the original
// set: AsyncSequence, AsyncFallback, ParallelAll, IfThenElse, WhileDoElse, TryCatch,
// KeepRunningUntilFailure, Delay, RunOnce, and the SKIPPED status RunOnce introduces. Each as
// BehaviorTree.CPP 4.10 does it (its src/controls and decorators); docs/BEHAVIOR_TREES.md.

#include <gtest/gtest.h>

#include "bt/executor.h"
#include "bt/test/test_support.h"

namespace costar::bt {
namespace {

using testing::TestTree;
using Events = std::vector<std::string>;
using std::chrono::milliseconds;

// --- AsyncSequence / AsyncFallback --------------------------------------------------------

TEST(AsyncSequence, GivesTheTickBackAfterEachInstantChildAndAsksForAnImmediateTick) {
  TestTree t(R"(<AsyncSequence><TestLeaf name="a"/><TestLeaf name="b"/><TestLeaf name="c"/></AsyncSequence>)");
  EXPECT_EQ(t.tree.tick(), Status::kRunning);
  EXPECT_EQ(t.log.events, (Events{"a:start", "a:success"}));
  EXPECT_TRUE(t.tree.context().takeImmediateTickRequest());
  EXPECT_EQ(t.tree.tick(), Status::kRunning);
  EXPECT_EQ(t.log.count("b:success"), 1);
  EXPECT_EQ(t.log.count("c:start"), 0);
  EXPECT_TRUE(t.tree.context().takeImmediateTickRequest());
  EXPECT_EQ(t.tree.tick(), Status::kSuccess);  // after the last child: no yield
  EXPECT_FALSE(t.tree.context().takeImmediateTickRequest());
  EXPECT_EQ(t.log.count("a:start"), 1);
}

TEST(AsyncSequence, AChildThatTookTicksHandsOnToTheNextInTheSameTick) {
  TestTree t(R"(<AsyncSequence><TestLeaf name="a" ticks="1"/><TestLeaf name="b"/></AsyncSequence>)");
  EXPECT_EQ(t.tree.tick(), Status::kRunning);
  EXPECT_EQ(t.tree.tick(), Status::kSuccess);  // a was RUNNING before: b runs at once
  EXPECT_EQ(t.log.events, (Events{"a:start", "a:success", "b:start", "b:success"}));
}

TEST(AsyncSequence, CanBeHaltedBetweenChildrenAndThenStartsOver) {
  TestTree t(R"(<AsyncSequence><TestLeaf name="a"/><TestLeaf name="b" results="failure" reason="dropped"/>
                </AsyncSequence>)");
  EXPECT_EQ(t.tree.tick(), Status::kRunning);
  t.tree.halt();
  EXPECT_EQ(t.tree.root().status(), Status::kIdle);
  EXPECT_EQ(t.tree.tick(), Status::kRunning);
  EXPECT_EQ(t.log.count("a:start"), 2);
  EXPECT_EQ(t.tree.tick(), Status::kFailure);
  EXPECT_EQ(t.tree.root().failureReason(), "dropped");
}

TEST(AsyncFallback, GivesTheTickBackAfterEachInstantFailureAndStopsAtASuccess) {
  TestTree t(R"(<AsyncFallback><TestLeaf name="a" results="failure"/><TestLeaf name="b"/>
                <TestLeaf name="c"/></AsyncFallback>)");
  EXPECT_EQ(t.tree.tick(), Status::kRunning);
  EXPECT_TRUE(t.tree.context().takeImmediateTickRequest());
  EXPECT_EQ(t.tree.tick(), Status::kSuccess);
  EXPECT_EQ(t.log.count("c:start"), 0);
}

TEST(AsyncFallback, AllFailedPassesOnTheLastReason) {
  TestTree t(R"(<AsyncFallback><TestLeaf name="a" results="failure" reason="first"/>
                <TestLeaf name="b" results="failure" reason="second"/></AsyncFallback>)");
  EXPECT_EQ(t.tree.tick(), Status::kRunning);
  EXPECT_EQ(t.tree.tick(), Status::kFailure);
  EXPECT_EQ(t.tree.root().failureReason(), "second");
}

// --- ParallelAll ----------------------------------------------------------------------------

TEST(ParallelAll, WaitsForEveryChildEvenAfterAFailureAndHaltsNone) {
  TestTree t(R"(<ParallelAll><TestLeaf name="a" results="failure" reason="jammed"/>
                <TestLeaf name="b" ticks="2"/></ParallelAll>)");
  EXPECT_EQ(t.tree.tick(), Status::kRunning);
  EXPECT_EQ(t.tree.tick(), Status::kRunning);
  EXPECT_EQ(t.tree.tick(), Status::kFailure);  // max_failures=1 by default
  EXPECT_EQ(t.log.count("b:halt"), 0);
  EXPECT_EQ(t.log.count("b:success"), 1);
  EXPECT_EQ(t.log.count("a:start"), 1);  // a completed child is not ticked again in the run
  EXPECT_EQ(t.tree.root().failureReason(), "jammed");
}

TEST(ParallelAll, SucceedsWhileFewerThanMaxFailuresFailed) {
  TestTree t(R"(<ParallelAll max_failures="2"><TestLeaf name="a" results="failure"/>
                <TestLeaf name="b" ticks="1"/><TestLeaf name="c"/></ParallelAll>)");
  EXPECT_EQ(t.tree.tick(), Status::kRunning);
  EXPECT_EQ(t.tree.tick(), Status::kSuccess);
  // The counts start over in the next run.
  EXPECT_EQ(t.tree.tick(), Status::kRunning);
  EXPECT_EQ(t.tree.tick(), Status::kSuccess);
}

TEST(ParallelAll, NegativeMaxFailuresCountsFromTheEnd) {
  TestTree t(R"(<ParallelAll max_failures="-1"><TestLeaf name="a" results="failure"/>
                <TestLeaf name="b"/></ParallelAll>)");
  EXPECT_EQ(t.tree.tick(), Status::kSuccess);  // -1 = all 2 must fail
  TestTree all(R"(<ParallelAll max_failures="-1"><AlwaysFailure/><AlwaysFailure/></ParallelAll>)");
  EXPECT_EQ(all.tree.tick(), Status::kFailure);
}

TEST(ParallelAll, HaltStopsTheRunningChildrenAndForgetsTheCount) {
  TestTree t(R"(<ParallelAll><TestLeaf name="a" results="failure;success"/><TestLeaf name="b" ticks="3"/>
                </ParallelAll>)");
  EXPECT_EQ(t.tree.tick(), Status::kRunning);
  t.tree.halt();
  EXPECT_EQ(t.log.count("b:halt"), 1);
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(t.tree.tick(), Status::kRunning);
  }
  EXPECT_EQ(t.tree.tick(), Status::kSuccess);  // the failure before the halt no longer counts
}

// --- IfThenElse --------------------------------------------------------------------------------

TEST(IfThenElse, RunsTheThenOrTheElseBranchAndReturnsItsResult) {
  TestTree yes(R"(<IfThenElse><TestCondition/><TestLeaf name="then"/><TestLeaf name="else"/></IfThenElse>)");
  EXPECT_EQ(yes.tree.tick(), Status::kSuccess);
  EXPECT_EQ(yes.log.count("else:start"), 0);
  TestTree no(R"(<IfThenElse><TestCondition results="failure"/><TestLeaf name="then"/>
                 <TestLeaf name="else" results="failure" reason="else failed"/></IfThenElse>)");
  EXPECT_EQ(no.tree.tick(), Status::kFailure);
  EXPECT_EQ(no.log.count("then:start"), 0);
  EXPECT_EQ(no.tree.root().failureReason(), "else failed");
}

TEST(IfThenElse, WithoutElseAFalseConditionIsItsFailure) {
  TestTree t(R"(<IfThenElse><TestCondition results="failure" reason="no object"/><TestLeaf name="then"/>
                </IfThenElse>)");
  EXPECT_EQ(t.tree.tick(), Status::kFailure);
  EXPECT_EQ(t.tree.root().failureReason(), "no object");
}

TEST(IfThenElse, DoesNotRecheckTheConditionWhileTheBranchRunsButDoesInTheNextRun) {
  TestTree t(R"(<IfThenElse><TestCondition name="c" results="success;failure"/><TestLeaf name="then" ticks="2"/>
                <TestLeaf name="else"/></IfThenElse>)");
  EXPECT_EQ(t.tree.tick(), Status::kRunning);
  EXPECT_EQ(t.tree.tick(), Status::kRunning);
  EXPECT_EQ(t.tree.tick(), Status::kSuccess);
  EXPECT_EQ(t.log.count("c:start"), 1);
  EXPECT_EQ(t.tree.tick(), Status::kSuccess);  // next run: condition false, else branch
  EXPECT_EQ(t.log.count("else:success"), 1);
}

TEST(IfThenElse, HaltStopsTheBranchAndTheNextRunRechecksTheCondition) {
  TestTree t(R"(<IfThenElse><TestCondition name="c"/><TestLeaf name="then" ticks="5"/></IfThenElse>)");
  EXPECT_EQ(t.tree.tick(), Status::kRunning);
  t.tree.halt();
  EXPECT_EQ(t.log.count("then:halt"), 1);
  EXPECT_EQ(t.tree.tick(), Status::kRunning);
  EXPECT_EQ(t.log.count("c:start"), 2);
}

// --- WhileDoElse ---------------------------------------------------------------------------------

TEST(WhileDoElse, RechecksTheConditionEveryTickAndSwitchesBranchHaltingTheOther) {
  TestTree t(R"(<WhileDoElse><TestCondition name="c" results="success;success;failure"/>
                <TestLeaf name="do" ticks="10"/><TestLeaf name="else" ticks="1"/></WhileDoElse>)");
  EXPECT_EQ(t.tree.tick(), Status::kRunning);
  EXPECT_EQ(t.tree.tick(), Status::kRunning);
  EXPECT_EQ(t.log.count("do:start"), 1);       // resumed, not restarted
  EXPECT_EQ(t.tree.tick(), Status::kRunning);  // condition false: do halted, else started
  EXPECT_EQ(t.log.count("do:halt"), 1);
  EXPECT_EQ(t.log.count("else:start"), 1);
  EXPECT_EQ(t.tree.tick(), Status::kSuccess);  // condition still false; else completes
  EXPECT_EQ(t.log.count("c:start"), 4);
}

TEST(WhileDoElse, WithoutElseAFalseConditionFailsAndHaltsTheDoBranch) {
  TestTree t(R"(<WhileDoElse><TestCondition results="success;failure" reason="lost sight"/>
                <TestLeaf name="do" ticks="10"/></WhileDoElse>)");
  EXPECT_EQ(t.tree.tick(), Status::kRunning);
  EXPECT_EQ(t.tree.tick(), Status::kFailure);
  EXPECT_EQ(t.log.count("do:halt"), 1);
  EXPECT_EQ(t.tree.root().failureReason(), "lost sight");
}

TEST(WhileDoElse, ReturnsTheBranchResultWhenItCompletes) {
  TestTree t(R"(<WhileDoElse><TestCondition/><TestLeaf name="do" results="failure" reason="do failed"/>
                </WhileDoElse>)");
  EXPECT_EQ(t.tree.tick(), Status::kFailure);
  EXPECT_EQ(t.tree.root().failureReason(), "do failed");
}

// --- TryCatch ------------------------------------------------------------------------------------

TEST(TryCatch, SucceedsWhenTheTryBlockSucceedsWithoutRunningTheCatch) {
  TestTree t(R"(<TryCatch><TestLeaf name="a"/><TestLeaf name="b" ticks="1"/><TestLeaf name="catch"/></TryCatch>)");
  EXPECT_EQ(t.tree.tick(), Status::kRunning);
  EXPECT_EQ(t.tree.tick(), Status::kSuccess);
  EXPECT_EQ(t.log.count("catch:start"), 0);
}

TEST(TryCatch, AFailureRunsTheCatchToCompletionThenFailsWithTheTryReason) {
  TestTree t(R"(<TryCatch><TestLeaf name="grasp" results="failure" reason="slipped"/><TestLeaf name="never"/>
                <TestLeaf name="open and retreat" ticks="2"/></TryCatch>)");
  EXPECT_EQ(t.tree.tick(), Status::kRunning);  // catch entered in the same tick
  EXPECT_EQ(t.tree.tick(), Status::kRunning);
  EXPECT_EQ(t.tree.tick(), Status::kFailure);
  EXPECT_EQ(t.log.events,
            (Events{"grasp:start", "grasp:failure", "open and retreat:start", "open and retreat:success"}));
  EXPECT_EQ(t.tree.root().failureReason(), "slipped");
  // The next run starts with the try block again.
  EXPECT_EQ(t.tree.tick(), Status::kRunning);
  EXPECT_EQ(t.log.count("grasp:start"), 2);
}

TEST(TryCatch, FailsEvenWhenTheCatchFails) {
  TestTree t(R"(<TryCatch><AlwaysFailure/><TestLeaf name="catch" results="failure" reason="catch failed"/>
                </TryCatch>)");
  EXPECT_EQ(t.tree.tick(), Status::kFailure);
  EXPECT_EQ(t.tree.root().failureReason(), "AlwaysFailure");
}

TEST(TryCatch, AHaltDuringTheTryBlockRunsTheCatchOnceOnlyWithCatchOnHalt) {
  TestTree plain(R"(<TryCatch><TestLeaf name="a" ticks="5"/><TestLeaf name="catch"/></TryCatch>)");
  EXPECT_EQ(plain.tree.tick(), Status::kRunning);
  plain.tree.halt();
  EXPECT_EQ(plain.log.events, (Events{"a:start", "a:halt"}));

  TestTree on_halt(R"(<TryCatch catch_on_halt="true"><TestLeaf name="a" ticks="5"/>
                      <TestLeaf name="catch" ticks="3"/></TryCatch>)");
  EXPECT_EQ(on_halt.tree.tick(), Status::kRunning);
  on_halt.tree.halt();
  // Best effort, as BehaviorTree.CPP: one tick of the catch child, halted if it is still running.
  EXPECT_EQ(on_halt.log.events, (Events{"a:start", "a:halt", "catch:start", "catch:halt"}));
  EXPECT_EQ(on_halt.tree.root().status(), Status::kIdle);
  for (const TreeNode* node : on_halt.tree.nodes()) {
    EXPECT_EQ(node->status(), Status::kIdle) << node->path();
  }
}

TEST(TryCatch, AHaltDuringTheCatchJustHaltsIt) {
  TestTree t(R"(<TryCatch catch_on_halt="true"><AlwaysFailure/><TestLeaf name="catch" ticks="3"/></TryCatch>)");
  EXPECT_EQ(t.tree.tick(), Status::kRunning);
  t.tree.halt();
  EXPECT_EQ(t.log.events, (Events{"catch:start", "catch:halt"}));
}

// --- KeepRunningUntilFailure -----------------------------------------------------------------

TEST(KeepRunningUntilFailure, RerunsTheChildOncePerTickUntilItFails) {
  TestTree t(R"(<KeepRunningUntilFailure><TestLeaf name="a" results="success;success;failure" reason="empty"/>
                </KeepRunningUntilFailure>)");
  EXPECT_EQ(t.tree.tick(), Status::kRunning);
  EXPECT_FALSE(t.tree.context().takeImmediateTickRequest());  // one run per tick, as BehaviorTree.CPP
  EXPECT_EQ(t.tree.tick(), Status::kRunning);
  EXPECT_EQ(t.tree.tick(), Status::kFailure);
  EXPECT_EQ(t.log.count("a:start"), 3);
  EXPECT_EQ(t.tree.root().failureReason(), "empty");
}

TEST(KeepRunningUntilFailure, HaltCancelsTheRunningChild) {
  TestTree t(R"(<KeepRunningUntilFailure><TestLeaf name="a" ticks="2"/></KeepRunningUntilFailure>)");
  EXPECT_EQ(t.tree.tick(), Status::kRunning);
  t.tree.halt();
  EXPECT_EQ(t.log.count("a:halt"), 1);
}

// --- Delay -----------------------------------------------------------------------------------------

TEST(Delay, WaitsOnTheTreesClockThenTicksTheChildAndReturnsItsResult) {
  TestTree t(R"(<Delay delay_msec="30"><TestLeaf name="a" ticks="1" results="failure" reason="late"/></Delay>)");
  EXPECT_EQ(t.tree.tick(), Status::kRunning);
  t.clock.advanceBy(milliseconds(29));
  EXPECT_EQ(t.tree.tick(), Status::kRunning);
  EXPECT_EQ(t.log.count("a:start"), 0);
  t.clock.advanceBy(milliseconds(1));
  EXPECT_EQ(t.tree.tick(), Status::kRunning);  // the child runs, in the tick the delay ended
  EXPECT_EQ(t.log.count("a:start"), 1);
  EXPECT_EQ(t.tree.tick(), Status::kFailure);  // no new delay while the child runs
  EXPECT_EQ(t.tree.root().failureReason(), "late");
  // The next run waits again.
  EXPECT_EQ(t.tree.tick(), Status::kRunning);
  EXPECT_EQ(t.log.count("a:start"), 1);
}

TEST(Delay, AHaltCancelsTheWaitAndTheChild) {
  TestTree t(R"(<Delay delay_msec="10"><TestLeaf name="a" ticks="5"/></Delay>)");
  EXPECT_EQ(t.tree.tick(), Status::kRunning);
  t.clock.advanceBy(milliseconds(10));
  EXPECT_EQ(t.tree.tick(), Status::kRunning);
  t.tree.halt();
  EXPECT_EQ(t.log.count("a:halt"), 1);
  EXPECT_EQ(t.tree.tick(), Status::kRunning);  // waits 10 ms again before restarting a
  EXPECT_EQ(t.log.count("a:start"), 1);
}

TEST(Delay, ZeroTicksTheChildAtOnce) {
  TestTree t(R"(<Delay delay_msec="0"><TestLeaf name="a"/></Delay>)");
  EXPECT_EQ(t.tree.tick(), Status::kSuccess);
}

// --- RunOnce and SKIPPED ----------------------------------------------------------------------

TEST(RunOnce, RunsTheChildOnceThenIsSkippedAndASequencePassesOver) {
  TestTree t(R"(<Sequence><RunOnce><TestLeaf name="init"/></RunOnce><TestLeaf name="work"/></Sequence>)");
  testing::RecordingObserver observer;
  t.tree.addObserver(&observer);
  EXPECT_EQ(t.tree.tick(), Status::kSuccess);
  EXPECT_EQ(t.tree.tick(), Status::kSuccess);
  EXPECT_EQ(t.log.count("init:start"), 1);
  EXPECT_EQ(t.log.count("work:start"), 2);
  // SKIPPED is returned to the parent, never recorded: observers see the node stay IDLE.
  for (const auto& transition : observer.transitions) {
    EXPECT_EQ(transition.find("SKIPPED"), std::string::npos) << transition;
  }
}

TEST(RunOnce, ASkippedChildOfAFallbackIsPassedOverNotTakenAsSuccess) {
  TestTree t(R"(<Fallback><RunOnce><TestLeaf name="a"/></RunOnce>
                <TestLeaf name="b" results="failure" reason="b failed"/></Fallback>)");
  EXPECT_EQ(t.tree.tick(), Status::kSuccess);
  EXPECT_EQ(t.tree.tick(), Status::kFailure);
  EXPECT_EQ(t.tree.root().failureReason(), "b failed");
}

TEST(RunOnce, WithoutThenSkipReturnsTheFirstResultAgainWithoutTickingTheChild) {
  TestTree t(R"(<RunOnce then_skip="false"><TestLeaf name="a" ticks="1" results="failure;success" reason="once"/>
                </RunOnce>)");
  EXPECT_EQ(t.tree.tick(), Status::kRunning);
  EXPECT_EQ(t.tree.tick(), Status::kFailure);
  EXPECT_EQ(t.tree.tick(), Status::kFailure);
  EXPECT_EQ(t.tree.root().failureReason(), "once");
  EXPECT_EQ(t.log.count("a:start"), 1);
}

TEST(RunOnce, AHaltedRunDoesNotCountButAResetStartsItOver) {
  TestTree t(R"(<RunOnce then_skip="false"><TestLeaf name="a" ticks="1"/></RunOnce>)");
  EXPECT_EQ(t.tree.tick(), Status::kRunning);
  t.tree.halt();
  EXPECT_EQ(t.tree.tick(), Status::kRunning);
  EXPECT_EQ(t.tree.tick(), Status::kSuccess);
  EXPECT_EQ(t.tree.tick(), Status::kSuccess);
  EXPECT_EQ(t.log.count("a:start"), 2);
  t.tree.reset();
  EXPECT_EQ(t.tree.tick(), Status::kRunning);
  EXPECT_EQ(t.log.count("a:start"), 3);
}

TEST(RunOnce, AllChildrenSkippedMakesTheParentSkippedAndARunOfNothingFails) {
  TestTree t(R"(<Repeat num_cycles="3"><Sequence><RunOnce><TestLeaf name="a"/></RunOnce></Sequence></Repeat>)");
  Executor executor(t.tree, t.clock);
  const RunResult result = executor.run();
  EXPECT_EQ(result.status, Status::kFailure);  // BehaviorTree.CPP's root returns SKIPPED: not a success
  EXPECT_NE(result.failure_reason.find("skipped"), std::string::npos);
  EXPECT_EQ(t.log.count("a:start"), 1);
  EXPECT_EQ(t.tree.root().status(), Status::kIdle);
}

TEST(RunOnce, SkippedPassesThroughDecoratorsAndParallelIgnoresIt) {
  TestTree t(R"(<Sequence><Inverter><RunOnce><AlwaysFailure/></RunOnce></Inverter><TestLeaf name="b"/></Sequence>)");
  EXPECT_EQ(t.tree.tick(), Status::kSuccess);
  EXPECT_EQ(t.tree.tick(), Status::kSuccess);  // Inverter of a skipped child is skipped, not FAILURE
  TestTree p(R"(<Parallel success_count="1"><RunOnce><AlwaysSuccess/></RunOnce><TestLeaf name="b" ticks="1"/>
                </Parallel>)");
  EXPECT_EQ(p.tree.tick(), Status::kSuccess);
  EXPECT_EQ(p.tree.tick(), Status::kRunning);  // the skipped child neither succeeds nor fails
  EXPECT_EQ(p.tree.tick(), Status::kSuccess);
}

TEST(RunOnce, InsideTryCatchAndIfThenElse) {
  TestTree t(R"(<TryCatch><RunOnce><AlwaysSuccess/></RunOnce><TestLeaf name="catch"/></TryCatch>)");
  EXPECT_EQ(t.tree.tick(), Status::kSuccess);
  EXPECT_EQ(t.tree.tick(), Status::kSkipped);  // whole try block skipped
  TestTree i(R"(<IfThenElse><RunOnce><AlwaysSuccess/></RunOnce><TestLeaf name="then"/></IfThenElse>)");
  EXPECT_EQ(i.tree.tick(), Status::kSuccess);
  EXPECT_EQ(i.tree.tick(), Status::kSkipped);
  EXPECT_EQ(i.log.count("then:start"), 1);
}

}  // namespace
}  // namespace costar::bt
