#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include <filesystem>

#include "core/paths.h"
#include "smartmove/grasps.h"
#include "smartmove/selection.h"
#include "smartmove/smartmove.h"

namespace costar::smartmove {
namespace {

world::ObjectClass loadClass(const std::string& name) {
  return world::loadObjectClass(dataRoot() / "data/objects" / (name + ".json"));
}

TEST(PredicateList, ObjectIsTheFirstArgumentUnlessAWildcardSaysOtherwise) {
  const auto patterns = parsePredicateList(" right_of(table_center) ; on(node_1, ?);is_a(node)  ;");
  ASSERT_EQ(patterns.size(), 3u);
  EXPECT_EQ(patterns[0].predicate, "right_of");
  EXPECT_EQ(patterns[0].args, (std::vector<std::string>{"?", "table_center"}));
  EXPECT_EQ(patterns[1].args, (std::vector<std::string>{"node_1", "?"}));
  EXPECT_EQ(patterns[2].args, (std::vector<std::string>{"?", "node"}));
  EXPECT_TRUE(parsePredicateList("").empty());
  EXPECT_EQ(parsePredicateList("gripper_open")[0].args, std::vector<std::string>{"?"});
  EXPECT_THROW(parsePredicateList("left_of(table_center"), std::invalid_argument);
  EXPECT_THROW(parsePredicateList("near(?, ?)"), std::invalid_argument);
  EXPECT_THROW(parsePredicateList("left of(x)"), std::invalid_argument);
  EXPECT_THROW(parsePredicateList("near(a;b)"), std::invalid_argument);
}

TEST(Grasps, ATeachingOnATurnedPartSnapsToTheSameCanonicalGrasp) {
  const world::ObjectClass node = loadClass("node");
  const world::Pose canonical = world::poseFromXyzRpy(0, 0, 0.005, M_PI, 0, 0);
  for (const Eigen::Matrix3d& symmetry : node.symmetries) {
    // The same physical grasp, seen from the node's frame turned by a symmetry.
    world::Pose turned = world::Pose::Identity();
    turned.linear() = symmetry;
    const world::Pose taught = turned.inverse() * canonical;
    const world::Pose snapped = snapToCanonical(taught, node);
    EXPECT_TRUE(snapped.isApprox(canonical, 1e-9));
  }
}

TEST(Grasps, TaughtGraspsOverrideDefaultsAndPersist) {
  const auto file = std::filesystem::temp_directory_path() / "costar_grasps_test.json";
  std::filesystem::remove(file);
  {
    GraspLibrary library(dataRoot() / "data/grasps.json", file);
    ASSERT_TRUE(library.find("node", "top").has_value());
    EXPECT_FALSE(library.find("node", "side").has_value());
    library.teach({"node", "side", world::poseFromXyzRpy(0.03, 0, 0, 0, -M_PI / 2, 0)});
    library.teach({"node", "top", world::poseFromXyzRpy(0, 0, 0.01, M_PI, 0, 0)});
  }
  GraspLibrary reloaded(dataRoot() / "data/grasps.json", file);
  EXPECT_NEAR(reloaded.find("node", "top")->tcp_in_object.translation().z(), 0.01, 1e-12);
  // A hostile tester taught '', '../x', 'a b' and 100 characters: each was saved.
  for (const std::string& bad : std::vector<std::string>{"", "../x", "/tmp/abs", "a b", std::string(100, 'g')}) {
    EXPECT_THROW(reloaded.teach({"node", bad, world::poseFromXyzRpy(0, 0, 0.02, M_PI, 0, 0)}), std::invalid_argument)
        << bad;
    EXPECT_TRUE(bad.empty() || !reloaded.find("node", bad).has_value()) << bad;
  }
  EXPECT_TRUE(reloaded.find("node", "side").has_value());
  EXPECT_EQ(reloaded.forClass("node").size(), 2u);
  std::filesystem::remove(file);
}

TEST(Grasps, OneClassHasATwoFingerAndAThreeFingerGrasp) {
  const GraspLibrary two(dataRoot() / "data/grasps.json", {});
  const GraspLibrary three(dataRoot() / "data/grasps.json", {}, kAdaptiveGripper);
  EXPECT_EQ(two.gripper(), kParallelGripper);
  // The 2-finger gripper sees only its own grasps (the file's entries without "gripper").
  ASSERT_EQ(two.forClass("node").size(), 1u);
  EXPECT_EQ(two.defaultFor("node")->name, "top");
  EXPECT_FALSE(two.find("node", "basic").has_value());
  // The 3-finger gripper has one grasp per mode for the same class, plus its own "top" (node)
  // and "middle" (link), so that the UR5 plans that name them run unchanged; none of the
  // 2-finger's.
  EXPECT_EQ(three.forClass("node").size(), 5u);
  EXPECT_EQ(three.forClass("link").size(), 5u);
  for (const Grasp& grasp : three.forClass("node")) {
    EXPECT_EQ(grasp.gripper, kAdaptiveGripper) << grasp.name;
  }
  ASSERT_TRUE(three.find("node", "top").has_value());
  EXPECT_EQ(three.find("node", "top")->gripper, kAdaptiveGripper);
  EXPECT_NE(three.find("link", "middle")->tcp_in_object.translation(),
            two.find("link", "middle")->tcp_in_object.translation());
  ASSERT_TRUE(three.find("link", "scissor").has_value());
  EXPECT_EQ(three.find("link", "scissor")->gripper, kAdaptiveGripper);
  // Each 3-finger grasp names the mode it needs (SmartGrasp sets it while the fingers are open);
  // "top" and "middle" are fingertip (Pinch) grasps: an encompassing Basic grasp pulls the part
  // toward the palm and the held transform no longer holds. The 2-finger grasps need none.
  for (const char* name : {"basic", "pinch", "wide", "scissor"}) {
    EXPECT_EQ(three.find("node", name)->mode, name);
    EXPECT_EQ(three.find("link", name)->mode, name);
  }
  EXPECT_EQ(three.find("node", "top")->mode, "pinch");
  // A plan that names no grasp gets the class's first in the file: the Pinch one for 3 fingers.
  EXPECT_EQ(three.defaultFor("node")->name, "top");
  EXPECT_EQ(three.defaultFor("link")->name, "middle");
  EXPECT_EQ(three.find("link", "middle")->mode, "pinch");
  EXPECT_TRUE(two.find("node", "top")->mode.empty());
  EXPECT_TRUE(two.find("link", "middle")->mode.empty());
  // Scissor closes fingers 1 and 2 along the tool's x: across the link (object y), not along it.
  const Eigen::Vector3d closing = three.find("link", "scissor")->tcp_in_object.linear().col(0);
  EXPECT_NEAR(std::abs(closing.y()), 1.0, 1e-9);
}

TEST(Grasps, TeachingKeepsTheOtherGrippersGraspsAndOldFilesStayValid) {
  const auto file = std::filesystem::temp_directory_path() / "costar_grasps_gripper_test.json";
  // A taught file written before grasps had grippers: its entries are the 2-finger gripper's.
  std::ofstream(file) << R"({"grasps": [{"class": "node", "name": "edge", "position": [0, 0, 0.01],)"
                         R"( "rpy_degrees": [180, 0, 0]}]})";
  {
    GraspLibrary three(dataRoot() / "data/grasps.json", file, kAdaptiveGripper);
    EXPECT_FALSE(three.find("node", "edge").has_value());
    three.teach({"node", "corner", world::poseFromXyzRpy(0.01, 0, 0, M_PI, 0, 0), {}, "wide"});
  }
  const GraspLibrary two(dataRoot() / "data/grasps.json", file);
  EXPECT_TRUE(two.find("node", "edge").has_value());  // still there after the 3-finger teach
  EXPECT_FALSE(two.find("node", "corner").has_value());
  const GraspLibrary three(dataRoot() / "data/grasps.json", file, kAdaptiveGripper);
  ASSERT_TRUE(three.find("node", "corner").has_value());
  EXPECT_NEAR(three.find("node", "corner")->tcp_in_object.translation().x(), 0.01, 1e-12);
  EXPECT_EQ(three.find("node", "corner")->mode, "wide");  // the mode it was taught in, saved
  EXPECT_TRUE(two.find("node", "edge")->mode.empty());
  // The 2-finger entry is written back without a "gripper" field, as before.
  std::ifstream in(file);
  const nlohmann::json saved = nlohmann::json::parse(in);
  for (const auto& item : saved.at("grasps")) {
    EXPECT_EQ(item.contains("gripper"), item.at("name") == "corner") << item.dump();
  }
  std::filesystem::remove(file);
}

TEST(Grasps, ABadEntryNamesTheFileAndTheEntry) {
  const auto file = std::filesystem::temp_directory_path() / "costar_grasps_bad_test.json";
  std::ofstream(file)
      << R"({"grasps": [{"class": "node", "name": "a", "position": [0, 0, 0], "rpy_degrees": [0, 0, 0]},)"
         R"( {"gripper": "", "class": "node", "name": "b", "position": [0, 0, 0], "rpy_degrees": [0, 0, 0]}]})";
  try {
    GraspLibrary library(file, {});
    ADD_FAILURE() << "accepted an empty gripper";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("costar_grasps_bad_test.json': grasps[1]: \"gripper\" must not be empty"),
              std::string::npos)
        << e.what();
  }
  std::ofstream(file)
      << R"({"grasps": [{"gripper": "robotiq3f", "mode": "", "class": "node", "name": "a", "position": [0, 0, 0],)"
         R"( "rpy_degrees": [0, 0, 0]}]})";
  try {
    GraspLibrary library(file, {}, kAdaptiveGripper);
    ADD_FAILURE() << "accepted an empty mode";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("grasps[0]: \"mode\" must not be empty"), std::string::npos) << e.what();
  }
  std::filesystem::remove(file);
}

