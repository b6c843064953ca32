#include "arm/free_drive.h"

#include "arm/ur5_kinematics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include <Eigen/Geometry>

#include "arm/test/published_arms.h"

namespace costar::arm {
namespace {

TEST(FreeDrive, GuidingModesParseAndBadOnesAreRefusedNamingTheField) {
  EXPECT_EQ(GuidingMode::parse("free", "", "world").str(), "free");
  EXPECT_EQ(GuidingMode::parse("translation", "", "world").str(), "translation");
  EXPECT_EQ(GuidingMode::parse("rotation", "", "tool").str(), "rotation");
  EXPECT_EQ(GuidingMode::parse("free", "z, rx", "tool").str(), "locked z, rx (tool)");
  try {
    GuidingMode::parse("sideways", "", "world");
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "mode: 'sideways' is not a guiding mode (free, translation, rotation)");
  }
  EXPECT_THROW(GuidingMode::parse("free", "z,w", "world"), std::invalid_argument);
  EXPECT_THROW(GuidingMode::parse("free", "", "base"), std::invalid_argument);
  EXPECT_THROW(GuidingMode::parse("translation", "x,y,z", "world"), std::invalid_argument);
}

TEST(FreeDrive, ThePayloadsWeightIsTakenOutAsTheToolTurns) {
  Payload payload{1.2, Eigen::Vector3d(0.0, 0.01, 0.08)};
  const Eigen::Matrix3d start = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()).toRotationMatrix();
  const Eigen::Matrix3d turned = Eigen::AngleAxisd(0.7, Eigen::Vector3d(0.3, 1.0, 0.2).normalized()) * start;
  // What the flange pushes the payload with to hold it, at either orientation, plus a bias.
  const auto reading = [&](const Eigen::Matrix3d& sensor, const Eigen::Vector3d& hand_world) {
    Wrench w;
    w.force = sensor.transpose() * Eigen::Vector3d(0, 0, payload.mass * 9.81) + Eigen::Vector3d(1.0, -2.0, 0.5);
    w.torque = payload.center_of_mass.cross(w.force - Eigen::Vector3d(1.0, -2.0, 0.5)) + Eigen::Vector3d(0.1, 0, 0);
    // The hand pushes at the sensor's origin.
    w.force -= sensor.transpose() * hand_world;
    return w;
  };
  const Wrench at_start = reading(start, Eigen::Vector3d::Zero());
  const Wrench still =
      handWrench(reading(turned, Eigen::Vector3d::Zero()), at_start, turned, start, Eigen::Vector3d::Zero(), payload);
  EXPECT_LT(still.force.norm(), 1e-9);
  EXPECT_LT(still.torque.norm(), 1e-9);
  const Eigen::Vector3d push(5.0, -3.0, 10.0);
  const Wrench pushed =
      handWrench(reading(turned, push), at_start, turned, start, Eigen::Vector3d(0, 0, 0.15), payload);
  EXPECT_LT((pushed.force - push).norm(), 1e-9);
  // A push at the sensor's origin turns the tool about its centre point, 0.15 m beyond it.
  const Eigen::Vector3d lever = turned * Eigen::Vector3d(0, 0, -0.15);
  EXPECT_LT((pushed.torque - lever.cross(push)).norm(), 1e-9);
  // Without the payload's weight taken out, the turn alone would read as a push.
  const Wrench naive =
      handWrench(reading(turned, Eigen::Vector3d::Zero()), at_start, turned, start, Eigen::Vector3d::Zero(), {});
  EXPECT_GT(naive.force.norm(), 3.0);
}

