// The person beside the cell (sim/person.h, sim/person_sim.h) and the speed and separation
// monitor (sim/speed_separation.h): the script's format and motion, the hand holding a part
// physically, and the arm kept away from the person.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "arm/robot_description.h"
#include "arm/trajectory.h"
#include "core/paths.h"
#include "sim/person.h"
#include "sim/scene.h"
#include "sim/simulation.h"
#include "sim/speed_separation.h"

namespace costar::sim {
namespace {

PersonSpec personOf(const std::string& json) { return parsePerson(json, "person"); }

std::string errorOf(const std::string& json) {
  try {
    parseScene(R"({"parts": [], "person": )" + json + "}", "my.json");
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

TEST(PersonScript, ReadsEveryStepAndWritesTheEntryBack) {
  const Scene scene = parseScene(R"({"parts": [], "person": {"shoulder": [0.55, 0.8, 0.4], "seed": 3, "script": [
      {"do": "reach", "to": [0.45, 0.35, 0.12], "speed": 0.8}, {"do": "gesture", "seconds": 1.5},
      {"do": "wait", "seconds": 2}, {"do": "close", "seconds": 0.6}, {"do": "withdraw"},
      {"do": "reach_random", "min": [0.3, 0.2, 0.05], "max": [0.7, 0.4, 0.3], "speed": 1.6},
      {"do": "open", "seconds": 0.4}]}})",
                                 "test");
  ASSERT_TRUE(scene.person);
  EXPECT_EQ(scene.person->scripts.at(0).size(), 7u);
  EXPECT_EQ(scene.person->scripts.at(0)[1].kind, PersonStep::Kind::kGesture);
  EXPECT_EQ(scene.person->seed, 3u);
  const Scene again = parseScene(sceneFileText(scene), "again");
  ASSERT_TRUE(again.person);
  EXPECT_EQ(again.person->scripts.at(0).size(), 7u);
  EXPECT_EQ(again.person->scripts.at(0)[5].box_max, Eigen::Vector3d(0.7, 0.4, 0.3));
}

TEST(PersonScript, RefusesWhatItDoesNotKnowNamingTheField) {
  EXPECT_NE(errorOf(R"({"script": [{"do": "reach", "to": [0.45, 0.35, 0.12]}], "hat": 1})")
                .find("scene 'my.json': person.hat: unknown field"),
            std::string::npos);
  EXPECT_NE(errorOf(R"({"script": [{"do": "dance", "seconds": 1}]})").find("person.script[0].do: unknown step 'dance'"),
            std::string::npos);
  EXPECT_NE(errorOf(R"({"script": [{"do": "reach", "to": [0.45, 0.35, 0.12], "speed": 2.5}]})")
                .find("person.script[0].speed: must be from 0.05 to 1.6 m/s, not 2.5"),
            std::string::npos);
  EXPECT_NE(errorOf(R"({"script": [{"do": "reach", "to": [0.2, -0.4, 0.1]}]})").find("person.script[0].to: lies"),
            std::string::npos);
  EXPECT_NE(errorOf(R"({"script": [{"do": "wait", "seconds": 1, "to": [0, 0, 0]}]})")
                .find("person.script[0].to: unknown field"),
            std::string::npos);
  EXPECT_NE(errorOf(R"({"start": "away", "script": [{"do": "gesture", "seconds": 1}]})")
                .find("person.script[0].do: the person is away"),
            std::string::npos);
  EXPECT_NE(errorOf(R"({"repeat": true, "script": [{"do": "leave"}]})")
                .find("person.script: a repeating script must end at the table"),
            std::string::npos);
  // Beside the table too: its top is an endless plane to the simulator (a hand resting in it
  // was pushed out by the contacts).
  EXPECT_NE(errorOf(R"({"script": [{"do": "reach", "to": [0.5, 0.75, 0.0]}]})")
                .find("person.script[0].to: lies 0 m above the table top's height"),
            std::string::npos);
  PersonSpec low;
  low.shoulder = Eigen::Vector3d(0.5, 0.8, 0.2);
  EXPECT_NEAR(low.restPosition().z(), 0.05, 1e-12);
  EXPECT_NE(errorOf(R"({"script": []})").find("person.script: must be a list of 1 to 1000 steps"), std::string::npos);
  EXPECT_NE(errorOf(R"({"script": [{"do": "wait"}]})").find("person.script[0].seconds: missing"), std::string::npos);
}

