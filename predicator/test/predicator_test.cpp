// Predicates on hand-made scenes: the convention, the dead bands (nearly equal is neither),
// contacts, on-demand references, queries, switching sub-components, incremental updates.

#include "predicator/predicator.h"

#include <gtest/gtest.h>

#include "core/paths.h"

namespace costar::predicator {
namespace {

using world::FrameValue;
using world::Pose;
using world::Symbol;

class PredicatorTest : public ::testing::Test {
 protected:
  PredicatorTest() : predicator(world, world::loadObjectClasses(dataRoot() / "data/objects")) {
    world.update("workcell",
                 {{Symbol{"table_center", "", {}, FrameValue{"world", Pose(Eigen::Translation3d(0.5, 0, 0))}}}, {}});
  }

  /// Places objects (name, class, x, y, z) as a perception component would report them.
  void place(const std::vector<std::tuple<std::string, std::string, double, double, double>>& objects) {
    world::Report report;
    for (const auto& [name, object_class, x, y, z] : objects) {
      report.symbols.push_back({name, "", {}, FrameValue{"world", Pose(Eigen::Translation3d(x, y, z))}});
      report.predicates.push_back({"is_a", {name, object_class}, true, ""});
    }
    world.update("perception", report);
    world.update("predicator", predicator.report());
  }

  bool holds(const std::string& predicate, const std::string& a, const std::string& b) {
    return world.holds(predicate, std::vector<std::string>{a, b});
  }