TEST(FreeDrive, TheAdmittanceAnswersBeyondItsDeadBandWithinItsSpeedAndMasksLockedAxes) {
  AdmittanceGains gains;
  gains.acceleration = 1e6;  // no ramp here
  const Eigen::Matrix3d tool = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  Wrench hand;
  hand.force = Eigen::Vector3d(2.0, 0, 0);
  EXPECT_EQ(admittance(hand, {}, 0.01, GuidingMode::parse("free", "", "world"), tool, gains).velocity.norm(), 0.0);
  hand.force = Eigen::Vector3d(13.0, 0, 0);
  EXPECT_NEAR(admittance(hand, {}, 0.01, GuidingMode::parse("free", "", "world"), tool, gains).velocity.x(), 0.1,
              1e-12);
  hand.force = Eigen::Vector3d(0, 0, -500.0);
  EXPECT_NEAR(admittance(hand, {}, 0.01, GuidingMode::parse("free", "", "world"), tool, gains).velocity.norm(),
              gains.max_speed, 1e-12);
  hand.force = Eigen::Vector3d(20.0, 20.0, 20.0);
  hand.torque = Eigen::Vector3d(1.0, 1.0, 1.0);
  const Twist rotation = admittance(hand, {}, 0.01, GuidingMode::parse("rotation", "", "world"), tool, gains);
  EXPECT_EQ(rotation.velocity.norm(), 0.0);
  EXPECT_GT(rotation.angular_velocity.norm(), 0.1);
  const Twist translation = admittance(hand, {}, 0.01, GuidingMode::parse("translation", "", "world"), tool, gains);
  EXPECT_EQ(translation.angular_velocity.norm(), 0.0);
  // The tool's x is the world's y here: locking it in tool axes stops the world's y.
  const Twist locked = admittance(hand, {}, 0.01, GuidingMode::parse("translation", "x", "tool"), tool, gains);
  EXPECT_NEAR(locked.velocity.y(), 0.0, 1e-12);
  EXPECT_GT(locked.velocity.x(), 0.05);
  // The ramp: from rest, at most the acceleration's worth in one step.
  gains.acceleration = 1.5;
  EXPECT_NEAR(admittance(hand, {}, 0.01, GuidingMode::parse("translation", "", "world"), tool, gains).velocity.norm(),
              0.015, 1e-12);
}

TEST(FreeDrive, TheProtectiveStopTripsOnSpeedHeldPastItsWindowOrOnTrackingNamingTheLimitAndTheValue) {
  // A hard push the compliant arm yields to: the wrist reads little, the tool runs fast and away
  // from its reference (the 150 N stop never fired: 200 N moved the UR5's tool 0.8 m at 3.9 m/s).
  ProtectiveStop stop;
  const double dt = 0.01;
  // A transient above the speed shorter than the window is let be, and the window starts over.
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(stop.check(0.30, 0.010, 0.0, dt), "") << i;
  }
  EXPECT_EQ(stop.check(0.20, 0.010, 0.0, dt), "");
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(stop.check(0.40, 0.010, 0.0, dt), "") << i;
  }
  EXPECT_EQ(stop.check(0.31, 0.010, 0.0, dt),
            "the tool moved faster than 0.25 m/s for 50 ms (0.40 m/s at most), the teaching speed limit");
  // The tool held away from its reference trips at once, speed or not.
  ProtectiveStop tracking;
  EXPECT_EQ(tracking.check(0.0, 0.024, 0.0, dt), "");
  EXPECT_EQ(tracking.check(0.0, 0.0312, 0.0, dt),
            "the tool was 31.2 mm from where free-drive held it (at most 25 mm: a push harder than a hand's, or a "
            "collision)");
  EXPECT_EQ(tracking.check(0.0, 0.0, 0.2, dt),
            "the tool was turned 11.5 deg from where free-drive held it (at most 8.6 deg: a twist harder than a "
            "hand's, or a collision)");
}

/// A one-joint-per-axis "arm" (its joints are the tool's x, y, z) above a wall at z = 0.1 that
/// the sweep refuses with `why`.
StepChecks axesArmAboveAWall(const std::string& why_blocked) {
  StepChecks check;
  check.reach = [](const world::Pose& pose, const JointVector&, std::string&) -> std::optional<JointVector> {
    JointVector q = JointVector::zero(3);
    for (int i = 0; i < 3; ++i) {
      q[i] = pose.translation()[i];
    }
    return q;
  };
  check.sweep = [why_blocked](const JointVector& from, const JointVector& to, std::string& why) {
    if (std::min(from[2], to[2]) < 0.1) {
      why = why_blocked;
      return false;
    }
    return true;
  };
  check.displacement = [](const JointVector& from, const JointVector& to) {
    return (to.eigen() - from.eigen()).norm();
  };
  return check;
}

