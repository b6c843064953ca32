// Pacing a simulated clock to a multiple of wall time (no sleeping: times are given).

#include "server/pacing.h"

#include <gtest/gtest.h>

namespace costar::server {
namespace {

using Wall = Pacer::WallClock;
using std::chrono::milliseconds;

TimePoint sim(int ms) { return TimePoint(milliseconds(ms)); }
Wall::time_point wall(int ms) { return Wall::time_point(milliseconds(1000000 + ms)); }

TEST(Pacer, KeepsSimulatedTimeAtTheFactorTimesWallTime) {
  Pacer pacer(1.0);
  EXPECT_EQ(pacer.delay(sim(0), wall(0)), Wall::duration::zero());  // anchors
  EXPECT_EQ(pacer.delay(sim(500), wall(100)), milliseconds(400));
  EXPECT_EQ(pacer.delay(sim(500), wall(600)), Wall::duration::zero());

  Pacer fast(2.0);
  fast.delay(sim(0), wall(0));
  EXPECT_EQ(fast.delay(sim(1000), wall(200)), milliseconds(300));

  Pacer slow(0.5);
  slow.delay(sim(0), wall(0));
  EXPECT_EQ(slow.delay(sim(100), wall(0)), milliseconds(200));
}

TEST(Pacer, ZeroFactorDoesNotPace) {
  Pacer pacer(0.0);
  EXPECT_EQ(pacer.delay(sim(0), wall(0)), Wall::duration::zero());
  EXPECT_EQ(pacer.delay(sim(100000), wall(1)), Wall::duration::zero());
}

TEST(Pacer, DoesNotRaceToCatchUpAfterFallingBehind) {
  Pacer pacer(1.0);
  pacer.delay(sim(0), wall(0));
  // A long computation: wall time ran 2 s ahead while simulated time stood still.
  EXPECT_EQ(pacer.delay(sim(10), wall(2000)), Wall::duration::zero());
  // From here the reference is (10 ms, 2000 ms): the next 100 ms of simulation take 100 ms.
  EXPECT_EQ(pacer.delay(sim(110), wall(2000)), milliseconds(100));
}

TEST(Pacer, ChangingTheFactorStartsAfresh) {
  Pacer pacer(1.0);
  pacer.delay(sim(0), wall(0));
  pacer.setFactor(4.0);
  EXPECT_EQ(pacer.delay(sim(5000), wall(10)), Wall::duration::zero());
  EXPECT_EQ(pacer.delay(sim(5400), wall(10)), milliseconds(100));
}

}  // namespace
}  // namespace costar::server
