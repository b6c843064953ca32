#include "gripper/adaptive_gripper.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "component/abstract.h"
#include "core/paths.h"
#include "gripper/parallel_gripper.h"
#include "world/world_state.h"

namespace costar::gripper {
namespace {

using component::OperationResult;
using component::OperationState;

/// Three fingers that move at the commanded speed and stop where a part blocks them; a scissor
/// axis that takes 200 ms to reach a mode.
class FakeHand final : public AdaptiveGripperDriver {
 public:
  explicit FakeHand(SimClock& clock) : clock_(clock) {
    clock_.addStepListener([this](TimePoint from, TimePoint to) { advance(toSeconds(to - from)); });
  }
  AdaptiveGripperReading read() const override {
    AdaptiveGripperReading reading = reading_;
    reading.stamp = stale ? TimePoint{} + std::chrono::milliseconds(1) : clock_.now();
    if (broken) {
      reading.fingers[1].position = std::nan("");
    }
    return reading;
  }
  void commandFingers(const std::array<double, kFingerCount>& positions, double speed, double force) override {
    targets_ = positions;
    speed_ = speed;
    force_ = force;
    ++finger_commands;
  }
  void commandMode(GripperMode mode) override {
    reading_.mode = mode;
    reading_.mode_reached = false;
    mode_time_ = 0.0;
  }

  /// Where a part stops each finger (1: nothing in the way).
  std::array<double, kFingerCount> block = {1.0, 1.0, 1.0};
  bool stale = false;
  bool broken = false;
  bool scissor_jammed = false;
  int finger_commands = 0;

 private:
  void advance(double dt) {
    for (std::size_t i = 0; i < kFingerCount; ++i) {
      auto& finger = reading_.fingers[i];
      const double wanted = std::min(targets_[i], block[i]);
      const double step = std::clamp(wanted - finger.position, -speed_ * dt, speed_ * dt);
      finger.position += step;
      finger.speed = step / dt;
      const bool blocked = block[i] < 1.0 && finger.position >= block[i] - 1e-9 && targets_[i] > block[i];
      finger.contact = blocked;
      finger.force = blocked ? force_ : 0.0;
    }
    mode_time_ += dt;
    if (!scissor_jammed && mode_time_ >= 0.2) {
      reading_.mode_reached = true;
    }
  }

