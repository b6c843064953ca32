#include "faults/injector.h"

#include <gtest/gtest.h>

#include <cmath>

#include "faults/test/fakes.h"

namespace costar::faults {
namespace {

using test::GoodAdaptiveFingers;
using test::GoodArm;
using test::GoodCamera;
using test::GoodComponent;
using test::GoodFingers;

std::shared_ptr<Injector> injector(const std::vector<std::string>& specs, const Clock& clock, std::uint64_t seed = 1) {
  auto made = Injector::fromText(specs, seed);
  made->attach(clock);
  return made;
}

TEST(Injector, PassesCallsThroughUntilTheFaultIsDue) {
  SimClock clock;
  GoodArm arm(clock);
  auto faults = injector({"nan:arm-driver@t=1s"}, clock);
  arm::ArmDriver& wrapped = faults->wrap(arm);
  ASSERT_NE(&wrapped, &arm);
  clock.advanceTo(TimePoint(fromSeconds(0.5)));
  EXPECT_DOUBLE_EQ(wrapped.read().position[5], 0.5);
  EXPECT_FALSE(faults->records()[0].activated);
  clock.advanceTo(TimePoint(fromSeconds(1.0)));
  EXPECT_TRUE(std::isnan(wrapped.read().position[0]));
  EXPECT_TRUE(std::isnan(wrapped.read().velocity[3]));
  ASSERT_TRUE(faults->records()[0].activated);
  EXPECT_DOUBLE_EQ(toSeconds(*faults->records()[0].activated), 1.0);
  EXPECT_DOUBLE_EQ(toSeconds(*faults->records()[0].first_effect), 1.0);
  // Commands still reach the controller.
  wrapped.execute(nullptr, clock.now());
  EXPECT_EQ(arm.commands, 1);
}

TEST(Injector, AHungDriverKeepsAnsweringWithItsLastReading) {
  SimClock clock;
  GoodArm arm(clock);
  GoodFingers fingers(clock);
  auto faults = injector({"hang:arm-driver@t=1s", "hang:gripper-driver@t=1s"}, clock);
  arm::ArmDriver& wrapped_arm = faults->wrap(arm);
  gripper::GripperDriver& wrapped_fingers = faults->wrap(fingers);
  clock.advanceTo(TimePoint(fromSeconds(0.9)));
  wrapped_arm.read();
  wrapped_fingers.read();
  clock.advanceTo(TimePoint(fromSeconds(2.0)));
  EXPECT_DOUBLE_EQ(wrapped_arm.read().position[5], 0.9);
  EXPECT_DOUBLE_EQ(toSeconds(wrapped_arm.read().stamp), 0.9);
  EXPECT_DOUBLE_EQ(toSeconds(wrapped_fingers.read().stamp), 0.9);
  wrapped_fingers.command(0.0, 0.1, 10.0);
  EXPECT_EQ(fingers.commands, 1);
}

TEST(Injector, AThrowingDriverThrowsFromNowOnNamingTheFault) {
  SimClock clock;
  GoodFingers fingers(clock);
  auto faults = injector({"throw:gripper-driver@op=2"}, clock);
  gripper::GripperDriver& wrapped = faults->wrap(fingers);
  wrapped.command(0.0, 0.1, 10.0);
  EXPECT_NO_THROW(wrapped.read());
  wrapped.command(0.085, 0.1, 10.0);  // the 2nd command makes it due
  for (int i = 0; i < 2; ++i) {
    try {
      wrapped.read();
      ADD_FAILURE() << "no exception";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find("throw:gripper-driver@op=2"), std::string::npos) << e.what();
    }
  }
}

TEST(Injector, BreaksAThreeFingerGrippersReadingsAsThoseOfTwoFingers) {
  // The same target, "gripper-driver", on a cell with the adaptive gripper (iiwa-3f-sim).
  SimClock clock;
  GoodAdaptiveFingers fingers(clock);
  auto nan = injector({"nan:gripper-driver@op=2"}, clock);
  gripper::AdaptiveGripperDriver& wrapped = nan->wrap(fingers);
  ASSERT_NE(&wrapped, &fingers);
  EXPECT_NO_THROW(nan->checkTargets());
  wrapped.commandMode(gripper::GripperMode::kPinch);
  EXPECT_DOUBLE_EQ(wrapped.read().fingers[2].position, 0.25);
  wrapped.commandFingers({1.0, 1.0, 1.0}, 0.5, 20.0);  // the 2nd command makes it due
  EXPECT_EQ(fingers.commands, 2);                      // commands still reach the gripper
  for (const auto& finger : wrapped.read().fingers) {
    EXPECT_TRUE(std::isnan(finger.position));
    EXPECT_TRUE(std::isnan(finger.force));
  }
  ASSERT_TRUE(nan->records()[0].first_effect);

  GoodAdaptiveFingers other(clock);
  auto hang = injector({"hang:gripper-driver@t=1s"}, clock);
  gripper::AdaptiveGripperDriver& hung = hang->wrap(other);
  clock.advanceTo(TimePoint(fromSeconds(0.5)));
  hung.read();
  clock.advanceTo(TimePoint(fromSeconds(2.0)));
  EXPECT_DOUBLE_EQ(toSeconds(hung.read().stamp), 0.5);

  auto broken = injector({"throw:gripper-driver@t=0s"}, clock);
  gripper::AdaptiveGripperDriver& throwing = broken->wrap(other);
  try {
    throwing.read();
    ADD_FAILURE() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("throw:gripper-driver@t=0s"), std::string::npos) << e.what();
  }
}