TEST(PersonScript, TheSceneFilesWithAPersonLoad) {
  for (const char* name : {"person_away", "person_random"}) {
    const Scene scene = loadScene(dataRoot() / "sim/scenes" / (std::string(name) + ".json"));
    ASSERT_TRUE(scene.person) << name;
    EXPECT_TRUE(scene.person->repeat) << name;
    EXPECT_GT(PersonMotion(*scene.person, 1).duration(), 1.0) << name;
  }
}

TEST(PersonScript, OneOfSeveralScriptsIsDrawnFromTheSeedAndEachIsChecked) {
  const PersonSpec spec = personOf(R"({"scripts": [[{"do": "wait", "seconds": 1}],
      [{"do": "reach", "to": [0.45, 0.35, 0.12]}, {"do": "take", "seconds": 5}],
      [{"do": "leave"}, {"do": "open", "seconds": 0.5}, {"do": "wait", "seconds": 2}]]})");
  ASSERT_EQ(spec.scripts.size(), 3u);
  std::vector<int> drawn(3, 0);
  for (std::uint64_t seed = 1; seed <= 60; ++seed) {
    const PersonMotion motion(spec, seed);
    EXPECT_EQ(PersonMotion(spec, seed).scriptIndex(), motion.scriptIndex());  // the seed decides
    ++drawn.at(motion.scriptIndex());
  }
  for (const int count : drawn) {
    EXPECT_GE(count, 10);  // each about a third of the time
  }
  // The scene file's mix loads, and each of its scripts is drawn.
  const Scene scene = loadScene(dataRoot() / "sim/scenes/collaborative_assembly.json");
  ASSERT_TRUE(scene.person);
  EXPECT_EQ(scene.person->scripts.size(), 5u);
  EXPECT_NE(errorOf(R"({"script": [{"do": "wait", "seconds": 1}], "scripts": [[{"do": "wait", "seconds": 1}]]})")
                .find("person.script: give \"script\" or \"scripts\", not both"),
            std::string::npos);
  EXPECT_NE(errorOf(R"({"scripts": [[{"do": "wait", "seconds": 1}], [{"do": "take"}]]})")
                .find("person.scripts[1][0].seconds: missing"),
            std::string::npos);
  EXPECT_NE(errorOf(R"({"scripts": []})").find("person.scripts: must be a list of 1 to 100 scripts"),
            std::string::npos);
  // Away, the hand may put down what it carried off, but not reach.
  EXPECT_NE(errorOf(R"({"script": [{"do": "leave"}, {"do": "reach", "to": [0.45, 0.35, 0.12]}]})")
                .find("person.script[1].do: the person is away: only \"enter\", \"wait\", \"open\" or \"close\""),
            std::string::npos);
}

TEST(PersonMotion, ATakeOffersTheOpenPalmForItsTimeAtMost) {
  const PersonSpec spec = personOf(R"({"script": [{"do": "reach", "to": [0.45, 0.35, 0.12]},
      {"do": "take", "seconds": 3}, {"do": "close", "seconds": 0.5}]})");
  const PersonMotion motion(spec, 1);
  double offered = 0.0;
  for (double t = 0.0; t < motion.duration(); t += 0.01) {
    const PersonPose pose = motion.at(t);
    offered += pose.offering ? 0.01 : 0.0;
    if (pose.step == "take") {
      EXPECT_EQ(motion.stepAt(t).kind, PersonStep::Kind::kTake);
    }
  }
  EXPECT_NEAR(offered, 3.0, 0.03);  // the palm turned up (0.4 s), then offered for the take's time
}

