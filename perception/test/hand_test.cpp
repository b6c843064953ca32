// The person's hand seen by the camera (perception/hand_detector.h, hand_tracker.h,
// hand_component.h): on the simulated cell with a scripted person, checked against the script's
// pose (the simulator's truth, read here only to check the answers).
#include <gtest/gtest.h>

#include <memory>

#include "perception/hand_component.h"
#include "perception/hand_detector.h"
#include "perception/hand_tracker.h"
#include "perception/perception_component.h"
#include "sim/drivers.h"
#include "sim/person.h"
#include "sim/scene.h"
#include "sim/simulation.h"

namespace costar::perception {
namespace {

/// A person beside a table with a wood link and a red node: reaches palm down, waits, offers
/// (palm up, held), closes, waits, withdraws, leaves.
sim::Scene offeringPerson() {
  return sim::parseScene(R"({"seed": 5, "parts": [{"class": "link", "color": "wood", "at": [0.45, 0.1, 0]},
      {"class": "node", "color": "red", "at": [0.6, -0.2, 0]}],
      "person": {"shoulder": [0.55, 0.8, 0.4], "script": [
      {"do": "reach", "to": [0.5, 0.3, 0.2], "speed": 0.6}, {"do": "wait", "seconds": 1.0},
      {"do": "gesture", "seconds": 1.5}, {"do": "close", "seconds": 0.6}, {"do": "wait", "seconds": 1.0},
      {"do": "withdraw", "speed": 0.6}, {"do": "leave", "speed": 1.6}, {"do": "wait", "seconds": 3}]}})",
                         "hand test");
}

/// The first time from `after` at which the script is at `step` (and offering, if asked), plus `into`.
double timeOf(const sim::PersonMotion& motion, const std::string& step, double after, double into,
              bool offering = false) {
  double t = after;
  while ((motion.at(t).step != step || (offering && !motion.at(t).offering)) && t < motion.duration()) {
    t += 0.01;
  }
  return t + into;
}

Eigen::Vector3d handCentre(const sim::PersonPose& pose) { return pose.wrist + pose.hand * Eigen::Vector3d(0.06, 0, 0); }

TEST(HandDetector, FindsTheHandOverTheTableAndTellsAnOpenPalmTurnedUp) {
  const sim::Scene scene = offeringPerson();
  const auto sim = sim::Simulation::create(scene);
  const sim::PersonMotion motion(*scene.person, scene.seed);
  const auto lookAt = [&](double t) {
    sim->stepTo(TimePoint(fromSeconds(t)));
    const camera::RgbdFrame frame = sim->captureRgbd(1, true);
    return detectHand(frame, frame.camera_pose);
  };
  const double palm_down = timeOf(motion, "wait", 0.0, 0.5);
  const auto down = lookAt(palm_down);
  ASSERT_TRUE(down);
  EXPECT_LT((down->position - handCentre(*sim->person())).norm(), 0.06);
  EXPECT_FALSE(down->open_palm_up) << down->palm_fraction;
  EXPECT_LT(down->direction.y(), -0.5);  // the person reaches from +y towards -y

  const auto offered = lookAt(timeOf(motion, "gesture", palm_down, 0.5, true));
  ASSERT_TRUE(offered);
  EXPECT_LT((offered->position - handCentre(*sim->person())).norm(), 0.06);
  EXPECT_TRUE(offered->open_palm_up) << offered->palm_fraction;

  const double closed_at = timeOf(motion, "wait", timeOf(motion, "close", 0.0, 0.0), 0.3);
  const auto fist = lookAt(closed_at);
  ASSERT_TRUE(fist);
  EXPECT_TRUE(sim->person()->palm_up);                      // the fist's palm is up ...
  EXPECT_FALSE(fist->open_palm_up) << fist->palm_fraction;  // ... but the fingers cover it

  EXPECT_FALSE(lookAt(motion.duration() - 1.0));  // the person has left: the parts are no hand
}

