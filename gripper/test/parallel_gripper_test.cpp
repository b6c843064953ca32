#include "gripper/parallel_gripper.h"

#include <gtest/gtest.h>

#include <algorithm>

#include "component/registry.h"

namespace costar::gripper {
namespace {

using component::OperationResult;
using component::OperationState;

/// Fingers that move at the commanded speed and stop on an object of a given width.
class FakeFingers final : public GripperDriver {
 public:
  explicit FakeFingers(SimClock& clock) : clock_(clock) {
    clock_.addStepListener([this](TimePoint from, TimePoint to) { advance(toSeconds(to - from)); });
  }
  FingerReading read() const override { return reading_; }
  void command(double opening, double speed, double force) override {
    target_ = opening;
    speed_ = speed;
    force_ = force;
    ++commands;
  }
  double maxOpening() const override { return 0.085; }

  double object_width = 0.0;  // 0: nothing between the fingers
  double obstacle_at = 1.0;   // the fingers cannot open beyond this
  bool jammed = false;        // keeps "moving" without getting anywhere
  int commands = 0;

 private:
  void advance(double dt) {
    const double wanted = std::clamp(target_, object_width, std::min(obstacle_at, maxOpening()));
    const double step = jammed ? 0.0 : std::clamp(wanted - reading_.opening, -speed_ * dt, speed_ * dt);
    reading_.opening += step;
    reading_.opening_speed = jammed ? 0.01 : step / dt;
    const bool blocked = object_width > 0 && reading_.opening <= object_width + 1e-9 && target_ < object_width;
    reading_.contact = blocked;
    reading_.force = blocked ? force_ : 0.0;
  }

  SimClock& clock_;
  FingerReading reading_{0.085, 0.0, 0.0, false};
  double target_ = 0.085;
  double speed_ = 0.1;
  double force_ = 40.0;
};

class GripperTest : public ::testing::Test {
 protected:
  /// Runs an operation to completion on the simulated clock (10 ms ticks).
  OperationResult run(const std::string& operation, component::ParamMap params = {}) {
    for (const auto& spec : gripper.description().operation(operation)->params) {
      params.try_emplace(spec.name, *spec.default_value);
    }
    const auto id = gripper.start(operation, params);
    for (int tick = 0; tick < 1000; ++tick) {
      const OperationResult result = gripper.poll(id);
      if (result.state != OperationState::kRunning) {
        return result;
      }
      clock.advanceBy(std::chrono::milliseconds(10));
    }
    return OperationResult::failure("test: did not finish");
  }

  bool holds(const std::string& predicate, std::vector<std::string> args = {}) {
    world::WorldState world;
    world.update("gripper", gripper.report());
    return world.holds(predicate, args);
  }