TEST(PersonMotion, ReachesItsTargetsNoFasterThanAskedAndOffersAfterTheGesture) {
  const PersonSpec spec = personOf(R"({"script": [{"do": "reach", "to": [0.45, 0.35, 0.12], "speed": 1.2},
      {"do": "gesture", "seconds": 1}, {"do": "close", "seconds": 0.5}, {"do": "withdraw", "speed": 0.5}]})");
  const PersonMotion motion(spec, 1);
  double fastest = 0.0;
  bool offered = false;
  double closed = 0.0;
  for (double t = 0.0; t <= motion.duration() + 0.5; t += 0.001) {
    const PersonPose pose = motion.at(t);
    fastest = std::max(fastest, pose.velocity.norm());
    offered = offered || pose.offering;
    closed = std::max(closed, pose.closure);
    EXPECT_NEAR((pose.elbow - spec.shoulder).norm(), kUpperArmLength, 1e-6);
    EXPECT_NEAR((pose.elbow - pose.wrist).norm(), kForearmLength, 1e-6);
  }
  EXPECT_LE(fastest, 1.2 + 1e-6);
  EXPECT_GT(fastest, 1.15);
  EXPECT_TRUE(offered);
  EXPECT_DOUBLE_EQ(closed, 1.0);
  // The reach ends at its target; the withdrawal at rest, palm down.
  double reached = 0.0;
  for (double t = 0.0; t < motion.duration(); t += 0.01) {
    if (motion.at(t).step == "gesture") {
      reached = (motion.at(t).wrist - Eigen::Vector3d(0.45, 0.35, 0.12)).norm();
      break;
    }
  }
  EXPECT_LT(reached, 1e-9);
  const PersonPose end = motion.at(motion.duration() + 1.0);
  EXPECT_LT((end.wrist - spec.restPosition()).norm(), 1e-9);
  EXPECT_TRUE(end.palm_up);  // a closed hand keeps what it holds upright
  EXPECT_FALSE(end.offering);
}

TEST(PersonMotion, RandomReachesAreSeededAndStayWithinTheArmsReach) {
  const PersonSpec spec = personOf(R"({"repeat": true, "rest": [0.5, 0.45, 0.2], "script": [
      {"do": "reach_random", "min": [0.1, -0.3, 0.05], "max": [0.9, 0.5, 0.6], "speed": 1.6},
      {"do": "wait", "seconds": 0.2}]})");
  const PersonMotion a(spec, 11, 60.0);
  const PersonMotion b(spec, 11, 60.0);
  const PersonMotion c(spec, 12, 60.0);
  double differs = 0.0;
  for (double t = 0.0; t < 60.0; t += 0.05) {
    EXPECT_EQ(a.at(t).wrist, b.at(t).wrist);
    differs = std::max(differs, (a.at(t).wrist - c.at(t).wrist).norm());
    EXPECT_LE((a.at(t).wrist - spec.shoulder).norm(), kPersonReach + 1e-9);
    EXPECT_GE(a.at(t).wrist.z(), 0.03 - 1e-9);
  }
  EXPECT_GT(differs, 0.1);
}

TEST(SpeedSeparation, CapsuleDistancesAreTheSurfaces) {
  const Capsule x{{0, 0, 0}, {1, 0, 0}, 0.1};
  EXPECT_NEAR(capsuleDistance(x, {{0.5, 1, 0}, {0.5, 2, 0}, 0.1}), 0.8, 1e-12);       // across, beside
  EXPECT_NEAR(capsuleDistance(x, {{2, 0, 0}, {3, 0, 0}, 0.2}), 0.7, 1e-12);           // end to end
  EXPECT_NEAR(capsuleDistance(x, {{0.5, -1, 0.5}, {0.5, 1, 0.5}, 0.0}), 0.4, 1e-12);  // crossing above
  EXPECT_NEAR(capsuleDistance({{0, 0, 0}, {0, 0, 0}, 0.1}, {{0, 0, 1}, {0, 0, 1}, 0.2}), 0.7, 1e-12);
  EXPECT_LT(capsuleDistance(x, {{0.5, 0.05, 0}, {0.5, 0.05, 0}, 0.1}), 0.0);
}