TEST(FreeDrive, AStepTowardAWallStopsTheLookAheadShortOfItAndAnAslantPushSlidesAlongIt) {
  AdmittanceGains gains;
  gains.max_point_speed = 1.0;  // the wall, not the speed, is what this checks
  StepChecks check = axesArmAboveAWall("tool would touch table");
  // The wall is the gripper's (a part under it): the arm's other links are clear of it.
  check.sweep_arm = [](const JointVector&, const JointVector&, std::string&) { return true; };
  world::Pose reference = world::Pose::Identity();
  reference.translation() = Eigen::Vector3d(0, 0, 0.2);
  JointVector joints = JointVector::zero(3);
  joints[2] = 0.2;
  const JointVector max_step = JointVector(3, 1.0);
  Twist down;
  down.velocity = Eigen::Vector3d(0.05, 0.0, -0.2);
  const Eigen::Vector3d push(8.0, 0.0, -32.0);  // the hand pushes along the motion
  double lowest = 1.0;
  std::string blocked;
  for (int i = 0; i < 200; ++i) {
    const FreeDriveStep step = stepReference(reference, joints, down, 0.01, max_step, gains, check, push);
    reference = step.reference;
    joints = step.joints;
    lowest = std::min(lowest, reference.translation().z());
    if (!step.blocked.empty()) {
      blocked = step.blocked;
    }
  }
  // It stops the gripper's look-ahead short of the wall (and a step), never at it: the distance to
  // stop from 0.21 m/s (14 mm) and the clearance (2 mm) along the motion, and the push's give (8 mm
  // down): 23.7 mm above the wall, not the 4 cm the arm's other links keep.
  const double ahead = -gripperLookAhead(down.velocity, push, gains).z();
  EXPECT_NEAR(ahead, 0.0237, 0.0005);
  EXPECT_GE(lowest, 0.1 + ahead);
  EXPECT_LE(lowest, 0.1 + ahead + 0.003);
  EXPECT_EQ(blocked, "tool would touch table");
  // Pushed down and sideways, it slides along the wall at the sideways speed: 2 s at 0.05 m/s.
  EXPECT_NEAR(reference.translation().x(), 0.1, 1e-9);
}

TEST(FreeDrive, TheGrippersLookAheadIsTheDistanceToStopAndThePushsGiveNotAFixedFourCentimetres) {
  // A fixed 4 cm kept a gripper guided down onto a part 3.2 cm above where it would grasp it.
  const AdmittanceGains gains;
  const Eigen::Vector3d none = Eigen::Vector3d::Zero();
  EXPECT_EQ(gripperLookAhead(none, none, gains), none);
  const Eigen::Vector3d down(0.0, 0.0, -0.15);
  EXPECT_NEAR(gripperLookAhead(down, none, gains).z(), -(0.0075 + gains.clearance), 1e-12);  // 0.15^2 / (2 x 1.5)
  // The push's give, wherever it pushes: 40 N down while the tool slides along x.
  const Eigen::Vector3d slide =
      gripperLookAhead(Eigen::Vector3d(0.05, 0.0, 0.0), Eigen::Vector3d(10.0, 0.0, -40.0), gains);
  EXPECT_NEAR(slide.z(), -0.01, 1e-12);
  EXPECT_NEAR(slide.x(), 0.0025 + 0.05 * 0.05 / 3.0 + gains.clearance, 1e-12);
  EXPECT_NEAR(gripperLookAhead(Eigen::Vector3d(0.5, 0.0, 0.0), Eigen::Vector3d(150.0, 0.0, 0.0), gains).norm(),
              gains.look_ahead, 1e-12);  // at most look_ahead
}