// Issue 27: a grasp file with the same (gripper, class, name) twice silently kept the second.
TEST(Grasps, AGraspGivenTwiceIsRefusedNamingBothEntries) {
  const auto file = std::filesystem::temp_directory_path() / "costar_grasps_twice_test.json";
  std::ofstream(file)
      << R"({"grasps": [{"class": "node", "name": "top", "position": [0, 0, 0], "rpy_degrees": [0, 0, 0]},)"
         R"( {"class": "link", "name": "top", "position": [0, 0, 0], "rpy_degrees": [0, 0, 0]},)"
         R"( {"gripper": "parallel-2f", "class": "node", "name": "top", "position": [0, 0, 0.01],)"
         R"( "rpy_degrees": [0, 0, 0]}]})";
  try {
    GraspLibrary library(file, {});
    ADD_FAILURE() << "accepted a grasp given twice";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), "grasp file '" + file.string() +
                                         "': grasps[2]: gripper 'parallel-2f', class 'node', name 'top' is given "
                                         "twice, in grasps[0] and here (one grasp per gripper, class and name)");
  }
  std::filesystem::remove(file);
}

/// An arm that reaches goals with x < 0.6; "joints" encode the goal for the cost.
ArmModel fakeArm() {
  ArmModel arm;
  arm.solutions = [](const world::Pose& goal) -> std::vector<arm::JointVector> {
    if (goal.translation().x() >= 0.6) {
      return {};
    }
    return {{goal.translation().x(), goal.translation().y(), 0, 0, 0, 0}};
  };
  arm.tool = world::poseFromXyzRpy(0.2, 0, 0.3, M_PI, 0, 0);
  arm.joints = {0.2, 0, 0, 0, 0, 0};
  return arm;
}