TEST(HandDetector, PartsTheTableAndTheRobotAreNotSkin) {
  const HandOptions options;
  const unsigned char back_of_hand_lit[3] = {255, 240, 194};
  const unsigned char palm_lit[3] = {247, 169, 169};
  const unsigned char wood_lit[3] = {254, 183, 106};
  const unsigned char red_node[3] = {230, 30, 30};
  const unsigned char grey[3] = {180, 180, 180};
  EXPECT_TRUE(isSkinColour(back_of_hand_lit, options));
  EXPECT_TRUE(isSkinColour(palm_lit, options));
  EXPECT_FALSE(isSkinColour(wood_lit, options));
  EXPECT_FALSE(isSkinColour(red_node, options));
  EXPECT_FALSE(isSkinColour(grey, options));
  // The whole cell without a person (parts, table, the arm): no hand.
  const auto sim = sim::Simulation::create(sim::parseScene(
      R"({"seed": 5, "parts": [{"class": "link", "color": "wood", "at": [0.45, 0.1, 0]},
          {"class": "node", "color": "red", "at": [0.6, -0.2, 0]}, {"class": "node", "color": "blue", "at": [0.4, -0.1, 0]}]})",
      "hand test"));
  const camera::RgbdFrame frame = sim->captureRgbd(1, true);
  EXPECT_FALSE(detectHand(frame, frame.camera_pose));
  camera::RgbdFrame no_colour = frame;
  no_colour.rgb = RgbImage();
  EXPECT_THROW(detectHand(no_colour, no_colour.camera_pose), std::invalid_argument);
}

HandObservation observed(const Eigen::Vector3d& at, bool open_palm_up) {
  HandObservation seen;
  seen.position = at;
  seen.open_palm_up = open_palm_up;
  return seen;
}

TEST(HandTracker, TheGestureIsAnOpenPalmUpHeldStillForItsTime) {
  HandTracker tracker({.still_tolerance = 0.015, .hold_seconds = 0.5, .lost_after = 0.3});
  const auto at = [](double s) { return TimePoint(fromSeconds(s)); };
  // Moving with the palm up: no gesture.
  for (int i = 0; i <= 10; ++i) {
    tracker.update(observed(Eigen::Vector3d(0.5, 0.3 - 0.03 * i, 0.2), true), at(0.1 * i));
  }
  ASSERT_TRUE(tracker.hand());
  EXPECT_FALSE(tracker.hand()->gesture);
  EXPECT_FALSE(tracker.hand()->still);
  // Still (within 1 cm), palm up: the gesture after 0.5 s, not before.
  const Eigen::Vector3d rest(0.5, -0.1, 0.2);
  tracker.update(observed(rest, true), at(1.1));
  tracker.update(observed(rest + Eigen::Vector3d(0.01, 0, 0), true), at(1.4));
  EXPECT_TRUE(tracker.hand()->still);
  EXPECT_FALSE(tracker.hand()->gesture);
  tracker.update(observed(rest, true), at(1.6));
  EXPECT_TRUE(tracker.hand()->gesture);
  EXPECT_NEAR(tracker.hand()->still_seconds, 0.5, 1e-9);
  // The palm turned down: no gesture, still the same; up again, the hold starts again.
  tracker.update(observed(rest, false), at(1.7));
  EXPECT_FALSE(tracker.hand()->gesture);
  EXPECT_TRUE(tracker.hand()->still);
  tracker.update(observed(rest, true), at(1.8));
  EXPECT_FALSE(tracker.hand()->gesture);
  tracker.update(observed(rest, true), at(2.3));
  EXPECT_TRUE(tracker.hand()->gesture);
  // Missed for 0.2 s: kept; for more than 0.3 s: gone.
  tracker.update(std::nullopt, at(2.5));
  EXPECT_TRUE(tracker.hand());
  tracker.update(std::nullopt, at(2.7));
  EXPECT_FALSE(tracker.hand());
  EXPECT_THROW(tracker.update(std::nullopt, at(2.0)), std::invalid_argument);
}