TEST(Injector, BreaksCameraFramesAtTheChosenFrame) {
  SimClock clock;
  GoodCamera good(clock);
  auto faults = injector({"empty-frame:camera@op=2", "nan-frame:camera@op=4"}, clock);
  camera::RgbdCamera& camera = faults->wrap(good);
  EXPECT_EQ(camera.capture().validCount(), 48u);
  EXPECT_TRUE(camera.capture().points.empty());  // 2nd frame: empty from here on
  EXPECT_TRUE(camera.capture().points.empty());
  // Both faults wrap the camera; the outer (nan-frame) counts its own frames.
  SimClock clock2;
  GoodCamera good2(clock2);
  auto hang = injector({"hang:camera@op=2"}, clock2);
  camera::RgbdCamera& hung = hang->wrap(good2);
  clock2.advanceBy(std::chrono::milliseconds(33));
  const camera::RgbdFrame first = hung.capture();
  clock2.advanceBy(std::chrono::milliseconds(33));
  EXPECT_EQ(hung.capture().stamp, first.stamp);  // the stream stopped: the same frame again
  auto nan = injector({"nan-frame:camera@op=1"}, clock2);
  EXPECT_EQ(nan->wrap(good2).capture().validCount(), 0u);
}

TEST(Injector, TheCameraStreamsStatusShowsTheFaultBetweenFrames) {
  // What a health monitor sees without taking a frame; asking does not count for op=N.
  SimClock clock;
  GoodCamera good(clock);
  auto hang = injector({"hang:camera@t=1s"}, clock);
  camera::RgbdCamera& hung = hang->wrap(good);
  clock.advanceTo(TimePoint(fromSeconds(0.9)));
  ASSERT_TRUE(hung.streamStatus());
  EXPECT_DOUBLE_EQ(toSeconds(hung.streamStatus()->stamp), 0.9);
  EXPECT_FALSE(hang->records()[0].first_effect);
  clock.advanceTo(TimePoint(fromSeconds(1.5)));
  EXPECT_DOUBLE_EQ(toSeconds(hung.streamStatus()->stamp), 0.9) << "no frame since the fault";
  ASSERT_TRUE(hang->records()[0].first_effect);
  EXPECT_DOUBLE_EQ(toSeconds(*hang->records()[0].first_effect), 1.5);

  SimClock clock2;
  GoodCamera good2(clock2);
  auto broken = injector({"empty-frame:camera@op=1", "nan-frame:camera@op=1", "throw:camera@op=2"}, clock2);
  camera::RgbdCamera& camera = broken->wrap(good2);
  EXPECT_EQ(camera.streamStatus()->valid, 48u) << "no frame taken yet: op=1 is not due";
  camera.capture();  // the first frame: empty and NaN from here on; the throw counts 1 frame
  EXPECT_EQ(camera.streamStatus()->points, 0u);
  EXPECT_EQ(camera.streamStatus()->valid, 0u);
  EXPECT_THROW(camera.capture(), std::runtime_error);
  EXPECT_THROW(camera.streamStatus(), std::runtime_error);
}

