#include <gtest/gtest.h>

#include <thread>

#include <random>

#include "core/paths.h"
#include "planning/collision_world.h"
#include "planning/planner.h"
#include "planning/robot_model.h"

namespace costar::planning {
namespace {

RobotModel ur5() {
  return RobotModel::fromUrdf(COSTAR_UR5_URDF, std::filesystem::path(COSTAR_GRIPPER_MODEL_DIR) / "parallel-2f.urdf",
                              "tool0", "base_link", "tcp");
}

/// Independent standard-DH model of the UR5 with the 0.14 m tool centre point.
world::Pose dhForward(const Eigen::VectorXd& q) {
  const double d[6] = {0.089159, 0, 0, 0.10915, 0.09465, 0.0823};
  const double a[6] = {0, -0.425, -0.39225, 0, 0, 0};
  const double alpha[6] = {M_PI / 2, 0, 0, M_PI / 2, -M_PI / 2, 0};
  world::Pose pose = world::Pose::Identity();
  for (int i = 0; i < 6; ++i) {
    pose = pose * Eigen::AngleAxisd(q[i], Eigen::Vector3d::UnitZ()) * Eigen::Translation3d(a[i], 0, d[i]) *
           Eigen::AngleAxisd(alpha[i], Eigen::Vector3d::UnitX());
  }
  return pose * Eigen::Translation3d(0, 0, 0.14);
}

Eigen::VectorXd joints(std::initializer_list<double> values) {
  Eigen::VectorXd q(static_cast<Eigen::Index>(values.size()));
  std::copy(values.begin(), values.end(), q.data());
  return q;
}

const Eigen::VectorXd kHome = joints({0.0, -2.3, 1.9, -M_PI / 2 + 0.4, -M_PI / 2, 0.0});
// The robot's base is turned 180 degrees about z in the workcell.
const world::Pose kBaseInWorld(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitZ()));

TEST(RobotModel, TheUrdfChainMatchesTheDhModel) {
  const RobotModel robot = ur5();
  ASSERT_EQ(robot.dof(), 6u);
  EXPECT_EQ(robot.jointNames().front(), "shoulder_pan_joint");
  EXPECT_NEAR(robot.upperLimits()[0], 2 * M_PI, 1e-6);
  EXPECT_NEAR(robot.velocityLimits()[5], M_PI, 1e-6);
  std::mt19937 random(3);
  std::uniform_real_distribution<double> angle(-M_PI, M_PI);
  for (int trial = 0; trial < 1000; ++trial) {
    Eigen::VectorXd q(6);
    for (int j = 0; j < 6; ++j) {
      q[j] = angle(random);
    }
    const world::Pose expected = dhForward(q);
    const world::Pose actual = robot.forward(q);
    EXPECT_LT((actual.translation() - expected.translation()).norm(), 1e-9);
    EXPECT_LT(world::rotationAngle(actual, expected), 1e-9);
  }
  EXPECT_EQ(robot.links().size(), 9u);  // base, shoulder, upper arm, forearm, 3 wrists, tool, fingers
}

TEST(RobotModel, NumericInverseKinematicsReachesReachablePoses) {
  const RobotModel robot = ur5();
  std::mt19937 random(5);
  std::uniform_real_distribution<double> angle(-M_PI, M_PI);
  int solved = 0;
  for (int trial = 0; trial < 50; ++trial) {
    Eigen::VectorXd q(6);
    for (int j = 0; j < 6; ++j) {
      q[j] = angle(random);
    }
    const world::Pose target = robot.forward(q);
    if (const auto solution = robot.inverse(target, Eigen::VectorXd::Zero(6), 10, trial)) {
      ++solved;
      EXPECT_LT((robot.forward(*solution).translation() - target.translation()).norm(), 1e-5);
    }
  }
  EXPECT_GE(solved, 48);
}

TEST(RobotModel, ForwardKinematicsOnSeveralThreadsAtOnceMatchesTheDhModel) {
  // KDL's joints cache their last pose: on a shared chain, one thread could take another's.
  // Two threads alternate between the same two configurations, out of phase.
  const RobotModel robot = ur5();
  const Eigen::VectorXd configurations[2] = {kHome, joints({1.0, -1.2, 1.5, -0.3, 0.8, 2.0})};
  const auto work = [&](int phase, int& wrong) {
    std::vector<world::Pose> poses;
    for (int trial = 0; trial < 30000; ++trial) {
      const Eigen::VectorXd& q = configurations[(trial + phase) % 2];
      robot.linkPoses(q, poses);
      const world::Pose expected = dhForward(q);
      const world::Pose actual = robot.forward(q);
      if ((actual.translation() - expected.translation()).norm() > 1e-9 ||
          world::rotationAngle(actual, expected) > 1e-9) {
        ++wrong;
      }
    }
  };
  int wrong_here = 0;
  int wrong_there = 0;
  std::thread other(work, 1, std::ref(wrong_there));
  work(0, wrong_here);
  other.join();
  EXPECT_EQ(wrong_here, 0);
  EXPECT_EQ(wrong_there, 0);
}

class Collisions : public ::testing::Test {
 protected:
  /// Two 26 x 8 x 40 mm finger pads whose inner faces are `opening` apart, 14 cm along the tool.
  static std::vector<CollisionShape> pads(double opening) {
    std::vector<CollisionShape> shapes(2);
    for (int side = 0; side < 2; ++side) {
      shapes[side].size = {0.026, 0.008, 0.04};
      shapes[side].origin = world::Pose(Eigen::Translation3d(0, (side == 0 ? 1 : -1) * (opening / 2 + 0.004), 0.14));
    }
    return shapes;
  }