TEST(FreeDrive, AHandPushingIntoAWallAlmostSquarelyDoesNotCreepAlongIt) {
  // The tool held back by a wall at z = 0.1 (the look-ahead above it), the hand pushing into it 1 degree aslant: the
  // push along the wall (0.7 N) is within the dead band, so the reference holds; 10 degrees
  // aslant (6.9 N) it slides.
  AdmittanceGains gains;
  const StepChecks check = axesArmAboveAWall("fingers would touch part:node_1");
  const auto slid = [&](double degrees) {
    const double aslant = degrees * M_PI / 180.0;
    const Eigen::Vector3d push = 40.0 * Eigen::Vector3d(std::sin(aslant), 0.0, -std::cos(aslant));
    world::Pose reference = world::Pose::Identity();
    reference.translation() = Eigen::Vector3d(0.0, 0.0, 0.1 + 40.0 / gains.stiffness + 0.001);
    JointVector joints = JointVector::zero(3);
    joints[2] = reference.translation().z();
    Twist twist;
    for (int i = 0; i < 100; ++i) {
      twist = admittance({push, Eigen::Vector3d::Zero()}, twist, 0.01, GuidingMode::parse("translation", "", "world"),
                         reference.linear(), gains);
      const FreeDriveStep step = stepReference(reference, joints, twist, 0.01, JointVector(3, 1.0), gains, check, push);
      reference = step.reference;
      joints = step.joints;
      twist = step.twist;
    }
    return reference.translation().x();
  };
  EXPECT_EQ(slid(1.0), 0.0);
  EXPECT_GT(slid(10.0), 0.01);  // 0.026 m/s at most
}

TEST(FreeDrive, FastJointsNearASingularitySlowTheStep) {
  AdmittanceGains gains;
  StepChecks check;
  check.reach = [](const world::Pose& pose, const JointVector&, std::string&) -> std::optional<JointVector> {
    JointVector q = JointVector::zero(1);
    q[0] = 10.0 * pose.translation().x();  // the joint turns 10 rad per metre
    return q;
  };
  check.sweep = [](const JointVector&, const JointVector&, std::string&) { return true; };
  check.displacement = [](const JointVector& from, const JointVector& to) { return 0.1 * std::abs(to[0] - from[0]); };
  Twist twist;
  twist.velocity = Eigen::Vector3d(0.2, 0, 0);
  const FreeDriveStep step = stepReference(world::Pose::Identity(), JointVector::zero(1), twist, 0.01,
                                           JointVector(1, 0.01), gains, check, Eigen::Vector3d::Zero());
  EXPECT_LE(std::abs(step.joints[0]), 0.01);
  EXPECT_GT(step.twist.velocity.x(), 0.0);
  EXPECT_LT(step.twist.velocity.x(), 0.1);
  EXPECT_EQ(step.blocked, "a joint would turn too fast (near a singularity)");
}

TEST(FreeDrive, ALinkSwingingFasterThanTheToolSlowsTheStepToTheLinksSpeedLimit) {
  // A one-joint "arm" whose elbow moves five times as far as its tool.
  AdmittanceGains gains;
  StepChecks check;
  check.reach = [](const world::Pose& pose, const JointVector&, std::string&) -> std::optional<JointVector> {
    JointVector q = JointVector::zero(1);
    q[0] = pose.translation().x();
    return q;
  };
  check.sweep = [](const JointVector&, const JointVector&, std::string&) { return true; };
  check.displacement = [](const JointVector& from, const JointVector& to) { return 5.0 * std::abs(to[0] - from[0]); };
  Twist twist;
  twist.velocity = Eigen::Vector3d(0.15, 0, 0);
  const FreeDriveStep step = stepReference(world::Pose::Identity(), JointVector::zero(1), twist, 0.01,
                                           JointVector(1, 1.0), gains, check, Eigen::Vector3d::Zero());
  EXPECT_GT(step.twist.velocity.x(), 0.0);
  EXPECT_LE(5.0 * step.twist.velocity.x(), gains.max_point_speed + 1e-12);
  EXPECT_EQ(step.blocked, "a link would move faster than 0.20 m/s");
}