// Issue 12: a frame lost on the way is one empty frame; the stream goes on after it.
TEST(Injector, ADroppedFrameIsOneEmptyFrameThenTheStreamGoesOn) {
  SimClock clock;
  GoodCamera good(clock);
  auto faults = injector({"drop-frame:camera@op=2"}, clock);
  camera::RgbdCamera& camera = faults->wrap(good);
  EXPECT_EQ(camera.capture().validCount(), 48u);
  EXPECT_TRUE(camera.capture().points.empty());  // the 2nd frame is lost
  EXPECT_EQ(camera.streamStatus()->valid, 48u) << "the stream goes on";
  EXPECT_EQ(camera.capture().validCount(), 48u);
  EXPECT_EQ(camera.capture().validCount(), 48u);
  ASSERT_TRUE(faults->records()[0].first_effect.has_value());
}

component::OperationResult runToEnd(component::Component& component) {
  const component::OperationId id = component.start("Work", {});
  for (int i = 0; i < 10; ++i) {
    const component::OperationResult result = component.poll(id);
    if (result.state != component::OperationState::kRunning) {
      return result;
    }
  }
  return component::OperationResult::failure("did not finish");
}

TEST(Injector, AComponentThrowsOnceThenWorks) {
  SimClock clock;
  auto faults = injector({"throw:worker@op=2"}, clock);
  auto worker = faults->wrap(std::make_shared<GoodComponent>("worker"));
  EXPECT_EQ(runToEnd(*worker).state, component::OperationState::kSuccess);
  EXPECT_THROW(worker->start("Work", {}), std::runtime_error);
  EXPECT_EQ(runToEnd(*worker).state, component::OperationState::kSuccess);
  EXPECT_NO_THROW(worker->report());
}

TEST(Injector, AHungOrDeadComponentFailsEveryCall) {
  SimClock clock;
  auto faults = injector({"hang:sleeper@t=1s", "die:goner@t=1s"}, clock);
  auto sleeper = faults->wrap(std::make_shared<GoodComponent>("sleeper"));
  auto goner = faults->wrap(std::make_shared<GoodComponent>("goner"));
  const component::OperationId id = sleeper->start("Work", {});
  EXPECT_NO_THROW(goner->report());
  clock.advanceTo(TimePoint(fromSeconds(1.0)));
  EXPECT_THROW(sleeper->poll(id), NoAnswer);
  EXPECT_THROW(sleeper->cancel(id), NoAnswer);
  EXPECT_THROW(sleeper->report(), NoAnswer);
  EXPECT_THROW(sleeper->start("Work", {}), NoAnswer);
  try {
    goner->report();
    ADD_FAILURE() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("component 'goner' is gone"), std::string::npos) << e.what();
  }
  EXPECT_EQ(sleeper->description().name, "sleeper");  // known without asking it
}

TEST(Injector, RandomMomentsComeFromTheSeed) {
  const auto due = [](std::uint64_t seed) { return *Injector::fromText({"die:x@random=8s"}, seed)->records()[0].due; };
  EXPECT_EQ(due(7), due(7));
  EXPECT_NE(due(7), due(8));
  EXPECT_LT(toSeconds(due(7)), 8.0);
  EXPECT_GE(toSeconds(due(7)), 0.0);
}

TEST(Injector, RefusesATargetTheCellDoesNotHave) {
  SimClock clock;
  GoodArm arm(clock);
  auto faults = injector({"die:perseption@t=1"}, clock);
  faults->wrap(arm);
  faults->wrap(std::make_shared<GoodComponent>("perception"));
  try {
    faults->checkTargets();
    ADD_FAILURE() << "accepted";
  } catch (const FaultSpecError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("no 'perseption'"), std::string::npos) << message;
    EXPECT_NE(message.find("arm-driver, perception"), std::string::npos) << message;
  }
}

}  // namespace
}  // namespace costar::faults
