// The root that generates ticks: rate, lockstep clock, stop, time limit.

#include "bt/executor.h"

#include <gtest/gtest.h>

#include <unistd.h>
#include <fstream>
#include <sstream>
#include <thread>

#include "bt/test/test_support.h"
#include "bt/trace.h"

namespace costar::bt {
namespace {

using namespace std::chrono_literals;

TEST(Executor, TicksAtItsRateOnTheSimulatedClockWithoutWaiting) {
  testing::TestTree t(R"(<Sequence><Sleep msec="500"/><TestLeaf name="a"/></Sequence>)");
  Executor executor(t.tree, t.clock, {.tick_period = 10ms});
  const auto wall_start = std::chrono::steady_clock::now();
  const RunResult result = executor.run();
  EXPECT_EQ(result.status, Status::kSuccess);
  EXPECT_EQ(result.elapsed, 500ms);
  EXPECT_EQ(result.ticks, 51u);
  EXPECT_LT(std::chrono::steady_clock::now() - wall_start, 400ms);  // lockstep, not real time
}

TEST(Executor, LoopsThatFinishARunEveryTickDoNotAdvanceTheClock) {
  testing::TestTree t(R"(<Repeat num_cycles="1000"><TestLeaf name="a"/></Repeat>)");
  Executor executor(t.tree, t.clock);
  const RunResult result = executor.run();
  EXPECT_EQ(result.status, Status::kSuccess);
  EXPECT_EQ(t.log.count("a:success"), 1000);
  EXPECT_EQ(result.elapsed, 0ms);
}

TEST(Executor, ReportsTheFailingNodesPathAndReason) {
  testing::TestTree t(
      R"(<Sequence><TestLeaf name="grasp" results="failure" reason="no reachable candidate"/></Sequence>)");
  Executor executor(t.tree, t.clock);
  const RunResult result = executor.run();
  EXPECT_EQ(result.status, Status::kFailure);
  EXPECT_EQ(result.failure_path, R"(main/Sequence[1]/TestLeaf "grasp")");
  EXPECT_EQ(result.failure_reason, "no reachable candidate");
}

TEST(Executor, TimeLimitHaltsTheTreeAndFails) {
  testing::TestTree t(R"(<TestLeaf name="forever" ticks="1000000"/>)");
  Executor executor(t.tree, t.clock, {.tick_period = 10ms, .time_limit = 1s});
  const RunResult result = executor.run();
  EXPECT_EQ(result.status, Status::kFailure);
  EXPECT_EQ(result.elapsed, 1s);
  EXPECT_EQ(t.log.count("forever:halt"), 1);
  EXPECT_NE(result.failure_reason.find("time limit"), std::string::npos);
}

TEST(Executor, StopFromAnotherThreadHaltsAndCancelsTheRunningOperation) {
  testing::EventLog log;
  const NodeRegistry registry = testing::registryWithTestLeaf(log);
  RealClock clock;
  Tree tree =
      buildTree(loadPlanText(testing::planXml(R"(<TestLeaf name="move" ticks="1000000"/>)"), "t"), registry, clock);
  Executor executor(tree, clock, {.tick_period = 1ms});
  std::thread stopper([&] {
    std::this_thread::sleep_for(50ms);
    executor.requestStop();
  });
  const RunResult result = executor.run();
  stopper.join();
  EXPECT_TRUE(result.stopped);
  EXPECT_EQ(result.status, Status::kIdle);
  EXPECT_EQ(log.count("move:halt"), 1);
  EXPECT_EQ(tree.root().status(), Status::kIdle);
}

TEST(Executor, PauseStopsTheTicksStepTicksOnceResumeGoesOn) {
  testing::TestTree t(R"(<Sequence><TestLeaf name="a"/><TestLeaf name="b"/><TestLeaf name="c"/></Sequence>)");
  Executor executor(t.tree, t.clock);
  executor.pause();
  int hooks = 0;
  executor.setBeforeTick([&] {
    ++hooks;
    if (hooks == 5) {
      EXPECT_TRUE(t.log.events.empty());  // paused: nothing ticked, time went on
      executor.step();
    }
  });
  const RunResult result = executor.run();
  EXPECT_EQ(result.status, Status::kSuccess);
  EXPECT_EQ(result.ticks, 1u);             // one tick: the step
  EXPECT_EQ(t.log.count("c:success"), 1);  // it ran the whole (synchronous) tree
  EXPECT_EQ(result.elapsed, 40ms);         // four paused periods went by first
}

TEST(Executor, BeforeTickHookRunsBeforeEveryTick) {
  testing::TestTree t(R"(<TestLeaf ticks="4"/>)");
  Executor executor(t.tree, t.clock);
  int calls = 0;
  executor.setBeforeTick([&] { ++calls; });
  const RunResult result = executor.run();
  EXPECT_EQ(calls, 5);
  EXPECT_EQ(result.ticks, 5u);
}

std::string contents(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

TEST(Executor, AFileTraceHoldsEveryTickButTheCurrentOneWhileTheRunGoesOnAndAllAfterClose) {
  // What SIGKILL leaves: the file as it is between two ticks.
  const std::filesystem::path file =
      std::filesystem::temp_directory_path() / ("costar_trace_" + std::to_string(::getpid()) + ".jsonl");
  testing::TestTree t(R"(<Sequence><TestLeaf name="a" ticks="2"/><TestLeaf name="b" ticks="3"/></Sequence>)");
  JsonLinesFileTrace trace(file);
  std::ostringstream expected;
  JsonLinesTrace all(expected);
  t.tree.addObserver(&trace);
  t.tree.addObserver(&all);
  Executor executor(t.tree, t.clock);
  int checked = 0;
  executor.setBeforeTick([&] {
    trace.flush();
    EXPECT_EQ(contents(file), expected.str()) << "before tick " << checked;
    ++checked;
  });
  const RunResult result = executor.run();
  EXPECT_EQ(result.status, Status::kSuccess);
  EXPECT_EQ(checked, static_cast<int>(result.ticks));  // checked before every tick
  trace.close();
  EXPECT_TRUE(trace.error().empty()) << trace.error();
  EXPECT_EQ(contents(file), expected.str());
  EXPECT_NE(expected.str().find(R"("to":"SUCCESS")"), std::string::npos);
  std::filesystem::remove(file);
}

TEST(Executor, AFileTraceThatCannotBeWrittenSaysSoAndTheRunGoesOn) {
  testing::TestTree t(R"(<TestLeaf name="a" ticks="2"/>)");
  JsonLinesFileTrace trace("/dev/full");
  t.tree.addObserver(&trace);
  Executor executor(t.tree, t.clock);
  executor.setBeforeTick([&] { trace.flush(); });
  EXPECT_EQ(executor.run().status, Status::kSuccess);
  trace.close();
  EXPECT_EQ(trace.error(), "cannot write '/dev/full': No space left on device");
}

}  // namespace
}  // namespace costar::bt