TEST(SpeedSeparation, TheProtectiveDistanceIsTheStandardsSum) {
  SpeedSeparationParams p;
  const double reaction = p.sensor_period + p.control_period;
  EXPECT_NEAR(protectiveDistance(p, 1.0),
              1.6 * (reaction + p.stopping_time) + 1.0 * reaction + p.stopping_distance_per_speed * 1.0 + p.intrusion +
                  p.sensor_uncertainty + p.robot_uncertainty,
              1e-12);
  EXPECT_GT(protectiveDistance(p, 1.0), protectiveDistance(p, 0.5));
}

TEST(SpeedSeparation, TheMonitorStopsForAPersonAndResumesWhenTheyWithdraw) {
  SpeedSeparationMonitor monitor;
  const SpeedSeparationParams& p = monitor.params();
  const double dt = 0.002;
  for (int i = 0; i < 100; ++i) {
    monitor.update(dt, 2.0, 0.8);
  }
  EXPECT_DOUBLE_EQ(monitor.scale(), 1.0);
  // The person comes within the standing protective distance: the arm brakes to rest within
  // ramp_down and stays there.
  const double close = protectiveDistance(p, 0.0) + p.margin - 0.01;
  int steps = 0;
  while (monitor.scale() > 0.0 && steps < 1000) {
    monitor.update(dt, close, 0.8 * monitor.scale());
    ++steps;
  }
  EXPECT_LE(steps * dt, p.ramp_down + 1e-9);
  EXPECT_EQ(monitor.state(), SpeedSeparationMonitor::State::kStopped);
  EXPECT_EQ(monitor.stops(), 1);
  // Just beyond the stop distance is not enough to resume (hysteresis) ...
  for (int i = 0; i < 100; ++i) {
    monitor.update(dt, close + 0.05, 0.0);
  }
  EXPECT_DOUBLE_EQ(monitor.scale(), 0.0);
  // ... the person withdrawn is: the arm speeds up again.
  for (int i = 0; i < 1000; ++i) {
    monitor.update(dt, 3.0, 0.8 * monitor.scale());
  }
  EXPECT_DOUBLE_EQ(monitor.scale(), 1.0);
  EXPECT_EQ(monitor.state(), SpeedSeparationMonitor::State::kFree);
  EXPECT_EQ(monitor.stops(), 1);
}