  SimClock& clock_;
  AdaptiveGripperReading reading_{};
  std::array<double, kFingerCount> targets_{};
  double speed_ = 0.5;
  double force_ = 40.0;
  double mode_time_ = 1.0;
};

AdaptiveGripperDescription robotiq3f() { return loadAdaptiveGripperDescription(gripperDescriptionFile("robotiq3f")); }

class AdaptiveGripperTest : public ::testing::Test {
 protected:
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
  FakeHand hand{clock};
  AdaptiveGripper gripper{hand, clock, robotiq3f()};
};

TEST(AdaptiveGripperDescriptionTest, ReadsTheFourModesFromTheGeneratorsFile) {
  const AdaptiveGripperDescription description = robotiq3f();
  EXPECT_EQ(description.name, "robotiq3f");
  ASSERT_EQ(description.modes.size(), 4u);
  EXPECT_DOUBLE_EQ(description.mode(GripperMode::kBasic).scissor_deg, 0.0);
  EXPECT_GT(description.mode(GripperMode::kPinch).scissor_deg, 0.0);  // turned toward each other
  EXPECT_LT(description.mode(GripperMode::kWide).scissor_deg, 0.0);   // spread
  EXPECT_NEAR(description.mode(GripperMode::kScissor).scissor_deg, 90.0, 1e-9);
  // In Scissor mode only fingers 1 and 2 close; elsewhere all three.
  EXPECT_EQ(description.mode(GripperMode::kScissor).closing, (std::array<bool, 3>{false, true, true}));
  EXPECT_EQ(description.mode(GripperMode::kBasic).closing, (std::array<bool, 3>{true, true, true}));
  EXPECT_GT(description.max_force, 0.0);
}

TEST(AdaptiveGripperDescriptionTest, BadFilesNameTheFieldAndTheProblem) {
  const auto dir = std::filesystem::temp_directory_path() / "costar_adaptive_gripper_test";
  std::filesystem::create_directories(dir);
  const auto write = [&](const std::string& text) {
    const auto file = dir / "robotiq3f.json";  // a description's name is its file's
    std::ofstream(file) << text;
    return file;
  };
  const auto error = [](const std::filesystem::path& file) {
    try {
      loadAdaptiveGripperDescription(file);
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  std::ifstream in(gripperDescriptionFile("robotiq3f"));
  std::string good((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(error(dir / "missing.json").find("No such file or directory"), std::string::npos);
  EXPECT_NE(error(write("{")).find("costar_adaptive_gripper_test/robotiq3f.json"), std::string::npos);
  std::string unknown_mode = good;
  unknown_mode.replace(unknown_mode.find("\"name\": \"wide\""), 14, "\"name\": \"wild\"");
  EXPECT_NE(error(write(unknown_mode)).find("modes[2].name: must be one of basic, pinch, wide, scissor"),
            std::string::npos)
      << error(write(unknown_mode));
  std::string bad_finger = good;
  bad_finger.replace(bad_finger.find("\"closing\": [\"finger_1\""), 22, "\"closing\": [\"finger_9\"");
  EXPECT_NE(error(write(bad_finger)).find("modes[3].closing[0]"), std::string::npos) << error(write(bad_finger));
  // Issue 27: negative and 1e308 phalanges passed; a key given twice was taken silently.
  const auto phalanx = [&good](const std::string& length) {
    const std::string medial = "\"length\": 0.035";
    std::string text = good;
    text.replace(text.find(medial), medial.size(), "\"length\": " + length);
    return text;
  };
  EXPECT_NE(error(write(phalanx("-0.035")))
                .find("phalanges[1].length: must be a length above 0 and at most 0.5 m, not "
                      "-0.035"),
            std::string::npos)
      << error(write(phalanx("-0.035")));
  EXPECT_NE(error(write(phalanx("1e308"))).find("phalanges[1].length: must be at most 0.5 in magnitude, not 1e+308"),
            std::string::npos)
      << error(write(phalanx("1e308")));
  std::string twice = good;
  const std::string tcp = "\"tcp\": [";
  twice.replace(twice.find(tcp), tcp.size(), "\"tcp\": [0, 0, 0.1], \"tcp\": [");
  EXPECT_NE(error(write(twice)).find("(top level): key 'tcp' appears twice"), std::string::npos) << error(write(twice));
  std::filesystem::remove_all(dir);
}

TEST_F(AdaptiveGripperTest, ImplementsTheAbstractGripper) {
  EXPECT_TRUE(component::missingRequirements(component::abstractGripper(), gripper.description()).empty());
  for (const auto* name : {"Open", "Close", "SetMode", "BasicMode", "PinchMode", "WideMode", "ScissorMode"}) {
    EXPECT_NE(gripper.description().operation(name), nullptr) << name;
  }
}

TEST_F(AdaptiveGripperTest, StartsOpenInBasicMode) {
  EXPECT_TRUE(holds("gripper_open"));
  EXPECT_FALSE(holds("gripper_closed"));
  EXPECT_FALSE(holds("gripper_holding"));
  EXPECT_TRUE(holds("gripper_mode", {"basic"}));
}

TEST_F(AdaptiveGripperTest, CloseOnNothingClosesFully) {
  const OperationResult result = run("Close");
  ASSERT_EQ(result.state, OperationState::kSuccess) << result.reason;
  EXPECT_FALSE(result.data.at("holding").get<bool>());
  EXPECT_TRUE(holds("gripper_closed"));
  EXPECT_FALSE(holds("gripper_open"));
  EXPECT_FALSE(holds("gripper_holding"));
}

// The fingers' reading is a symbol (the editor draws the fingers from it): each finger's
// position, finger_middle first.
TEST_F(AdaptiveGripperTest, TheReportCarriesEachFingersPosition) {
  hand.block = {0.3, 0.35, 0.32};
  ASSERT_EQ(run("Close", {{"force", 30.0}}).state, OperationState::kSuccess);
  world::WorldState world;
  world.update("gripper", gripper.report());
  const world::Symbol* fingers = world.symbol("gripper_fingers");
  ASSERT_NE(fingers, nullptr);
  ASSERT_NE(fingers->joints(), nullptr);
  EXPECT_EQ(fingers->joints()->joint_names, (std::vector<std::string>{"finger_middle", "finger_1", "finger_2"}));
  ASSERT_EQ(fingers->joints()->positions.size(), 3u);
  EXPECT_NEAR(fingers->joints()->positions[0], 0.3, 0.02);
  EXPECT_NEAR(fingers->joints()->positions[1], 0.35, 0.02);
}

TEST_F(AdaptiveGripperTest, CloseOnAPartHoldsIt) {
  hand.block = {0.3, 0.35, 0.32};
  const OperationResult result = run("Close", {{"force", 30.0}});
  ASSERT_EQ(result.state, OperationState::kSuccess) << result.reason;
  EXPECT_TRUE(result.data.at("holding").get<bool>());
  EXPECT_NEAR(result.data.at("fingers").at("finger_1").at("position").get<double>(), 0.35, 0.01);
  EXPECT_TRUE(holds("gripper_holding"));
  EXPECT_FALSE(holds("gripper_closed"));
  // Open lets go.
  ASSERT_EQ(run("Open").state, OperationState::kSuccess);
  EXPECT_TRUE(holds("gripper_open"));
  EXPECT_FALSE(holds("gripper_holding"));
}

TEST_F(AdaptiveGripperTest, OneFingerOnSomethingIsNotHolding) {
  hand.block = {0.3, 1.0, 1.0};  // the part touches finger_middle only
  const OperationResult result = run("Close");
  ASSERT_EQ(result.state, OperationState::kSuccess);
  EXPECT_FALSE(result.data.at("holding").get<bool>());
  EXPECT_FALSE(holds("gripper_holding"));
}

TEST_F(AdaptiveGripperTest, EveryModeIsReachedAndReported) {
  for (const GripperMode mode : kGripperModes) {
    const OperationResult result = run("SetMode", {{"mode", std::string(toString(mode))}});
    ASSERT_EQ(result.state, OperationState::kSuccess) << toString(mode) << ": " << result.reason;
    EXPECT_TRUE(holds("gripper_mode", {std::string(toString(mode))})) << toString(mode);
  }
  // The abstract Gripper's per-mode operations do the same.
  ASSERT_EQ(run("PinchMode").state, OperationState::kSuccess);
  EXPECT_TRUE(holds("gripper_mode", {"pinch"}));
  EXPECT_FALSE(holds("gripper_mode", {"scissor"}));
}

TEST_F(AdaptiveGripperTest, ScissorModeClosesFingersOneAndTwoOnly) {
  ASSERT_EQ(run("ScissorMode").state, OperationState::kSuccess);
  ASSERT_EQ(run("Close").state, OperationState::kSuccess);
  const auto reading = hand.read();
  EXPECT_LT(reading.fingers[0].position, 0.01);  // finger_middle stays open
  EXPECT_GT(reading.fingers[1].position, 0.99);
  EXPECT_GT(reading.fingers[2].position, 0.99);
  EXPECT_TRUE(holds("gripper_closed"));  // closed: the mode's closing fingers are
}

TEST_F(AdaptiveGripperTest, InPinchModeTheFingersOpenPartWayElsewhereOpenRefuses) {
  // In Basic mode the fingers curl as they close: only fully open is modelled.
  try {
    run("Open", {{"position", 0.3}});
    ADD_FAILURE() << "opened part way in basic mode";
  } catch (const std::invalid_argument& e) {  // it cannot start: the reason
    EXPECT_NE(std::string(e.what()).find("only in a fingertip mode"), std::string::npos) << e.what();
  }
  ASSERT_EQ(run("PinchMode").state, OperationState::kSuccess);
  ASSERT_EQ(run("Open", {{"position", 0.3}}).state, OperationState::kSuccess);
  for (const auto& finger : hand.read().fingers) {
    EXPECT_NEAR(finger.position, 0.3, 0.011);
  }
  EXPECT_FALSE(holds("gripper_open"));
  ASSERT_EQ(run("Open").state, OperationState::kSuccess);
  EXPECT_TRUE(holds("gripper_open"));
}

TEST(AdaptiveGripperDescriptionTest, PinchFingersClosedPartWayClearAPartAndStayStraight) {
  const AdaptiveGripperDescription description = robotiq3f();
  // Open, the fingertips lean out past their knuckles (4.5 cm from the axis, 1.6 cm thick);
  // closing turns them in, so the clear width shrinks as the position grows.
  const double open = fingertipClearance(description, GripperMode::kPinch, 0.0);
  EXPECT_GT(open, 0.045);
  double previous = open;
  for (const double position : {0.1, 0.2, 0.3, 0.4}) {
    const double clear = fingertipClearance(description, GripperMode::kPinch, position);
    EXPECT_LT(clear, previous) << position;
    previous = clear;
  }
  // A 2.5 cm part with 8 mm either side: the most closed position that still clears it.
  const double position = fingertipPositionFor(description, GripperMode::kPinch, 0.0205);
  EXPECT_GT(position, 0.0);
  EXPECT_GE(fingertipClearance(description, GripperMode::kPinch, position), 0.0205);
  EXPECT_LT(fingertipClearance(description, GripperMode::kPinch, position + 0.01), 0.0205);
  // Open boxes are the position-0 ones; other modes are modelled open only.
  const auto boxes = openFingerBoxes(description, GripperMode::kPinch);
  const auto at_zero = fingerBoxesAt(description, GripperMode::kPinch, 0.0);
  ASSERT_EQ(boxes.size(), at_zero.size());
  EXPECT_TRUE(boxes[0].pose.isApprox(at_zero[0].pose));
  EXPECT_EQ(fingertipPositionFor(description, GripperMode::kBasic, 0.0205), 0.0);
  EXPECT_THROW(fingerBoxesAt(description, GripperMode::kBasic, 0.3), std::invalid_argument);
}

TEST(AdaptiveGripperDescriptionTest, FingertipsReachAcrossNoFartherThanTheFingers) {
  const AdaptiveGripperDescription description = robotiq3f();
  for (const GripperMode mode : {GripperMode::kBasic, GripperMode::kPinch, GripperMode::kWide, GripperMode::kScissor}) {
    const std::string name(toString(mode));
    const double reach = fingerReachAcross(description, mode);
    // No farther than the open fingers' boxes reach, corner by corner.
    double furthest = 0.0;
    for (const OrientedBox& box : openFingerBoxes(description, mode)) {
      for (int corner = 0; corner < 8; ++corner) {
        const Eigen::Vector3d local(((corner & 1) ? 0.5 : -0.5) * box.size.x(),
                                    ((corner & 2) ? 0.5 : -0.5) * box.size.y(),
                                    ((corner & 4) ? 0.5 : -0.5) * box.size.z());
        furthest = std::max(furthest, std::abs((box.pose * local).x()));
      }
    }
    EXPECT_LE(reach, furthest + 1e-9) << name;
    EXPECT_GE(reach, 0.5 * description.finger_width) << name;
    std::printf("%s: the fingertips reach %.1f mm across (the fingers %.1f mm)\n", name.c_str(), 1000 * reach,
                1000 * furthest);
  }
  // Basic: fingers 1 and 2 stand straight at x = +-28 mm, 24 mm wide: their tips reach 40 mm.
  EXPECT_NEAR(fingerReachAcross(description, GripperMode::kBasic), 0.028 + 0.012, 1e-6);
}

TEST_F(AdaptiveGripperTest, ModeChangeWithClosedFingersFailsAndSaysWhy) {
  hand.block = {0.3, 0.35, 0.32};
  ASSERT_EQ(run("Close").state, OperationState::kSuccess);
  const OperationResult result = run("WideMode");
  ASSERT_EQ(result.state, OperationState::kFailure);
  EXPECT_NE(result.reason.find("Open the gripper first"), std::string::npos) << result.reason;
  EXPECT_TRUE(holds("gripper_mode", {"basic"}));  // nothing moved
  EXPECT_TRUE(holds("gripper_holding"));
}

TEST_F(AdaptiveGripperTest, AJammedScissorAxisTimesOut) {
  hand.scissor_jammed = true;
  const OperationResult result = run("SetMode", {{"mode", std::string("wide")}});
  ASSERT_EQ(result.state, OperationState::kFailure);
  EXPECT_NE(result.reason.find("did not reach wide mode"), std::string::npos) << result.reason;
  EXPECT_FALSE(holds("gripper_mode", {"wide"}));
}

TEST_F(AdaptiveGripperTest, UntrustworthyReadingsStopTheFingers) {
  // Mid-stroke: the operation fails and says why.
  const auto id = gripper.start("Close", {{"speed", 0.5}, {"force", 30.0}});
  clock.advanceBy(std::chrono::milliseconds(100));
  hand.broken = true;
  const OperationResult result = gripper.poll(id);
  ASSERT_EQ(result.state, OperationState::kFailure);
  EXPECT_NE(result.reason.find("finger_1 is not a number; the fingers were stopped"), std::string::npos)
      << result.reason;
  EXPECT_THROW(gripper.report(), std::runtime_error);
  // Before it starts: Close cannot start (the executor reports "could not start: ...").
  EXPECT_THROW(gripper.start("Close", {{"speed", 0.5}, {"force", 30.0}}), std::runtime_error);
  hand.broken = false;
  hand.stale = true;
  clock.advanceBy(std::chrono::seconds(1));
  EXPECT_THROW(gripper.report(), std::runtime_error);
}

TEST(ParallelGripperModesTest, TheTwoFingerGripperRefusesEveryModeButPinch) {
  // The 2-finger gripper's answer to the modes a 3-finger gripper has.
  class Fingers final : public GripperDriver {
   public:
    FingerReading read() const override { return {0.085, 0.0, 0.0, false}; }
    void command(double, double, double) override {}
    double maxOpening() const override { return 0.085; }
  } fingers;
  SimClock clock;
  ParallelGripper gripper(fingers, clock);
  for (const auto* mode : {"BasicMode", "WideMode", "ScissorMode"}) {
    const auto id = gripper.start(mode, {});
    const OperationResult result = gripper.poll(id);
    EXPECT_EQ(result.state, OperationState::kFailure) << mode;
    EXPECT_NE(result.reason.find("only Pinch mode"), std::string::npos) << result.reason;
  }
  const auto id = gripper.start("PinchMode", {});
  EXPECT_EQ(gripper.poll(id).state, OperationState::kSuccess);
  // SetMode, the 3-finger gripper's way, answers the same.
  const auto pinch = gripper.start("SetMode", {{"mode", std::string("pinch")}});
  EXPECT_EQ(gripper.poll(pinch).state, OperationState::kSuccess);
  const auto wide = gripper.start("SetMode", {{"mode", std::string("wide")}});
  const OperationResult refused = gripper.poll(wide);
  EXPECT_EQ(refused.state, OperationState::kFailure);
  EXPECT_NE(refused.reason.find("SetMode(wide): mode not supported by this gripper"), std::string::npos)
      << refused.reason;
}

}  // namespace
}  // namespace costar::gripper
