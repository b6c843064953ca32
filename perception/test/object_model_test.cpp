// Object models generated from the class boxes; per-class parameters from data.

#include "perception/object_model.h"

#include <gtest/gtest.h>

#include <fstream>
#include <random>

#include "core/paths.h"

namespace costar::perception {
namespace {

bool insideAny(const std::vector<world::Box>& boxes, const Eigen::Vector3d& p) {
  for (const auto& box : boxes) {
    if (((p - box.center).cwiseAbs() - box.half_size).maxCoeff() < 0) {
      return true;
    }
  }
  return false;
}

TEST(ObjectModel, SamplesEveryFaceOfABoxWithOutwardNormals) {
  const std::vector<world::Box> box = {{Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0.075, 0.0125, 0.0125)}};
  const Cloud surface = sampleOuterSurface(box, 0.0025);
  // 2 x (60 x 10) + 2 x (60 x 10) + 2 x (10 x 10) samples.
  EXPECT_EQ(surface.size(), 2u * 600 + 2u * 600 + 2u * 100);
  for (std::size_t i = 0; i < surface.size(); ++i) {
    EXPECT_FLOAT_EQ(surface.normals[i].norm(), 1.0f);
    EXPECT_GT(surface.points[i].dot(surface.normals[i]), 0.0f);  // outward from the centre
  }
}

TEST(ObjectModel, KeepsOnlyTheOuterSurfaceOfAUnionOfBoxes) {
  const auto classes = world::loadObjectClasses(dataRoot() / "data/objects");
  const world::ObjectClass& node = classes.at(1).name == "node" ? classes.at(1) : classes.at(0);
  ASSERT_EQ(node.name, "node");
  const Cloud surface = sampleOuterSurface(node.boxes, 0.002);
  ASSERT_GT(surface.size(), 3000u);
  for (std::size_t i = 0; i < surface.size(); ++i) {
    const Eigen::Vector3d p = surface.points[i].cast<double>();
    const Eigen::Vector3d n = surface.normals[i].cast<double>();
    EXPECT_FALSE(insideAny(node.boxes, p + 0.0005 * n)) << "sample " << i << " is inside the part";
    EXPECT_TRUE(insideAny(node.boxes, p - 0.0005 * n)) << "sample " << i << " is not on the part";
  }
  // The sockets: samples on the floor of the +z socket (z = 0.015), none on the hidden top of
  // the plate under the rim.
  int socket_floor = 0;
  for (const auto& p : surface.points) {
    socket_floor += std::abs(p.z() - 0.015f) < 1e-6f && std::abs(p.x()) < 0.0095f && std::abs(p.y()) < 0.0095f;
  }
  EXPECT_GT(socket_floor, 50);
}

TEST(ObjectModel, TheGridGivesTheNearestSurfaceSample) {
  const std::vector<world::Box> box = {{Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0.025, 0.025, 0.025)}};
  const Cloud surface = sampleOuterSurface(box, 0.002);
  const SurfaceGrid grid = buildSurfaceGrid(surface, 0.002f, 0.02f);
  std::mt19937 random(1);
  std::uniform_real_distribution<float> coordinate(-0.04f, 0.04f);
  for (int trial = 0; trial < 300; ++trial) {
    const Eigen::Vector3f q(coordinate(random), coordinate(random), coordinate(random));
    const int found = grid.lookup(q);
    ASSERT_GE(found, 0);
    float best = std::numeric_limits<float>::max();
    for (const auto& p : surface.points) {
      best = std::min(best, (p - q).norm());
    }
    // The nearest to the cell's centre: within a cell diagonal of the true nearest.
    EXPECT_LE((surface.points[static_cast<std::size_t>(found)] - q).norm(), best + 0.0035f);
  }
  EXPECT_EQ(grid.lookup(Eigen::Vector3f(0.2f, 0, 0)), -1);
}

TEST(ObjectModel, LoadsTheClassesWithTheirParameters) {
  const auto models = loadObjectModels(dataRoot() / "data/objects", dataRoot() / "data/perception/classes.json");
  ASSERT_EQ(models.size(), 2u);
  EXPECT_EQ(models[0].name(), "link");
  EXPECT_EQ(models[1].name(), "node");
  EXPECT_EQ(models[1].parameters.svm_label, 1);
  EXPECT_EQ(models[0].parameters.svm_label, 2);
  EXPECT_DOUBLE_EQ(models[1].parameters.pair_width, 0.035);
  EXPECT_NEAR(models[1].radius, std::sqrt(3.0) * 0.025, 0.002);
  EXPECT_FALSE(models[0].interior.empty());
}

TEST(ObjectModel, ParameterFilesAreChecked) {
  const auto dir = std::filesystem::temp_directory_path() / "costar_classes_test";
  std::filesystem::create_directories(dir);
  const auto write = [&](const std::string& text) {
    std::ofstream(dir / "classes.json") << text;
    return dir / "classes.json";
  };
  const auto objects = dataRoot() / "data/objects";
  EXPECT_THROW(loadObjectModels(objects, write(R"({"classes": {"node": {"svm_label": 1}, "link": {"svm_label": 1}}})")),
               std::runtime_error);
  EXPECT_THROW(loadObjectModels(objects, write(R"({"classes": {"gear": {"svm_label": 3}}})")), std::runtime_error);
  EXPECT_THROW(loadObjectModels(objects, write(R"({"defaults": {"voxel_size": -1}})")), std::runtime_error);
  // A class without an entry gets defaults and the next free label.
  const auto models = loadObjectModels(objects, write(R"({"classes": {"node": {"svm_label": 1}}})"));
  EXPECT_EQ(models[0].parameters.svm_label, 2);
  EXPECT_NEAR(models[0].parameters.pair_width, 0.02, 1e-9);  // 0.7 x 2.5 cm, at least 2 cm
  EXPECT_THROW(loadObjectModels(objects, dir / "missing.json"), std::runtime_error);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace costar::perception