  Collisions() : robot(ur5()), world(robot, kBaseInWorld, {}, {kHome}) {
    // The table: top at z = 0.
    world.setBox("table", world::Pose(Eigen::Translation3d(0.4, 0, -0.02)), {1.4, 1.2, 0.04});
    world.allow("base_link", "table");  // the robot stands on it
  }
  RobotModel robot;
  CollisionWorld world;
};

TEST_F(Collisions, HomeIsFreeAndTheTableIsHitBelowIt) {
  EXPECT_FALSE(world.check(kHome).has_value());
  // Shoulder lowered until the tool reaches into the table.
  Eigen::VectorXd down = kHome;
  down[1] = -1.2;
  const auto contact = world.check(down);
  ASSERT_TRUE(contact.has_value());
  EXPECT_EQ(contact->other, "table");
  EXPECT_NE(contact->str().find("would touch table"), std::string::npos);
}

TEST_F(Collisions, SelfCollisionsAreFound) {
  // Elbow folded in: the tool comes down onto the shoulder.
  Eigen::VectorXd folded = kHome;
  folded[2] = 2.4;
  const auto contact = world.check(folded);
  ASSERT_TRUE(contact.has_value());
  EXPECT_EQ(contact->str(), "shoulder_link would touch fingers");
}

TEST_F(Collisions, AllowedContactsAreIgnoredAndObstaclesCanBeRemoved) {
  const world::Pose tcp = kBaseInWorld * robot.forward(kHome);
  world.setBox("part_1", tcp, {0.05, 0.05, 0.05});
  ASSERT_TRUE(world.check(kHome).has_value());
  EXPECT_EQ(world.check(kHome)->other, "part_1");
  world.allow("tool0", "part_1");
  world.allow("fingers", "part_1");
  EXPECT_FALSE(world.check(kHome).has_value());
  world.disallowAll();
  world.allow("base_link", "table");
  world.removeAll("part_");
  EXPECT_FALSE(world.check(kHome).has_value());
}

TEST_F(Collisions, ContactsAllowedForOneQueryAreNotLeftInTheWorld) {
  const world::Pose tcp = kBaseInWorld * robot.forward(kHome);
  world.setBox("part_1", tcp, {0.05, 0.05, 0.05});
  const AllowedContacts grasping = AllowedContacts::between({"tool0", "fingers"}, {"part_1"});
  EXPECT_FALSE(world.check(kHome, grasping).has_value());
  EXPECT_FALSE(world.checkSegment(kHome, kHome, grasping).has_value());
  // The next query, without them, sees the part again.
  ASSERT_TRUE(world.check(kHome).has_value());
  EXPECT_EQ(world.check(kHome)->other, "part_1");
  // Allowing another part lets nothing touch this one.
  EXPECT_EQ(world.check(kHome, AllowedContacts::between({"tool0", "fingers"}, {"part_2"}))->other, "part_1");
  // A plan to a goal inside the part is refused unless the plan allows the contact.
  EXPECT_FALSE(planPath(world, kHome, kHome).ok());
  EXPECT_TRUE(planPath(world, kHome, kHome, {}, grasping).ok());
}

TEST_F(Collisions, ALinksShapesCanBeReplacedAndPutBack) {
  // A 2 cm block 5 cm from the tool centre point along the fingers' closing direction (the
  // tool's y): inside the box over the fingers' whole travel (60 mm + padding either side).
  const world::Pose tcp = kBaseInWorld * robot.forward(kHome);
  world.setBox("block", tcp * Eigen::Translation3d(0, 0.05, 0), {0.02, 0.02, 0.02});
  const auto contact = world.check(kHome);
  ASSERT_TRUE(contact.has_value());
  EXPECT_EQ(contact->str(), "fingers would touch block");
  const std::vector<CollisionShape> travel = world.linkShapes("fingers");
  ASSERT_EQ(travel.size(), 1u);
  // Two 8 mm pads 40 mm apart (their inner faces) miss it; 80 mm apart they reach it.
  world.setLinkShapes("fingers", pads(0.04));
  EXPECT_FALSE(world.check(kHome).has_value());
  world.setLinkShapes("fingers", pads(0.08));
  ASSERT_TRUE(world.check(kHome).has_value());
  EXPECT_EQ(world.check(kHome)->str(), "fingers would touch block");
  world.setLinkShapes("fingers", travel);
  EXPECT_EQ(world.linkShapes("fingers").size(), 1u);
  EXPECT_TRUE(world.check(kHome).has_value());
  EXPECT_THROW(world.setLinkShapes("tcp", {}), std::invalid_argument);  // a link without shapes
  EXPECT_THROW(world.linkShapes("gripper"), std::invalid_argument);
}

TEST_F(Collisions, AQueryCarriesItsSceneAndLeavesTheWorldAsItWas) {
  // The fingers at an opening, a keep-out box and a part left out, each for one query only.
  const world::Pose tcp = kBaseInWorld * robot.forward(kHome);
  world.setBox("block", tcp * Eigen::Translation3d(0, 0.05, 0), {0.02, 0.02, 0.02});
  QueryScene narrow;
  narrow.link_shapes = {{"fingers", pads(0.04)}};
  EXPECT_FALSE(world.check(kHome, narrow).has_value());
  EXPECT_EQ(world.check(kHome)->str(), "fingers would touch block");  // the world's fingers as they were
  EXPECT_EQ(world.linkShapes("fingers").size(), 1u);

  QueryScene without_block;
  without_block.removed = {"block"};
  EXPECT_FALSE(world.check(kHome, without_block).has_value());
  EXPECT_EQ(world.obstacleNames(), (std::vector<std::string>{"block", "table"}));

  // An obstacle of its own is reported by its name, in name order with the world's.
  QueryScene keep_out;
  keep_out.removed = {"block"};
  keep_out.obstacles = {{"a_keep_out", tcp, {0.1, 0.1, 0.1}}};
  const auto contact = world.check(kHome, keep_out);
  ASSERT_TRUE(contact.has_value());
  EXPECT_EQ(contact->other, "a_keep_out");
  EXPECT_EQ(world.obstacleNames(), (std::vector<std::string>{"block", "table"}));

  // A prepared query answers the same as one made per configuration, and plans see the scene.
  CollisionWorld::Query prepared = world.query(narrow);
  EXPECT_FALSE(prepared.check(kHome).has_value());
  EXPECT_FALSE(prepared.checkSegment(kHome, kHome).has_value());
  EXPECT_FALSE(planPath(world, kHome, kHome).ok());
  EXPECT_TRUE(planPath(world, kHome, kHome, {}, narrow).ok());
  QueryScene unknown_link;
  unknown_link.link_shapes = {{"gripper", pads(0.04)}};
  EXPECT_THROW(world.query(unknown_link), std::invalid_argument);
}

TEST_F(Collisions, QueriesOnSeveralThreadsAgreeWithOneThread) {
  // Queries place their own copies of the robot's shapes: two threads checking different
  // configurations at once get what one thread gets.
  const world::Pose tcp = kBaseInWorld * robot.forward(kHome);
  world.setBox("part_1", tcp, {0.05, 0.05, 0.05});
  std::vector<Eigen::VectorXd> configurations;
  for (int k = 0; k < 40; ++k) {
    Eigen::VectorXd q = kHome;
    q[0] += 0.05 * k;
    q[1] -= 0.02 * k;
    configurations.push_back(q);
  }
  std::vector<std::string> alone(configurations.size());
  for (std::size_t k = 0; k < configurations.size(); ++k) {
    const auto contact = world.check(configurations[k]);
    alone[k] = contact ? contact->str() : "free";
  }
  std::vector<std::string> together(configurations.size());
  const auto work = [&](std::size_t first) {
    for (int round = 0; round < 20; ++round) {
      for (std::size_t k = first; k < configurations.size(); k += 2) {
        const auto contact = world.check(configurations[k]);
        together[k] = contact ? contact->str() : "free";
      }
    }
  };
  std::thread other(work, 1);
  work(0);
  other.join();
  EXPECT_EQ(together, alone);
}

/// The tool over the table at 25 cm, swung to the left or right by the shoulder pan.
Eigen::VectorXd swung(double pan) { return joints({pan, -2.0, 2.0, -M_PI / 2, -M_PI / 2, 0.0}); }

/// A 24 cm post that the tool passes over at pan 0 (its TCP at (0.31, 0.109, 0.25)).
void addPost(CollisionWorld& world) {
  world.setBox("post", world::Pose(Eigen::Translation3d(0.31, 0.11, 0.12)), {0.04, 0.04, 0.24});
}

TEST_F(Collisions, SegmentsAreCheckedAlongTheirWholeLength) {
  const Eigen::VectorXd left = swung(1.2);
  const Eigen::VectorXd right = swung(-1.2);
  EXPECT_FALSE(world.checkSegment(left, right).has_value());
  addPost(world);
  EXPECT_FALSE(world.check(left).has_value());
  EXPECT_FALSE(world.check(right).has_value());
  const auto contact = world.checkSegment(left, right);
  ASSERT_TRUE(contact.has_value());
  EXPECT_EQ(contact->other, "post");
}

TEST_F(Collisions, ThePlannerFindsAWayAroundAnObstacleThatBlocksTheStraightMotion) {
  const Eigen::VectorXd left = swung(1.2);
  const Eigen::VectorXd right = swung(-1.2);
  addPost(world);
  const PlanResult plan = planPath(world, left, right, {.time_limit_s = 5.0, .seed = 7});
  ASSERT_TRUE(plan.ok()) << plan.failure;
  EXPECT_GT(plan.path.size(), 2u);
  EXPECT_TRUE(plan.path.front().isApprox(left));
  EXPECT_TRUE(plan.path.back().isApprox(right));
  for (std::size_t i = 1; i < plan.path.size(); ++i) {
    EXPECT_FALSE(world.checkSegment(plan.path[i - 1], plan.path[i]).has_value());
  }
  // The same seed gives the same plan, whatever was planned in between.
  planPath(world, right, left, {.time_limit_s = 5.0, .seed = 99});
  const PlanResult again = planPath(world, left, right, {.time_limit_s = 5.0, .seed = 7});
  ASSERT_EQ(again.path.size(), plan.path.size());
  for (std::size_t i = 0; i < plan.path.size(); ++i) {
    EXPECT_TRUE(again.path[i].isApprox(plan.path[i], 1e-12));
  }
}

TEST_F(Collisions, TheToolStaysInsideTheWorkspace) {
  EXPECT_FALSE(world.check(kHome).has_value());
  world.setWorkspace(Eigen::AlignedBox3d(Eigen::Vector3d(0.3, -1, 0), Eigen::Vector3d(1, 1, 1)));
  const auto contact = world.check(kHome);  // home's tool is at x = 0.17
  ASSERT_TRUE(contact.has_value());
  EXPECT_EQ(contact->str(), "tcp would touch the workspace boundary");
  // A query about the links alone (free-drive's look-ahead of the arm past the tool) leaves it out.
  QueryScene links_only;
  links_only.workspace = false;
  EXPECT_FALSE(world.check(kHome, links_only).has_value());
}

TEST_F(Collisions, ThePlannerSaysWhyWhenTheGoalIsInCollision) {
  Eigen::VectorXd down = kHome;
  down[1] = -1.2;
  const PlanResult plan = planPath(world, kHome, down);
  EXPECT_FALSE(plan.ok());
  EXPECT_NE(plan.failure.find("the goal is in collision"), std::string::npos) << plan.failure;
  EXPECT_NE(plan.failure.find("table"), std::string::npos);
  EXPECT_EQ(planPath(world, kHome, kHome).path.size(), 2u);  // nothing to plan
}

TEST_F(Collisions, AGoalBeyondAJointsLimitIsRefusedNamingTheJoint) {
  Eigen::VectorXd beyond = kHome;
  beyond[5] = world.robot().upperLimits()[5] + 0.01;
  const PlanResult plan = planPath(world, kHome, beyond);
  EXPECT_FALSE(plan.ok());
  EXPECT_NE(plan.failure.find("the goal is outside joint " + world.robot().jointNames()[5] + "'s limits"),
            std::string::npos)
      << plan.failure;
  beyond[5] = std::nan("");
  EXPECT_NE(planPath(world, kHome, beyond).failure.find("outside joint"), std::string::npos)
      << planPath(world, kHome, beyond).failure;  // not "in collision": a NaN angle is no configuration
}

}  // namespace
}  // namespace costar::planning