  SimClock clock;
  FakeFingers fingers{clock};
  ParallelGripper gripper{fingers, clock};
};

TEST_F(GripperTest, ClosingOnAPartStopsOnItAndHoldsIt) {
  fingers.object_width = 0.05;
  EXPECT_TRUE(holds("gripper_open"));
  const OperationResult result = run("Close");
  ASSERT_EQ(result.state, OperationState::kSuccess) << result.reason;
  EXPECT_TRUE(result.data.at("holding").get<bool>());
  EXPECT_NEAR(result.data.at("opening").get<double>(), 0.05, 1e-6);
  EXPECT_TRUE(holds("gripper_holding"));
  EXPECT_FALSE(holds("gripper_open"));
  EXPECT_FALSE(holds("gripper_closed"));
  EXPECT_GT(clock.now().time_since_epoch(), std::chrono::milliseconds(300));  // it took real (simulated) time
}

TEST_F(GripperTest, ClosingOnNothingClosesFully) {
  const OperationResult result = run("Close", {{"speed", 0.15}});
  ASSERT_EQ(result.state, OperationState::kSuccess);
  EXPECT_FALSE(result.data.at("holding").get<bool>());
  EXPECT_TRUE(holds("gripper_closed"));
  EXPECT_FALSE(holds("gripper_holding"));
}

TEST_F(GripperTest, PredicatesComeFromTheFingersNotFromTheCommand) {
  fingers.object_width = 0.05;
  run("Close");
  ASSERT_TRUE(holds("gripper_holding"));
  fingers.object_width = 0.0;  // the part slips out: the fingers close the rest of the way
  clock.advanceBy(std::chrono::milliseconds(600));
  EXPECT_FALSE(holds("gripper_holding"));
  EXPECT_TRUE(holds("gripper_closed"));
}

TEST_F(GripperTest, OpenFailsWithAReasonWhenBlocked) {
  run("Close");
  fingers.obstacle_at = 0.04;
  const OperationResult result = run("Open");
  EXPECT_EQ(result.state, OperationState::kFailure);
  EXPECT_EQ(result.reason, "the fingers are blocked at 40.0 mm: they could not open fully");
  fingers.obstacle_at = 1.0;
  EXPECT_EQ(run("Open").state, OperationState::kSuccess);
  EXPECT_TRUE(holds("gripper_open"));
}

TEST_F(GripperTest, OpenGoesOnlyAsFarAsAskedFromEitherSide) {
  // From fully open the fingers narrow to the opening; from closed they open to it.
  OperationResult result = run("Open", {{"opening", 0.06}});
  ASSERT_EQ(result.state, OperationState::kSuccess) << result.reason;
  EXPECT_NEAR(fingers.read().opening, 0.06, 0.001);
  EXPECT_FALSE(holds("gripper_open"));
  EXPECT_FALSE(holds("gripper_closed"));
  run("Close");
  result = run("Open", {{"opening", 0.045}});
  ASSERT_EQ(result.state, OperationState::kSuccess) << result.reason;
  EXPECT_NEAR(result.data.at("opening").get<double>(), 0.045, 0.001);
  // Something in the way short of the opening asked for.
  fingers.obstacle_at = 0.03;
  run("Close");
  result = run("Open", {{"opening", 0.045}});
  EXPECT_EQ(result.state, OperationState::kFailure);
  EXPECT_EQ(result.reason, "the fingers are blocked at 30.0 mm: they could not reach 45.0 mm");
  // A part between the fingers stops them narrowing.
  fingers.obstacle_at = 1.0;
  run("Open");
  fingers.object_width = 0.05;
  result = run("Open", {{"opening", 0.03}});
  EXPECT_EQ(result.state, OperationState::kFailure);
  EXPECT_EQ(result.reason, "the fingers are blocked at 50.0 mm: they could not reach 30.0 mm");
}

TEST_F(GripperTest, OpenRefusesAnOpeningBeyondTheStroke) {
  const auto* open = gripper.description().operation("Open");
  ASSERT_NE(open, nullptr);
  const auto spec = std::find_if(open->params.begin(), open->params.end(),
                                 [](const component::ParamSpec& p) { return p.name == "opening"; });
  ASSERT_NE(spec, open->params.end());
  EXPECT_FALSE(spec->check("0.09").empty());
  EXPECT_FALSE(spec->check("-0.01").empty());
  EXPECT_TRUE(spec->check("0.05").empty());
}

TEST_F(GripperTest, OnlyPinchModeIsSupported) {
  EXPECT_EQ(run("PinchMode").state, OperationState::kSuccess);
  for (const char* mode : {"BasicMode", "WideMode", "ScissorMode"}) {
    const OperationResult result = run(mode);
    EXPECT_EQ(result.state, OperationState::kFailure);
    EXPECT_NE(result.reason.find("mode not supported by this gripper"), std::string::npos) << mode;
  }
  const std::vector<std::string> pinch{"pinch"};
  EXPECT_TRUE(holds("gripper_mode", pinch));
}

// Plan validation (the editor's Check, costar run) refuses the modes a 2-finger gripper lacks
// before anything runs, with the same reason the operation gives.
TEST_F(GripperTest, ModesOtherThanPinchFailCheck) {
  const auto problem = [&](const std::string& operation, component::ParamMap params = {}) {
    const component::OperationSpec* spec = gripper.description().operation(operation);
    return spec->check ? spec->check(params) : std::string();
  };
  for (const char* mode : {"BasicMode", "WideMode", "ScissorMode"}) {
    EXPECT_NE(problem(mode).find("a parallel 2-finger gripper has only Pinch mode"), std::string::npos) << mode;
  }
  EXPECT_EQ(problem("PinchMode"), "");
  EXPECT_EQ(problem("SetMode", {{"mode", component::Value(std::string("pinch"))}}), "");
  EXPECT_NE(problem("SetMode", {{"mode", component::Value(std::string("scissor"))}}), "");
}

// The fingers' reading is a symbol: the editor draws the fingers from it.
TEST_F(GripperTest, TheReportCarriesTheFingersOpening) {
  run("Close", {{"speed", component::Value(0.15)}});
  world::WorldState world;
  world.update("gripper", gripper.report());
  const world::Symbol* reading = world.symbol("gripper_fingers");
  ASSERT_NE(reading, nullptr);
  ASSERT_NE(reading->joints(), nullptr);
  EXPECT_EQ(reading->joints()->joint_names, std::vector<std::string>{"opening"});
  EXPECT_NEAR(reading->joints()->positions.at(0), 0.0, 1e-3);
}

TEST_F(GripperTest, FingersThatNeverSettleFailAfterTheTimeout) {
  fingers.jammed = true;
  const OperationResult result = run("Close");
  EXPECT_EQ(result.state, OperationState::kFailure);
  EXPECT_NE(result.reason.find("did not settle"), std::string::npos);
  EXPECT_GE(clock.now().time_since_epoch(), std::chrono::seconds(3));
}

TEST_F(GripperTest, CancelStopsTheFingersWhereTheyAre) {
  const auto id = gripper.start("Close", {{"speed", 0.1}, {"force", 40.0}});
  clock.advanceBy(std::chrono::milliseconds(100));
  EXPECT_EQ(gripper.poll(id).state, OperationState::kRunning);
  const int before = fingers.commands;
  gripper.cancel(id);
  EXPECT_EQ(fingers.commands, before + 1);
  const double at_cancel = fingers.read().opening;
  clock.advanceBy(std::chrono::milliseconds(500));
  EXPECT_NEAR(fingers.read().opening, at_cancel, 1e-9);
}

TEST_F(GripperTest, ImplementsTheAbstractGripper) {
  component::ComponentRegistry registry;
  EXPECT_NO_THROW(registry.add(std::make_shared<ParallelGripper>(fingers, clock)));
}

}  // namespace
}  // namespace costar::gripper
