#include "world/world_state.h"

#include <gtest/gtest.h>

namespace costar::world {
namespace {

Symbol frame(std::string name, std::string parent, Pose pose) {
  return Symbol{std::move(name), "", {}, FrameValue{std::move(parent), pose}};
}

TEST(WorldState, IsTheUnionOfTheSourcesReports) {
  WorldState world;
  world.update("gripper", {{}, {{"gripper_open", {}, true, ""}}});
  world.update("perception", {{frame("node_1", "world", Pose(Eigen::Translation3d(1, 0, 0)))},
                              {{"is_a", {"node_1", "node"}, true, ""}}});
  EXPECT_TRUE(world.holds("gripper_open", {}));
  const std::vector<std::string> args{"node_1", "node"};
  EXPECT_TRUE(world.holds("is_a", args));
  ASSERT_NE(world.symbol("node_1"), nullptr);
  EXPECT_EQ(world.symbol("node_1")->source, "perception");
  EXPECT_EQ(world.predicates("is_a").size(), 1u);

  // A new report replaces the source's old one.
  const auto version = world.version();
  world.update("gripper", {{}, {{"gripper_closed", {}, true, ""}}});
  EXPECT_FALSE(world.holds("gripper_open", {}));
  EXPECT_TRUE(world.holds("gripper_closed", {}));
  EXPECT_GT(world.version(), version);
  world.removeSource("perception");
  EXPECT_EQ(world.symbol("node_1"), nullptr);
}

TEST(WorldState, APredicateReportedFalseBySomeSourceDoesNotHold) {
  WorldState world;
  world.update("a", {{}, {{"ready", {}, true, ""}}});
  world.update("b", {{}, {{"ready", {}, false, ""}}});
  EXPECT_FALSE(world.holds("ready", {}));
}

TEST(WorldState, WorldPoseComposesParentFrames) {
  WorldState world;
  world.update("cal", {{frame("table_center", "world", poseFromXyzRpy(0.5, 0, 0.1, 0, 0, M_PI / 2)),
                        frame("above_table", "table_center", Pose(Eigen::Translation3d(0.1, 0, 0.2))),
                        frame("loop_a", "loop_b", Pose::Identity()), frame("loop_b", "loop_a", Pose::Identity())},
                       {}});
  const auto pose = world.worldPose("above_table");
  ASSERT_TRUE(pose.has_value());
  EXPECT_TRUE(pose->translation().isApprox(Eigen::Vector3d(0.5, 0.1, 0.3), 1e-12));
  EXPECT_FALSE(world.worldPose("unknown").has_value());
  EXPECT_FALSE(world.worldPose("loop_a").has_value());
}

TEST(Pose, ParsesMetresAndDegreesAndRoundTrips) {
  std::string error;
  const auto pose = parsePose("0.1; 0.2;0.3;0;0;90", &error);
  ASSERT_TRUE(pose.has_value()) << error;
  EXPECT_TRUE((pose->linear() * Eigen::Vector3d::UnitX()).isApprox(Eigen::Vector3d::UnitY(), 1e-12));
  const auto again = parsePose(formatPose(*pose));
  ASSERT_TRUE(again.has_value());
  EXPECT_TRUE(again->isApprox(*pose, 1e-12));
  EXPECT_TRUE(parsePose("1;2;3")->translation().isApprox(Eigen::Vector3d(1, 2, 3)));
  EXPECT_FALSE(parsePose("1;2", &error).has_value());
  EXPECT_NE(error.find("has 2 numbers"), std::string::npos);
  EXPECT_FALSE(parsePose("1;x;3", &error).has_value());
  EXPECT_FALSE(parsePose("1;nan;3").has_value());
}

// A hostile tester's MoveToPose pose="0.4;0;0.3;1e308;0;0" was accepted.
TEST(Pose, AnglesBeyond360DegreesAndCoordinatesBeyond100MetresAreRefused) {
  std::string error;
  EXPECT_FALSE(parsePose("0.4;0;0.3;1e308;0;0", &error).has_value());
  EXPECT_EQ(error, "'0.4;0;0.3;1e308;0;0': roll 1e+308 is not within 360 degrees either way");
  EXPECT_FALSE(parsePose("0;-1000;0", &error).has_value());
  EXPECT_EQ(error, "'0;-1000;0': y -1000 is not within 100 m either way");
  EXPECT_TRUE(parsePose("100;0;0;-360;360;0").has_value());
}

TEST(Pose, RpyOfInvertsPoseFromXyzRpy) {
  for (double roll : {-2.0, 0.0, 0.7}) {
    for (double pitch : {-1.2, 0.0, 1.4}) {
      for (double yaw : {-3.0, 0.1, 2.5}) {
        const Pose pose = poseFromXyzRpy(0, 0, 0, roll, pitch, yaw);
        const Eigen::Vector3d rpy = rpyOf(pose.linear());
        EXPECT_TRUE(poseFromXyzRpy(0, 0, 0, rpy.x(), rpy.y(), rpy.z()).isApprox(pose, 1e-9));
      }
    }
  }
  EXPECT_NEAR(rotationAngle(Pose::Identity(), poseFromXyzRpy(0, 0, 0, 0, 0, 0.5)), 0.5, 1e-12);
}

}  // namespace
}  // namespace costar::world

namespace costar::world {
namespace {

TEST(WorldState, DerivedPredicatesAreEvaluatedOnDemand) {
  WorldState world;
  world.update("perception", {{Symbol{"a", "", {}, FrameValue{"world", Pose(Eigen::Translation3d(0, 0.3, 0))}},
                               Symbol{"b", "", {}, FrameValue{"world", Pose(Eigen::Translation3d(0, -0.3, 0))}}},
                              {{"is_a", {"a", "node"}, true, ""}, {"is_a", {"b", "node"}, true, ""}}});
  world.setEvaluator("left_of", [](const WorldState& w, std::span<const std::string> args) {
    const auto subject = w.worldPose(args[0]);
    const auto reference = w.worldPose(args[1]);
    return subject && reference && subject->translation().y() > reference->translation().y() + 0.02;
  });
  const std::vector<std::string> ab{"a", "b"};
  const std::vector<std::string> ba{"b", "a"};
  EXPECT_TRUE(world.holds("left_of", ab));
  EXPECT_FALSE(world.holds("left_of", ba));
  // Wildcards: which symbols are left of b; which are nodes.
  const std::vector<std::string> left_of_b{"?", "b"};
  EXPECT_EQ(world.match("left_of", left_of_b), std::vector<std::string>{"a"});
  const std::vector<std::string> nodes{"?", "node"};
  EXPECT_EQ(world.match("is_a", nodes), (std::vector<std::string>{"a", "b"}));
  const std::vector<std::string> two{"?", "?"};
  EXPECT_THROW(world.match("is_a", two), std::invalid_argument);
  EXPECT_EQ(world.match("is_a", std::vector<std::string>{"a", "node"}).size(), 1u);
}

}  // namespace
}  // namespace costar::world