TEST(FreeDrive, ALinkWhoseMotionAheadReachesAWallStopsTheStepThoughTheToolsLookAheadIsClear) {
  // Two joints: the tool moves with the first; a link with the second, which turns one way as
  // the tool sets off and back by the tool's look-ahead (q2 = 0.02 + 3 x - 75 x^2): where the
  // tool will be 4 cm on is clear, but the link carried on as it moves now reaches a wall at
  // q2 = 0.05.
  AdmittanceGains gains;
  StepChecks check;
  check.reach = [](const world::Pose& pose, const JointVector&, std::string&) -> std::optional<JointVector> {
    const double x = pose.translation().x();
    JointVector q = JointVector::zero(2);
    q[0] = x;
    q[1] = 0.02 + 3.0 * x - 75.0 * x * x;
    return q;
  };
  check.sweep = [](const JointVector& from, const JointVector& to, std::string& why) {
    if (std::max(from[1], to[1]) > 0.05) {
      why = "forearm_link would touch table";
      return false;
    }
    return true;
  };
  check.displacement = [](const JointVector& from, const JointVector& to) {
    return (to.eigen() - from.eigen()).cwiseAbs().maxCoeff();
  };
  JointVector joints = JointVector::zero(2);
  joints[1] = 0.02;
  Twist twist;
  twist.velocity = Eigen::Vector3d(0.05, 0, 0);
  const FreeDriveStep step = stepReference(world::Pose::Identity(), joints, twist, 0.01, JointVector(2, 1.0), gains,
                                           check, Eigen::Vector3d(20.0, 0.0, 0.0));
  EXPECT_EQ(step.twist.velocity.norm(), 0.0);
  EXPECT_EQ(step.blocked, "forearm_link would touch table");
}

/// The UR5's own kinematics with a tool 15 cm beyond the flange, free of obstacles: what a step
/// is checked against near its singularities.
struct Ur5Steps {
  Ur5Kinematics ur5{published::ur5Dh(), published::ur5Limits()};
  world::Pose tcp = world::Pose(Eigen::Translation3d(0.0, 0.0, 0.15));
  world::Pose tool(const JointVector& q) const { return ur5.forward(q) * tcp; }
  StepChecks checks(bool guard) const {
    StepChecks check;
    check.reach = [this](const world::Pose& pose, const JointVector& seed, std::string& why) {
      std::optional<JointVector> q = ur5.inverseNearest(pose * tcp.inverse(), seed);
      if (!q) {
        why = "out of the arm's reach";
      }
      return q;
    };
    check.sweep = [](const JointVector&, const JointVector&, std::string&) { return true; };
    check.displacement = [this](const JointVector& from, const JointVector& to) {
      return (tool(to).translation() - tool(from).translation()).norm();
    };
    if (guard) {
      check.dexterity = [this](const JointVector& q) {
        return dexterity([this](const JointVector& at) { return tool(at); }, q);
      };
    }
    return check;
  }
};

TEST(FreeDrive, TheDexterityFallsToZeroAtTheUr5sWristSingularityNamingTheWristJoints) {
  const Ur5Steps arm;
  const auto tool = [&arm](const JointVector& q) { return arm.tool(q); };
  JointVector q{0.3, -1.3, 1.5, -1.8, 1.2, 0.4};
  const Dexterity away = dexterity(tool, q);
  EXPECT_GT(away.value, AdmittanceGains{}.singular_slow);
  double before = away.value;
  for (double q5 : {0.6, 0.3, 0.1, 0.01}) {
    q[4] = q5;
    const Dexterity d = dexterity(tool, q);
    EXPECT_LT(d.value, before) << "q5 " << q5;
    EXPECT_EQ(d.joints, (std::vector<int>{4, 6})) << "q5 " << q5;
    before = d.value;
  }
  q[4] = 0.0;
  EXPECT_LT(dexterity(tool, q).value, 1e-6);
}

