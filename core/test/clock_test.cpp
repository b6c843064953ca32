#include "core/clock.h"

#include <gtest/gtest.h>

#include <chrono>
#include <vector>

namespace costar {
namespace {

using namespace std::chrono_literals;

TEST(SimClock, StartsAtZeroAndAdvancesOnlyWhenAsked) {
  SimClock clock;
  EXPECT_EQ(clock.now().time_since_epoch(), 0ns);
  clock.sleepUntil(TimePoint(5ms));
  EXPECT_EQ(clock.now().time_since_epoch(), 5ms);
  clock.advanceBy(1ms);
  EXPECT_EQ(clock.now().time_since_epoch(), 6ms);
  clock.advanceTo(TimePoint(2ms));  // never goes backwards
  EXPECT_EQ(clock.now().time_since_epoch(), 6ms);
  EXPECT_TRUE(clock.simulated());
}

TEST(SimClock, ListenersSimulateEachIntervalBeforeTimeMoves) {
  SimClock clock;
  std::vector<std::pair<Duration, Duration>> steps;
  const int handle = clock.addStepListener([&](TimePoint from, TimePoint to) {
    EXPECT_EQ(clock.now(), from);  // time has not moved yet while the step runs
    steps.emplace_back(from.time_since_epoch(), to.time_since_epoch());
  });
  clock.advanceBy(10ms);
  clock.advanceBy(0ms);  // no interval, no call
  clock.advanceBy(5ms);
  clock.removeStepListener(handle);
  clock.advanceBy(5ms);
  ASSERT_EQ(steps.size(), 2u);
  EXPECT_EQ(steps[0], std::make_pair(Duration(0ms), Duration(10ms)));
  EXPECT_EQ(steps[1], std::make_pair(Duration(10ms), Duration(15ms)));
}

TEST(RealClock, SleepsAtLeastUntilTheDeadline) {
  RealClock clock;
  const TimePoint deadline = clock.now() + 20ms;
  clock.sleepUntil(deadline);
  EXPECT_GE(clock.now(), deadline);
  EXPECT_FALSE(clock.simulated());
}

}  // namespace
}  // namespace costar
