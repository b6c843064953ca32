// The fingers' geometry a planner asks for, one implementation per kind of gripper.

#include "gripper/gripper_geometry.h"

#include <gtest/gtest.h>

#include "gripper/parallel_gripper_description.h"

namespace costar::gripper {
namespace {

/// The 2-finger gripper of the UR5 cell, as its description gives it.
FingerGeometry twoFingers() { return loadParallelGripperDescription(gripperDescriptionFile("parallel-2f")).fingers; }

TEST(GripperGeometry, AParallelGripperOpensAsFarAsAGraspNeedsAndIsModelledAtEveryOpening) {
  const auto geometry = parallelGripperGeometry(twoFingers());
  const double stroke = twoFingers().max_opening;
  ASSERT_EQ(geometry->stroke(), stroke);
  // A part 4 cm wide with a 16 mm margin; one wider than the stroke is refused.
  EXPECT_DOUBLE_EQ(*geometry->graspOpening(0.02, 0.016), 0.056);
  EXPECT_DOUBLE_EQ(*geometry->graspOpening(0.5 * stroke - 0.001, 0.016), stroke);
  EXPECT_FALSE(geometry->graspOpening(0.5 * stroke + 0.001, 0.016).has_value());
  // Boxes at an opening (both fingers, link and pad each); none asked: as the cell has them.
  const auto open = geometry->fingerBoxes({.opening = 0.05});
  ASSERT_TRUE(open.has_value());
  EXPECT_EQ(open->size(), twoFingers().at(0.05).size());
  EXPECT_FALSE(geometry->fingerBoxes({}).has_value());
  // Open to the opening asked for; no modes.
  component::ParamMap params;
  geometry->openTo({.opening = 0.05}, params);
  EXPECT_DOUBLE_EQ(params.at("opening").asDouble(), 0.05);
  EXPECT_TRUE(geometry->modes().empty());
  EXPECT_FALSE(geometry->plansMode("pinch"));
  EXPECT_GT(*geometry->reachAcross(""), 0.0);
}

TEST(GripperGeometry, AnAdaptiveGripperIsModelledInItsModes) {
  const auto geometry = adaptiveGripperGeometry(loadAdaptiveGripperDescription(gripperDescriptionFile("robotiq3f")));
  EXPECT_FALSE(geometry->stroke().has_value());
  EXPECT_EQ(geometry->graspOpening(0.02, 0.016), 0.0);  // it opens fully
  EXPECT_EQ(geometry->modes(), (std::vector<std::string>{"basic", "pinch", "wide", "scissor"}));
  EXPECT_TRUE(geometry->plansMode("pinch"));
  EXPECT_FALSE(geometry->plansMode(""));
  EXPECT_EQ(geometry->fingerBoxes({.mode = "pinch"})->size(), 3u);
  EXPECT_FALSE(geometry->fingerBoxes({.opening = 0.05}).has_value());  // a width says nothing to it
  EXPECT_FALSE(geometry->fingerBoxes({.mode = "sideways"}).has_value());
  // Pinch closes part way round a narrow part; Basic does not.
  EXPECT_GT(geometry->fingertipPosition("pinch", 0.015), 0.0);
  EXPECT_EQ(geometry->fingertipPosition("basic", 0.015), 0.0);
  component::ParamMap params;
  geometry->openTo({.mode = "pinch", .position = 0.3}, params);
  EXPECT_DOUBLE_EQ(params.at("position").asDouble(), 0.3);
  EXPECT_GT(*geometry->reachAcross("pinch"), 0.0);
  EXPECT_FALSE(geometry->reachAcross("").has_value());
}

TEST(GripperGeometry, AGripperWithoutAModelLeavesTheFingersAsTheyAre) {
  const auto geometry = rigidGripperGeometry();
  EXPECT_FALSE(geometry->fingerBoxes({.opening = 0.05, .mode = "pinch"}).has_value());
  EXPECT_EQ(geometry->graspOpening(0.3, 0.016), 0.0);
  component::ParamMap params;
  geometry->openTo({.opening = 0.05, .position = 0.3}, params);
  EXPECT_TRUE(params.empty());
  EXPECT_FALSE(geometry->reachAcross("pinch").has_value());
  EXPECT_EQ(geometry->closedHalfExtent(), Eigen::Vector2d(0.015, 0.015));
}

}  // namespace
}  // namespace costar::gripper