TEST(SpeedSeparation, CollaborativeModeCapsTheSpeedAndStopsOnContactOutsideTheHandOrAboveItsLimit) {
  SpeedSeparationMonitor monitor;
  const double dt = 0.002;
  const double near_the_hand = 0.05;  // well within the protective distance
  // Outside collaborative mode the arm stops for the separation.
  for (int i = 0; i < 200; ++i) {
    monitor.update(dt, near_the_hand, 0.5 * monitor.scale());
  }
  EXPECT_EQ(monitor.state(), SpeedSeparationMonitor::State::kStopped);
  EXPECT_EQ(monitor.stopReason(), "separation");
  // Collaborative: the arm moves near the hand, no faster than the cap (0.2 m/s): a motion
  // asked for at 0.5 m/s settles where its speed is at or under the cap.
  monitor.setCollaborative(true);
  double fastest_after_settling = 0.0;
  for (int i = 0; i < 2000; ++i) {
    const double speed = 0.5 * monitor.scale();
    monitor.update(dt, near_the_hand, speed);
    fastest_after_settling = i > 1000 ? std::max(fastest_after_settling, speed) : 0.0;
  }
  EXPECT_GT(monitor.scale(), 0.0);
  EXPECT_LE(fastest_after_settling, monitor.collaborativeParams().max_speed + 0.01);
  EXPECT_GT(fastest_after_settling, 0.8 * monitor.collaborativeParams().max_speed);
  EXPECT_EQ(monitor.stopReason(), "");
  // Touching the hand below its limit (the part's hand-over): on.
  monitor.setContact(50.0, true);
  monitor.update(dt, 0.0, 0.1);
  EXPECT_NE(monitor.state(), SpeedSeparationMonitor::State::kStopped);
  // Above it: a protective stop, held while collaborative.
  monitor.setContact(200.0, true);
  for (int i = 0; i < 200; ++i) {
    monitor.update(dt, 0.0, 0.1 * monitor.scale());
  }
  EXPECT_EQ(monitor.state(), SpeedSeparationMonitor::State::kStopped);
  EXPECT_EQ(monitor.stopReason(), "hand force above 140 N");
  monitor.setContact(0.0, true);
  monitor.update(dt, 0.1, 0.0);
  EXPECT_EQ(monitor.stopReason(), "hand force above 140 N");
  // Leaving collaborative mode: the separation rule again.
  monitor.setCollaborative(false);
  monitor.update(dt, near_the_hand, 0.0);
  EXPECT_EQ(monitor.stopReason(), "separation");
  // Any contact outside the hand stops it, however light.
  monitor.setCollaborative(true);
  monitor.update(dt, near_the_hand, 0.0);
  EXPECT_EQ(monitor.stopReason(), "");
  monitor.setContact(5.0, false);
  monitor.update(dt, near_the_hand, 0.0);
  EXPECT_EQ(monitor.stopReason(), "contact outside the hand");
  // The stop input overrides everything.
  monitor.setCollaborative(true);
  monitor.setStopInput(true);
  monitor.update(dt, near_the_hand, 0.0);
  EXPECT_EQ(monitor.stopReason(), "stop input");
}

TEST(SimPerson, TheHandHoldsAPartByClosingAroundIt) {
  // The hand reaches, turns palm up, a part is put on the palm, the hand closes and withdraws:
  // the part goes with it (fingers' contact and friction only).
  const Scene scene = parseScene(R"({"parts": [{"class": "node", "color": "red", "at": [0.3, -0.3, 0]}],
      "person": {"shoulder": [0.55, 0.8, 0.4], "rest": [0.55, 0.55, 0.25], "script": [
      {"do": "reach", "to": [0.5, 0.35, 0.2], "speed": 0.6}, {"do": "gesture", "seconds": 1.0},
      {"do": "close", "seconds": 0.6}, {"do": "withdraw", "speed": 0.4}, {"do": "wait", "seconds": 1}]}})",
                                 "test");
  const auto sim = Simulation::create(scene);
  const PersonMotion motion(*scene.person, scene.seed);
  double t = 0.0;
  while (motion.at(t).step != "gesture" || !motion.at(t).offering) {
    t += 0.01;
  }
  sim->stepTo(TimePoint(fromSeconds(t + 0.05)));
  const PersonPose pose = *sim->person();
  ASSERT_TRUE(pose.palm_up);
  // Onto the palm: 1.2 cm below the wrist's frame's palm side is its surface; the node's centre
  // 2.5 cm above that, from 1 cm higher.
  const Eigen::Vector3d palm_centre = pose.wrist + pose.hand * Eigen::Vector3d(0.055, 0, -0.012);
  world::Pose on = world::Pose::Identity();
  on.linear() = Eigen::AngleAxisd(std::atan2(pose.hand.toRotationMatrix()(1, 0), pose.hand.toRotationMatrix()(0, 0)),
                                  Eigen::Vector3d::UnitZ())
                    .toRotationMatrix();
  on.translation() = palm_centre + Eigen::Vector3d(0, 0, 0.035);
  sim->movePart("node_0", on);
  sim->stepTo(TimePoint(fromSeconds(motion.duration() + 0.5)));
  const PersonPose end = *sim->person();
  const Eigen::Vector3d part = sim->parts()[0].pose.translation();
  const Eigen::Vector3d hand_now = end.wrist + end.hand * Eigen::Vector3d(0.055, 0, 0);
  EXPECT_GT((end.wrist - pose.wrist).norm(), 0.15);  // the hand moved away ...
  EXPECT_LT((part - hand_now).norm(), 0.06);         // ... holding the part
  EXPECT_GT(part.z(), 0.1);
  bool fingers_touch = false;
  for (const auto& [a, b] : sim->contacts()) {
    fingers_touch = fingers_touch ||
                    ((a == "node_0" && b.rfind("person_", 0) == 0) || (b == "node_0" && a.rfind("person_", 0) == 0));
  }
  EXPECT_TRUE(fingers_touch);
}

