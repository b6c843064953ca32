#include "core/clock.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
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

TEST(CheckedDuration, RefusesNanInfiniteNegativeAndOverflowingSecondsNamingTheOption) {
  for (const double bad : {std::nan(""), std::numeric_limits<double>::infinity(), -1.0, 1e10, 1e308}) {
    try {
      checkedDuration(bad, "--time-limit");
      ADD_FAILURE() << bad << " was accepted";
    } catch (const std::invalid_argument& e) {
      const std::string message = e.what();
      EXPECT_EQ(message.rfind("--time-limit: must be a number of seconds from 0 to 1e+09, not ", 0), 0u) << message;
      EXPECT_LT(message.size(), 100u) << "numbers are printed short: " << message;
    }
  }
  EXPECT_EQ(checkedDuration(2.5, "t"), 2500ms);
  EXPECT_EQ(checkedDuration(1e9, "t"), std::chrono::seconds(1000000000));
  EXPECT_EQ(checkedDuration(0.0, "t"), 0ns);
}

}  // namespace
}  // namespace costar
