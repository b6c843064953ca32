#include "world/object_class.h"

#include <gtest/gtest.h>

#include <random>

#include "core/paths.h"

namespace costar::world {
namespace {

TEST(ObjectClass, TheNodeIsACubeWithTwentyFourSymmetries) {
  const ObjectClass node = loadObjectClass(dataRoot() / "data/objects/node.json");
  EXPECT_EQ(node.name, "node");
  EXPECT_EQ(node.symmetries.size(), 24u);
  EXPECT_TRUE(node.symmetries[0].isIdentity());
  EXPECT_TRUE(node.bounds().min().isApprox(Eigen::Vector3d::Constant(-0.025)));
  EXPECT_TRUE(node.bounds().max().isApprox(Eigen::Vector3d::Constant(0.025)));
  EXPECT_EQ(node.axis_priority, "zxy");
  // Each rotation maps the shape onto itself: a point is inside iff its image is.
  const auto inside = [&node](const Eigen::Vector3d& p) {
    return std::any_of(node.boxes.begin(), node.boxes.end(),
                       [&p](const Box& b) { return ((p - b.center).cwiseAbs().array() <= b.half_size.array()).all(); });
  };
  std::mt19937 random(42);
  std::uniform_real_distribution<double> coordinate(-0.026, 0.026);
  int inside_count = 0;
  for (int i = 0; i < 2000; ++i) {
    const Eigen::Vector3d p(coordinate(random), coordinate(random), coordinate(random));
    inside_count += inside(p) ? 1 : 0;
    for (const auto& rotation : node.symmetries) {
      EXPECT_EQ(inside(rotation * p), inside(p));
    }
  }
  // The sockets are really there: a point in the +z socket is outside, below it inside.
  EXPECT_FALSE(inside({0, 0, 0.02}));
  EXPECT_TRUE(inside({0, 0, 0.014}));
  EXPECT_GT(inside_count, 1000);
}

TEST(ObjectClass, TheLinkHasEightSymmetries) {
  const ObjectClass link = loadObjectClass(dataRoot() / "data/objects/link.json");
  EXPECT_EQ(link.symmetries.size(), 8u);
  for (const auto& rotation : link.symmetries) {
    // The long axis stays the long axis (up to sign).
    EXPECT_NEAR(std::abs((rotation * Eigen::Vector3d::UnitX()).x()), 1.0, 1e-9);
  }
  EXPECT_EQ(link.color("wood").size(), 3);
  EXPECT_THROW(link.color("purple"), std::out_of_range);
}

TEST(ObjectClass, EveryClassInTheDataFolderLoads) {
  const auto classes = loadObjectClasses(dataRoot() / "data/objects");
  ASSERT_GE(classes.size(), 2u);
  for (const auto& object : classes) {
    EXPECT_GT(object.mass, 0);
    EXPECT_FALSE(object.colors.empty()) << object.name;
  }
}

TEST(ObjectClass, BadFilesAreNamedInTheError) {
  try {
    loadObjectClass("/nonexistent/thing.json");
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/thing.json"), std::string::npos);
  }
}

TEST(SymmetryGroup, GeneratorsCloseIntoAGroup) {
  const Eigen::Matrix3d z90 = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  EXPECT_EQ(symmetryGroup({z90}).size(), 4u);
  EXPECT_EQ(symmetryGroup({}).size(), 1u);
  const Eigen::Matrix3d odd = Eigen::AngleAxisd(1.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  EXPECT_THROW(symmetryGroup({odd}), std::runtime_error);
}

}  // namespace
}  // namespace costar::world