TEST(SimPerson, ATakeEndsOnceAPartLiesOnThePalmAndTheHandClosesOnIt) {
  // The hand offers for up to 30 s; a part dropped onto the palm 2 cm from above ends the take at
  // once: the hand closes on it and withdraws with it. Without the part it would still offer.
  const std::string text = R"({"parts": [{"class": "node", "color": "red", "at": [0.3, -0.3, 0]}],
      "person": {"shoulder": [0.55, 0.8, 0.4], "script": [
      {"do": "reach", "to": [0.5, 0.35, 0.2], "speed": 0.6}, {"do": "take", "seconds": 30},
      {"do": "close", "seconds": 0.6}, {"do": "withdraw", "speed": 0.4}, {"do": "wait", "seconds": 60}]}})";
  const Scene scene = parseScene(text, "test");
  const auto sim = Simulation::create(scene);
  const PersonMotion motion(*scene.person, scene.seed);
  double t = 0.0;
  while (!motion.at(t).offering) {
    t += 0.01;
  }
  sim->stepTo(TimePoint(fromSeconds(t + 1.0)));
  const PersonPose pose = *sim->person();
  ASSERT_EQ(pose.step, "take");
  const Eigen::Vector3d palm_centre = pose.wrist + pose.hand * Eigen::Vector3d(0.055, 0, -0.012);
  world::Pose on = world::Pose::Identity();
  on.linear() = Eigen::AngleAxisd(std::atan2(pose.hand.toRotationMatrix()(1, 0), pose.hand.toRotationMatrix()(0, 0)),
                                  Eigen::Vector3d::UnitZ())
                    .toRotationMatrix();
  on.translation() = palm_centre + Eigen::Vector3d(0, 0, 0.025 + 0.02);
  sim->movePart("node_0", on);
  sim->stepTo(TimePoint(fromSeconds(t + 3.0)));
  EXPECT_NE(sim->person()->step, "take");  // 28 s early
  sim->stepTo(TimePoint(fromSeconds(t + 8.0)));
  const PersonPose end = *sim->person();
  EXPECT_EQ(end.step, "wait");
  EXPECT_GT((end.wrist - pose.wrist).norm(), 0.15);  // withdrawn ...
  const Eigen::Vector3d part = sim->parts()[0].pose.translation();
  EXPECT_LT((part - (end.wrist + end.hand * Eigen::Vector3d(0.055, 0, 0))).norm(), 0.06);  // ... holding the part
  EXPECT_GT(part.z(), 0.025 + 0.03);  // off the table (a node resting on it: 0.025)
  // The same script with nothing put on the palm: still offering at that time.
  const auto empty = Simulation::create(parseScene(text, "test"));
  empty->stepTo(TimePoint(fromSeconds(t + 8.0)));
  EXPECT_EQ(empty->person()->step, "take");
  EXPECT_TRUE(empty->person()->offering);
}