  world::WorldState world;
  Predicator predicator;
};

TEST_F(PredicatorTest, DirectionsFollowTheConventionWithDeadBands) {
  place({{"left", "node", 0.5, 0.021, 0.025},
         {"dead_band", "node", 0.5, 0.019, 0.025},
         {"right", "node", 0.5, -0.3, 0.025},
         {"front", "node", 0.7, 0.0, 0.025},
         {"back", "node", 0.3, 0.0, 0.025}});
  EXPECT_TRUE(holds("left_of", "left", "table_center"));
  EXPECT_FALSE(holds("left_of", "dead_band", "table_center"));   // 1.9 cm: neither left ...
  EXPECT_FALSE(holds("right_of", "dead_band", "table_center"));  // ... nor right
  EXPECT_TRUE(holds("right_of", "right", "table_center"));
  EXPECT_FALSE(holds("left_of", "right", "table_center"));
  EXPECT_TRUE(holds("in_front_of", "front", "table_center"));  // farther from the robot
  EXPECT_TRUE(holds("behind", "back", "table_center"));
  EXPECT_FALSE(holds("behind", "front", "table_center"));
}

TEST_F(PredicatorTest, EqualHeightsAreNeitherAboveNorBelow) {
  place({{"a", "node", 0.4, 0.2, 0.025},
         {"b", "node", 0.6, -0.2, 0.025},
         {"c", "node", 0.4, -0.2, 0.04},
         {"d", "node", 0.6, 0.2, 0.05}});
  EXPECT_FALSE(holds("above", "a", "b"));
  EXPECT_FALSE(holds("below", "a", "b"));
  EXPECT_FALSE(holds("above", "c", "a"));  // 1.5 cm higher: within the dead band
  EXPECT_TRUE(holds("above", "d", "a"));   // 2.5 cm higher
  EXPECT_TRUE(holds("below", "a", "d"));
}

TEST_F(PredicatorTest, OnMeansRestingOnTopAndNearMeansClose) {
  place({{"base", "node", 0.5, -0.2, 0.025},
         {"top", "node", 0.5, -0.2, 0.075},          // resting on base
         {"overhanging", "node", 0.53, 0.2, 0.075},  // 3 cm off: its centre is beyond base2's face
         {"base2", "node", 0.5, 0.2, 0.025},
         {"link", "link", 0.5, -0.12, 0.0125},  // its box 4.25 cm from base's
         {"far", "node", 0.5, 0.4, 0.025}});
  EXPECT_TRUE(holds("on", "top", "base"));
  EXPECT_FALSE(holds("on", "base", "top"));
  EXPECT_FALSE(holds("on", "overhanging", "base2"));
  EXPECT_TRUE(holds("above", "top", "base"));
  EXPECT_TRUE(holds("near", "top", "base"));
  EXPECT_FALSE(holds("near", "far", "base2"));   // 20 cm apart
  EXPECT_TRUE(holds("near", "link", "base"));    // near is measured between the boxes
  EXPECT_FALSE(holds("near", "base2", "base"));  // 40 cm apart, boxes 35 cm
}

TEST_F(PredicatorTest, AnySymbolCanBeAReferenceOnDemand) {
  place({{"a", "node", 0.5, 0.2, 0.025}, {"b", "node", 0.5, -0.2, 0.025}});
  // Not reported (only table_center is a reported reference) but evaluated when asked.
  const std::vector<std::string> ab{"a", "b"};
  bool reported = false;
  for (const auto* predicate : world.predicates("left_of")) {
    reported = reported || predicate->args == ab;
  }
  EXPECT_FALSE(reported);
  EXPECT_TRUE(holds("left_of", "a", "b"));
  EXPECT_TRUE(holds("right_of", "b", "a"));
  EXPECT_FALSE(holds("left_of", "a", "a"));
  EXPECT_FALSE(holds("left_of", "a", "unknown_thing"));
}

TEST_F(PredicatorTest, QueriesFindTheSymbolsThatSatisfyAllOrAnyPatterns) {
  place({{"node_1", "node", 0.5, -0.2, 0.025},
         {"node_2", "node", 0.5, 0.2, 0.025},
         {"link_1", "link", 0.4, -0.25, 0.0125}});
  EXPECT_EQ(predicator.match({{"is_a", {"?", "node"}}, {"right_of", {"?", "table_center"}}}),
            std::vector<std::string>{"node_1"});
  EXPECT_EQ(predicator.match({{"is_a", {"?", "link"}}, {"left_of", {"?", "table_center"}}}, MatchMode::kAny),
            (std::vector<std::string>{"link_1", "node_2"}));
  EXPECT_THROW(predicator.match({{"is_a", {"node_1", "node"}}}), std::invalid_argument);
  EXPECT_TRUE(predicator.test("is_a", {"node_2", "node"}));
}

TEST_F(PredicatorTest, SubComponentsCanBeSwitchedOffAndOn) {
  place({{"a", "node", 0.5, 0.2, 0.025}, {"b", "node", 0.5, 0.25, 0.025}});
  ASSERT_TRUE(holds("left_of", "a", "table_center"));
  const auto off = predicator.start("ActivatePredicates", {{"sub_component", "geometry"}, {"active", false}});
  ASSERT_EQ(predicator.poll(off).state, component::OperationState::kSuccess);
  world.update("predicator", predicator.report());
  EXPECT_FALSE(holds("left_of", "a", "table_center"));
  EXPECT_FALSE(holds("left_of", "b", "a"));  // nor on demand
  EXPECT_TRUE(holds("near", "a", "b"));      // contact is still on
  const auto on = predicator.start("ActivatePredicates", {{"sub_component", "geometry"}, {"active", true}});
  predicator.poll(on);
  world.update("predicator", predicator.report());
  EXPECT_TRUE(holds("left_of", "a", "table_center"));
}

TEST_F(PredicatorTest, UpdatesRecomputeOnlyWhatMoved) {
  std::vector<std::tuple<std::string, std::string, double, double, double>> objects;
  for (int i = 0; i < 400; ++i) {
    objects.emplace_back("node_" + std::to_string(i), "node", 0.1 + 0.05 * (i % 20), -0.5 + 0.05 * (i / 20), 0.025);
  }
  place(objects);
  const std::size_t full = predicator.lastRecomputed();
  world.update("predicator", predicator.report());
  EXPECT_EQ(predicator.lastRecomputed(), 0u);  // nothing moved
  std::get<2>(objects[210]) += 0.01;
  place(objects);
  EXPECT_GT(predicator.lastRecomputed(), 0u);
  EXPECT_LT(predicator.lastRecomputed() * 20, full);  // a neighbourhood, not everything
  // Facts of a removed object go, and so do its neighbours' facts about it.
  ASSERT_TRUE(holds("near", "node_0", "node_1"));
  objects.erase(objects.begin() + 1);
  place(objects);
  EXPECT_FALSE(holds("near", "node_0", "node_1"));
  for (const auto* predicate : world.predicates("near")) {
    EXPECT_NE(predicate->args[1], "node_1");
  }
}

}  // namespace
}  // namespace costar::predicator