TEST(Selection, ChecksInOrderOfCostAndStopsAtTheFirstFeasible) {
  const world::ObjectClass node = loadClass("node");
  const std::vector<std::pair<std::string, world::Pose>> objects = {
      {"near_but_blocked", world::Pose(Eigen::Translation3d(0.25, 0, 0.025))},
      {"middle", world::Pose(Eigen::Translation3d(0.4, 0.1, 0.025))},
      {"far_away", world::Pose(Eigen::Translation3d(0.9, 0, 0.025))}};
  int checks = 0;
  const Selection selection =
      selectGoal(objects, node, world::poseFromXyzRpy(0, 0, 0.005, M_PI, 0, 0), fakeArm(), {},
                 [&checks](Candidate& candidate) -> std::string {
                   ++checks;
                   return candidate.object == "near_but_blocked" ? "collision at the goal: x" : "";
                 });
  ASSERT_TRUE(selection.ok());
  EXPECT_EQ(selection.best().object, "middle");
  EXPECT_EQ(selection.candidates.size(), 72u);  // 3 objects x 24 symmetries
  // The top-down ones of the nearest node were checked first and failed.
  EXPECT_LE(checks, 24 + 1);
  int unreachable = 0;
  int not_checked = 0;
  for (const Candidate& candidate : selection.candidates) {
    unreachable += candidate.object == "far_away" ? 1 : 0;
    if (candidate.object == "far_away") {
      EXPECT_EQ(candidate.rejected, "no IK solution: out of reach or beyond the joint limits");
    }
    not_checked += candidate.rejected == "not checked: a cheaper candidate works" ? 1 : 0;
  }
  EXPECT_EQ(unreachable, 24);
  EXPECT_GT(not_checked, 0);
  // The chosen goal approaches from above: least tilt among the node's symmetric goals.
  EXPECT_NEAR(selection.best().goal.linear().col(2).z(), -1.0, 1e-9);
  const nlohmann::json json = selection.toJson();
  EXPECT_EQ(json.at("chosen"), "middle");
  EXPECT_EQ(json.at("candidates").size(), 72u);
}