TEST(SimPerson, TheRgbdCameraSeesTheHandOverTheTableAndNothingWhenThePersonHasLeft) {
  // The hand held still over an empty part of the table; then the person walks away.
  const Scene scene = parseScene(R"({"parts": [], "person": {"shoulder": [0.55, 0.8, 0.45], "script": [
      {"do": "reach", "to": [0.6, 0.35, 0.2], "speed": 1.0}, {"do": "wait", "seconds": 1},
      {"do": "leave", "speed": 1.6}, {"do": "wait", "seconds": 10}]}})",
                                 "test");
  const auto sim = Simulation::create(scene);
  const auto pointsNearTheHand = [&sim] {
    const camera::RgbdFrame frame = sim->captureRgbd(1, false);
    int near = 0;
    for (const auto& p : frame.points) {
      if (std::isfinite(p.z())) {
        const Eigen::Vector3d world_point = frame.camera_pose * p.cast<double>();
        // Above the table top by more than a part's height, within 12 cm of where the hand
        // reached (over the table: only the person is there).
        near += world_point.z() > 0.08 && (world_point - Eigen::Vector3d(0.6, 0.35, 0.2)).norm() < 0.12 ? 1 : 0;
      }
    }
    return near;
  };
  const PersonMotion motion(*scene.person, scene.seed);
  double t = 0.0;
  while (motion.at(t).step != "wait") {
    t += 0.01;
  }
  sim->stepTo(TimePoint(fromSeconds(t + 0.2)));
  EXPECT_GT(pointsNearTheHand(), 200);
  sim->stepTo(TimePoint(fromSeconds(motion.duration() - 5.0)));
  EXPECT_EQ(pointsNearTheHand(), 0);
}

/// The UR5 sweeps its base joint back and forth across where the person's hand waits; returns
/// the record, and in `finished` whether the arm ended its last sweep where it should.
SeparationRecord sweepPastAPerson(bool monitored, bool* finished) {
  // The person walks up, puts a hand where the gripper passes, withdraws and walks away.
  const Scene scene = parseScene(R"({"parts": [], "person": {"shoulder": [0.2, 0.72, 0.5], "start": "away", "script": [
      {"do": "wait", "seconds": 1}, {"do": "enter", "speed": 1.2}, {"do": "reach", "to": [0.1, 0.2, 0.34], "speed": 1.0},
      {"do": "wait", "seconds": 3}, {"do": "withdraw", "speed": 1.0}, {"do": "leave", "speed": 1.2},
      {"do": "wait", "seconds": 60}]}})",
                                 "test");
  SimulationOptions options;
  options.speed_separation_monitoring = monitored;
  const auto sim = Simulation::create(scene, options);
  const arm::RobotDescription ur5 = arm::loadRobotDescription(arm::robotDescriptionFile("ur5"));
  ArmJoints right = ur5.home;
  ArmJoints left = ur5.home;
  right[0] -= 0.6;
  left[0] += 1.2;
  auto go = std::make_shared<arm::JointTrajectory>(arm::JointTrajectory::pointToPoint(right, left, ur5.limits, 0.8));
  auto back = std::make_shared<arm::JointTrajectory>(arm::JointTrajectory::pointToPoint(left, right, ur5.limits, 0.8));
  // Start on the right, then sweep to the left and back four times.
  sim->setArmSetpointSource([right](TimePoint) {
    return ArmSetpoint{right, ArmJoints::zero(right.size()), ArmJoints::zero(right.size())};
  });
  sim->stepTo(sim->time() + fromSeconds(1.0));
  for (int i = 0; i < 8; ++i) {
    const auto trajectory = i % 2 == 0 ? go : back;
    const TimePoint start = sim->time();
    sim->setArmSetpointSource([trajectory, start](TimePoint t) {
      const arm::TrajectoryPoint point = trajectory->sample(t - start);
      return ArmSetpoint{point.position, point.velocity, point.acceleration};
    });
    // Until the controller has followed it to its end (held back by the override).
    while (sim->time() - start - sim->trajectoryLag() < trajectory->duration() + fromSeconds(0.2) &&
           sim->time() < start + fromSeconds(30.0)) {
      sim->stepTo(sim->time() + fromSeconds(0.01));
    }
  }
  *finished = std::abs(sim->armPositions()[0] - right[0]) < 0.01;
  return *sim->separationRecord();
}