TEST(HandComponent, ReportsTheHandItsZoneAndTheGestureFromTheCamera) {
  const sim::Scene scene = offeringPerson();
  SimClock clock;
  const auto sim = sim::Simulation::create(scene);
  sim->attach(clock);
  sim::SimRgbdCamera camera(*sim, 3);
  HandComponent hand(camera, clock);
  EXPECT_EQ(hand.description().type, "HandPerception");
  const sim::PersonMotion motion(*scene.person, scene.seed);
  bool gesture_seen = false;
  bool gesture_while_not_offering = false;
  bool palm_down_in_zone = false;
  double gesture_latency = -1.0;
  const double offer_from = timeOf(motion, "gesture", 0.0, 0.0, true);
  while (toSeconds(clock.now()) < motion.duration()) {
    clock.advanceBy(std::chrono::milliseconds(20));
    const world::Report report = hand.report();
    bool gesture = false;
    bool in_zone = false;
    for (const auto& predicate : report.predicates) {
      gesture = gesture || (predicate.name == "gesture" && predicate.value && predicate.args[1] == "offer");
      in_zone = in_zone || (predicate.name == "in_zone" && predicate.value && predicate.args[1] == "handover");
    }
    const sim::PersonPose truth = *sim->person();
    if (gesture && gesture_latency < 0.0) {
      gesture_latency = toSeconds(clock.now()) - offer_from;
    }
    gesture_seen = gesture_seen || gesture;
    gesture_while_not_offering = gesture_while_not_offering || (gesture && !truth.palm_up);
    palm_down_in_zone = palm_down_in_zone || (truth.step == "wait" && !truth.palm_up && in_zone);
    if (truth.step == "leave" && toSeconds(clock.now()) > motion.duration() - 1.0) {
      EXPECT_TRUE(report.symbols.empty());
    }
  }
  EXPECT_TRUE(gesture_seen);
  EXPECT_FALSE(gesture_while_not_offering);
  EXPECT_TRUE(palm_down_in_zone);  // the hand over the table's person side, y 0.2-0.3
  // The script offers from offer_from, once its palm has turned up (0.4 s); the camera sees the
  // palm up part way through the turn, and the gesture once held 0.5 s, within two frames.
  EXPECT_GE(gesture_latency, 0.5 - 0.4);
  EXPECT_LE(gesture_latency, 0.5 + 0.2);
  EXPECT_THROW(
      HandComponent(camera, clock, {.zones = {{"bad", {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, -1, 1)}}}}),
      std::invalid_argument);
}

TEST(HandDetector, DetectObjectsNeverReportsTheHandAsAPart) {
  // The open hand held over the table beside a node, and a fist near the link: DetectObjects
  // finds the two parts and nothing where the hand is.
  const sim::Scene scene = offeringPerson();
  SimClock clock;
  const auto sim = sim::Simulation::create(scene);
  sim->attach(clock);
  sim::SimRgbdCamera camera(*sim, 7);
  PerceptionConfig config;
  config.frames = 5;
  PerceptionComponent perception(camera, clock, config);
  const sim::PersonMotion motion(*scene.person, scene.seed);
  for (const double t : {timeOf(motion, "gesture", 0.0, 0.6, true), timeOf(motion, "close", 0.0, 0.9)}) {
    clock.advanceBy(TimePoint(fromSeconds(t)) - clock.now());
    const component::OperationId id = perception.start("DetectObjects", {{"frames", 5}});
    component::OperationResult result;
    for (int i = 0; i < 1000; ++i) {
      result = perception.poll(id);
      if (result.state != component::OperationState::kRunning) {
        break;
      }
      clock.advanceBy(std::chrono::milliseconds(10));
    }
    ASSERT_EQ(result.state, component::OperationState::kSuccess) << result.reason;
    const Eigen::Vector3d hand_at = handCentre(*sim->person());
    int parts = 0;
    for (const TrackedObject& object : perception.objects()) {
      EXPECT_GT((object.pose.translation() - hand_at).norm(), 0.12) << object.name << " at the hand";
      parts += object.pose.translation().z() < 0.06 ? 1 : 0;
    }
    EXPECT_EQ(parts, 2);
    EXPECT_EQ(perception.objects().size(), 2u);
  }
}

}  // namespace
}  // namespace costar::perception