TEST(Selection, WithNothingFeasibleTheFailureCountsTheReasons) {
  const world::ObjectClass link = loadClass("link");
  const Selection selection = selectGoal(
      {{"link_1", world::Pose(Eigen::Translation3d(0.9, 0, 0.0125))}, {"link_2", world::Pose::Identity()}}, link,
      world::Pose::Identity(), fakeArm(), {}, [](Candidate&) { return std::string("collision at the goal: y"); });
  EXPECT_FALSE(selection.ok());
  EXPECT_EQ(selection.failure, "16 candidates, none feasible (8 collision at the goal, 8 no IK solution)");
}

// "1 candidate, none feasible (1 predicate false)" did not say which predicate of which part was
// false (the UR5 assembly's top node: its one link not left of table_center, as the link across
// the base node had not been seen).
TEST(Selection, AFailureOnAPredicateNamesWhichWasFalse) {
  const auto rejected = [](const std::string& object, const std::string& reason) {
    Candidate candidate;
    candidate.object = object;
    candidate.symmetry = -1;
    candidate.rejected = reason;
    return candidate;
  };
  Selection one;
  one.candidates = {rejected("link_1", "predicate false: left_of(link_1,table_center) is false")};
  one.summarizeFailure();
  EXPECT_EQ(one.failure, "1 candidate, none feasible (1 predicate false: left_of(link_1,table_center) is false)");
  // Each distinct one, at most three, beside the other reasons' counts.
  Selection many;
  for (int n = 1; n <= 5; ++n) {
    const std::string part = "node_" + std::to_string(n);
    many.candidates.push_back(rejected(part, "predicate false: right_of(" + part + ",table_center) is false"));
  }
  many.candidates.push_back(rejected("node_6", "no IK solution: out of reach or beyond the joint limits"));
  many.summarizeFailure();
  EXPECT_EQ(many.failure,
            "6 candidates, none feasible (1 no IK solution, 5 predicate false: right_of(node_1,table_center) is false; "
            "right_of(node_2,table_center) is false; right_of(node_3,table_center) is false; 2 more)");
}

}  // namespace
}  // namespace costar::smartmove
