// Training examples: one per object by Euclidean clustering, saved and loaded.

#include "perception/training_data.h"

#include <gtest/gtest.h>

#include "perception/test/synthetic_scene.h"

namespace costar::perception {
namespace {

/// Three 5 cm blocks on the table, at y -0.2, 0.2 and 0: a synthetic frame.
camera::RgbdFrame threeBlocks() {
  world::ObjectClass block;
  block.boxes = {{Eigen::Vector3d::Zero(), Eigen::Vector3d(0.025, 0.025, 0.025)}};
  return test::renderSynthetic({{&block, world::Pose(Eigen::Translation3d(0.4, -0.2, 0.025))},
                                {&block, world::Pose(Eigen::Translation3d(0.6, 0.2, 0.025))},
                                {&block, world::Pose(Eigen::Translation3d(0.5, 0.0, 0.025))}},
                               0.0005);
}

TEST(TrainingData, EachObjectOnTheTableIsOneExample) {
  const camera::RgbdFrame frame = threeBlocks();
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

// Point-by-point labels (the simulator's truth in collection): each voxel takes its points'
// majority label; points labelled -1 (near a boundary) give no example.
TEST(TrainingData, LabelledExamplesTakeTheirPointsLabelsAndSkipTheUnlearned) {
  const camera::RgbdFrame frame = threeBlocks();
  TrainingSet set;
  set.names = {{0, "background"}, {1, "left"}, {2, "right"}};
  const auto label_of = [](const Eigen::Vector3d& point) {
    return point.y() < -0.1 ? 1 : (point.y() > 0.1 ? 2 : -1);  // the middle block is not learned from
  };
  const ExamplesAdded added = addLabelledExamples(frame, PipelineOptions{}, label_of, set);
  EXPECT_EQ(added.examples, 2);  // labels 1 and 2
  EXPECT_EQ(static_cast<int>(set.labels.size()), added.voxels);
  EXPECT_EQ(set.features.rows(), static_cast<Eigen::Index>(set.labels.size()));
  const auto ones = std::count(set.labels.begin(), set.labels.end(), 1);
  const auto twos = std::count(set.labels.begin(), set.labels.end(), 2);
  EXPECT_GT(ones, 20);
  EXPECT_GT(twos, 20);
  EXPECT_EQ(ones + twos, static_cast<long>(set.labels.size()));  // nothing of the middle block, no -1

  // Every point labelled the same: as many rows as the three blocks' voxels, one example.
  TrainingSet all;
  const ExamplesAdded every = addLabelledExamples(
      frame, PipelineOptions{}, [](const Eigen::Vector3d&) { return 0; }, all);
  EXPECT_EQ(every.examples, 1);
  EXPECT_GT(every.voxels, static_cast<int>(ones + twos));
}

}  // namespace
}  // namespace costar::perception