/// The checked joints as the hand pulls the UR5's tool, 3 s at 100 Hz, from the wrist at q5 =
/// 0.35 rad toward the pose it has at q5 = -0.35 (the other side of its wrist singularity).
struct WristPull {
  double least_q5 = 1e9;
  double least_dexterity = 1e9;
  double fastest = 0.0;  // m/s of the reference
  std::set<std::string> blocked;
  JointVector end;
};
WristPull pullThroughTheWrist(bool guard) {
  const Ur5Steps arm;
  const StepChecks check = arm.checks(guard);
  const AdmittanceGains gains;
  JointVector joints{0.3, -1.3, 1.5, -1.8, 0.35, 0.4};
  JointVector other = joints;
  other[4] = -0.35;
  const world::Pose goal = arm.tool(other);
  world::Pose reference = arm.tool(joints);
  const JointVector max_step(6, 0.5 * 3.15 * 0.01);  // half the UR5's top speed, one tick
  WristPull pull;
  for (int tick = 0; tick < 300; ++tick) {
    Twist twist;
    const Eigen::Vector3d error = goal.translation() - reference.translation();
    twist.velocity = error.norm() > 1e-6 ? Eigen::Vector3d(error.normalized() * std::min(0.1, error.norm() / 0.01))
                                         : Eigen::Vector3d::Zero();
    const Eigen::AngleAxisd turn(goal.linear() * reference.linear().transpose());
    twist.angular_velocity = turn.axis() * std::min(0.4, turn.angle() / 0.01);
    const FreeDriveStep step =
        stepReference(reference, joints, twist, 0.01, max_step, gains, check, Eigen::Vector3d::Zero());
    pull.fastest = std::max(pull.fastest, (step.reference.translation() - reference.translation()).norm() / 0.01);
    reference = step.reference;
    joints = step.joints;
    pull.least_q5 = std::min(pull.least_q5, joints[4]);
    pull.least_dexterity =
        std::min(pull.least_dexterity, dexterity([&arm](const JointVector& q) { return arm.tool(q); }, joints).value);
    if (!step.blocked.empty()) {
      pull.blocked.insert(step.blocked);
    }
  }
  pull.end = joints;
  return pull;
}

TEST(FreeDrive, PulledThroughTheUr5sWristSingularityTheStepSlowsAndStopsShortOfIt) {
  // Without the guard the checked wrist goes to within 0.03 rad of its singularity, where joints
  // 4 and 6 turn fast for little of the tool's motion (the UR5's 0.553 m/s on the random drag's
  // seed 1: the checked wrist crossed it, joints 4 and 6 chattered).
  const AdmittanceGains gains;
  const WristPull unguarded = pullThroughTheWrist(false);
  EXPECT_LT(unguarded.least_q5, 0.03);
  EXPECT_LT(unguarded.least_dexterity, 0.25 * gains.singular_floor);

  const WristPull guarded = pullThroughTheWrist(true);
  EXPECT_GE(guarded.least_dexterity, gains.singular_floor);
  EXPECT_GT(guarded.least_q5, 0.1);
  EXPECT_LE(guarded.fastest, gains.max_speed + 1e-9);
  EXPECT_TRUE(guarded.blocked.contains("slowed near a singularity (joints 4, 6)"));
  EXPECT_TRUE(guarded.blocked.contains("at a singularity (joints 4, 6): guide the tool another way"));
}

TEST(FreeDrive, AStepAwayFromASingularityIsNotSlowed) {
  // The UR5's wrist at q5 = 0.1 rad, within the guard's floor: pulled back to q5 = 0.6 at full speed.
  const Ur5Steps arm;
  const StepChecks check = arm.checks(true);
  const AdmittanceGains gains;
  const JointVector joints{0.3, -1.3, 1.5, -1.8, 0.1, 0.4};
  ASSERT_LT(check.dexterity(joints).value, gains.singular_floor);
  JointVector away = joints;
  away[4] = 0.11;
  const world::Pose from = arm.tool(joints);
  const world::Pose to = arm.tool(away);
  Twist twist;
  twist.velocity = (to.translation() - from.translation()).normalized() * 0.02;
  const Eigen::AngleAxisd turn(to.linear() * from.linear().transpose());
  twist.angular_velocity = turn.axis() * 0.02 * turn.angle() / (to.translation() - from.translation()).norm();
  const FreeDriveStep step =
      stepReference(from, joints, twist, 0.01, JointVector(6, 0.0157), gains, check, Eigen::Vector3d::Zero());
  EXPECT_EQ(step.blocked, "");
  EXPECT_GT(step.joints[4], joints[4]);
}

}  // namespace
}  // namespace costar::arm