TEST(SimPerson, TheMonitorKeepsTheArmAwayFromThePersonWhichItWouldOtherwiseHit) {
  bool finished = false;
  const SeparationRecord unmonitored = sweepPastAPerson(false, &finished);
  EXPECT_GT(unmonitored.contact_steps, 0u);  // the sweep goes through where the hand waits
  EXPECT_GT(unmonitored.violation_steps, 0u);
  const SeparationRecord monitored = sweepPastAPerson(true, &finished);
  EXPECT_TRUE(finished);  // stopped while the person was there, resumed once they had left
  EXPECT_EQ(monitored.contact_steps, 0u);
  EXPECT_EQ(monitored.violation_steps, 0u);
  EXPECT_GT(monitored.min_separation, 0.0);
  EXPECT_GE(monitored.stops, 1);
  EXPECT_GT(monitored.fast_seconds, 0.5);  // the arm did move fast while the person was away
}

TEST(SimPerson, InCollaborativeModeTheArmMovesSlowlyNearThePersonAndStopsWhenItTouchesThem) {
  // The person walks up and holds a hand where the UR5's base sweep passes; the arm sweeps in
  // collaborative mode: no protective stop for the separation, at most the cap's speed once
  // braked, and touching the person stops it with the reason.
  const Scene scene = parseScene(R"({"parts": [], "person": {"shoulder": [0.2, 0.72, 0.5], "script": [
      {"do": "reach", "to": [0.1, 0.2, 0.34], "speed": 1.0}, {"do": "wait", "seconds": 60}]}})",
                                 "test");
  const auto sim = Simulation::create(scene);
  const arm::RobotDescription ur5 = arm::loadRobotDescription(arm::robotDescriptionFile("ur5"));
  ArmJoints right = ur5.home;
  ArmJoints left = ur5.home;
  right[0] -= 0.6;
  left[0] += 1.2;
  sim->setArmSetpointSource([right](TimePoint) {
    return ArmSetpoint{right, ArmJoints::zero(right.size()), ArmJoints::zero(right.size())};
  });
  sim->stepTo(sim->time() + fromSeconds(2.0));
  EXPECT_EQ(sim->separation()->state, "stopped");  // the hand is within the protective distance
  EXPECT_EQ(sim->separation()->stop_reason, "separation");
  sim->setCollaborative(true);
  auto go = std::make_shared<arm::JointTrajectory>(arm::JointTrajectory::pointToPoint(right, left, ur5.limits, 0.8));
  const TimePoint start = sim->time();
  sim->setArmSetpointSource([go, start](TimePoint t) {
    const arm::TrajectoryPoint point = go->sample(t - start);
    return ArmSetpoint{point.position, point.velocity, point.acceleration};
  });
  double fastest_once_braked = 0.0;
  std::string reason;
  while (sim->time() < start + fromSeconds(20.0) && reason.empty()) {
    sim->stepTo(sim->time() + fromSeconds(0.01));
    const SeparationStatus status = *sim->separation();
    EXPECT_TRUE(status.collaborative);
    if (sim->time() > start + fromSeconds(0.5) && status.state != "stopped") {
      fastest_once_braked = std::max(fastest_once_braked, status.arm_speed);
    }
    reason = status.stop_reason;
  }
  EXPECT_TRUE(reason == "hand force above 140 N" || reason == "contact outside the hand") << reason;
  EXPECT_LE(fastest_once_braked, 0.21);
  EXPECT_GT(fastest_once_braked, 0.1);
  // Held after the contact while collaborative, however long.
  sim->stepTo(sim->time() + fromSeconds(1.0));
  EXPECT_EQ(sim->separation()->state, "stopped");
  EXPECT_EQ(sim->separation()->stop_reason, reason);
  const SeparationRecord record = *sim->separationRecord();
  EXPECT_GT(record.collaborative_seconds, 1.0);
}

}  // namespace
}  // namespace costar::sim
