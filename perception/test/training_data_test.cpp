// Training examples: one per object by Euclidean clustering, saved and loaded.

#include "perception/training_data.h"

#include <gtest/gtest.h>

#include "perception/test/synthetic_scene.h"

namespace costar::perception {
namespace {

TEST(TrainingData, EachObjectOnTheTableIsOneExample) {
  world::ObjectClass block;
  block.boxes = {{Eigen::Vector3d::Zero(), Eigen::Vector3d(0.025, 0.025, 0.025)}};
  const camera::RgbdFrame frame = test::renderSynthetic({{&block, world::Pose(Eigen::Translation3d(0.4, -0.2, 0.025))},
                                                         {&block, world::Pose(Eigen::Translation3d(0.6, 0.2, 0.025))},
                                                         {&block, world::Pose(Eigen::Translation3d(0.5, 0.0, 0.025))}},
                                                        0.0005);
  TrainingSet set;
  set.names = {{0, "background"}, {1, "block"}};
  const ExamplesAdded added = addTrainingExamples(frame, PipelineOptions{}, 1, /*add_table=*/true, set);
  EXPECT_EQ(added.examples, 4);  // three blocks and the table
  EXPECT_EQ(static_cast<int>(set.labels.size()), added.voxels);
  EXPECT_EQ(set.features.rows(), static_cast<Eigen::Index>(set.labels.size()));
  EXPECT_GT(std::count(set.labels.begin(), set.labels.end(), 1), 60);
  EXPECT_GT(std::count(set.labels.begin(), set.labels.end(), 0), 10);

  const auto folder = std::filesystem::temp_directory_path() / "costar_training_data_test";
  saveTrainingSet(set, folder);
  const TrainingSet loaded = loadTrainingSet(folder);
  std::filesystem::remove_all(folder);
  EXPECT_EQ(loaded.labels, set.labels);
  EXPECT_EQ(loaded.names, set.names);
  EXPECT_TRUE(loaded.features.isApprox(set.features));
  EXPECT_THROW(loadTrainingSet(folder), std::runtime_error);
}

}  // namespace
}  // namespace costar::perception
