#include "sim/scene.h"

#include <gtest/gtest.h>

#include "core/paths.h"

namespace costar::sim {
namespace {

std::vector<world::ObjectClass> classes() { return world::loadObjectClasses(dataRoot() / "data/objects"); }

TEST(Scene, FixedAndRandomPartsAreOnTheTableInTheirRegionsAndApart) {
  const Scene scene = parseScene(R"({"seed": 3, "parts": [
      {"class": "node", "color": "red", "at": [0.5, -0.2, 90]},
      {"class": "node", "count": 4, "region": "right"},
      {"class": "link", "count": 2, "region": "left"}]})",
                                 "test");
  const auto parts = placeParts(scene, classes());
  ASSERT_EQ(parts.size(), 7u);
  EXPECT_EQ(parts[0].name, "node_0");
  EXPECT_EQ(parts[0].color, "red");
  EXPECT_TRUE(parts[0].pose.translation().head<2>().isApprox(Eigen::Vector2d(0.5, -0.2)));
  EXPECT_NEAR(parts[0].pose.translation().z(), 0.0255, 1e-9);
  EXPECT_TRUE((parts[0].pose.linear() * Eigen::Vector3d::UnitX()).isApprox(Eigen::Vector3d::UnitY(), 1e-9));
  EXPECT_EQ(parts[6].name, "link_1");
  const auto regions = defaultRegions();
  for (std::size_t i = 1; i < parts.size(); ++i) {
    const Region& region = regions.at(parts[i].object_class == "node" ? "right" : "left");
    const Eigen::Vector2d xy = parts[i].pose.translation().head<2>();
    EXPECT_TRUE((xy.array() >= region.min.array()).all() && (xy.array() <= region.max.array()).all()) << parts[i].name;
    for (std::size_t j = 0; j < i; ++j) {
      EXPECT_GT((parts[j].pose.translation() - parts[i].pose.translation()).head<2>().norm(), 0.05);
    }
  }
}

TEST(Scene, PlacementIsDeterministicForASeedAndVariesWithIt) {
  const Scene scene = parseScene(R"({"seed": 11, "parts": [{"class": "node", "count": 3}]})", "test");
  const auto a = placeParts(scene, classes());
  const auto b = placeParts(scene, classes());
  const auto c = placeParts(scene, classes(), 12);
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_TRUE(a[i].pose.isApprox(b[i].pose));
  }
  EXPECT_FALSE(a[0].pose.isApprox(c[0].pose));
}

TEST(Scene, ProblemsAreNamed) {
  const auto problem = [](const std::string& json) {
    try {
      placeParts(parseScene(json, "bad.json"), classes());
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(problem(R"({"parts": [{"class": "gear"}]})"), "scene 'bad.json': unknown object class 'gear'");
  EXPECT_EQ(problem(R"({"parts": [{"class": "node", "region": "moon"}]})"), "scene 'bad.json': unknown region 'moon'");
  EXPECT_NE(problem(R"({"parts": [{"class": "node", "count": 60, "region": "right"}]})").find("cannot fit"),
            std::string::npos);
  EXPECT_NE(problem(R"({"parts": [{"class": "node", "color": "purple"}]})").find("no colour 'purple'"),
            std::string::npos);
  EXPECT_NE(problem(R"({"parts": 3})").find("scene 'bad.json'"), std::string::npos);
  EXPECT_THROW(loadScene("/nonexistent.json"), std::runtime_error);
}

TEST(Scene, TheSceneFilesInTheRepositoryLoad) {
  for (const char* name : {"one_node", "assembly", "clutter"}) {
    const Scene scene = loadScene(dataRoot() / "sim/scenes" / (std::string(name) + ".json"));
    EXPECT_FALSE(placeParts(scene, classes()).empty()) << name;
  }
}

}  // namespace
}  // namespace costar::sim
