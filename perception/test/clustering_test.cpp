// Euclidean clustering (PCL) and the organized variant of the pipeline.

#include "perception/clustering.h"

#include <gtest/gtest.h>

namespace costar::perception {
namespace {

TEST(Clustering, SplitsGroupsFartherApartThanTheTolerance) {
  std::vector<Eigen::Vector3f> points;
  for (int i = 0; i < 30; ++i) {
    points.emplace_back(0.004f * i, 0, 1);         // a line of 30 points, 4 mm apart
    points.emplace_back(0.5f + 0.004f * i, 0, 1);  // another, 38 cm away
  }
  points.emplace_back(1.5f, 0, 1);  // a lone point
  const auto clusters = euclideanClusters(points, 0.01, 2);
  ASSERT_EQ(clusters.size(), 2u);
  EXPECT_EQ(clusters[0].size(), 30u);
  EXPECT_EQ(clusters[0].front(), 0);  // ordered by first index
  EXPECT_EQ(clusters[1].front(), 1);
  EXPECT_EQ(euclideanClusters(points, 0.01, 1).size(), 3u);
  EXPECT_TRUE(euclideanClusters({}, 0.01).empty());
}

TEST(Clustering, OrganizedClustersFollowPixelsAndDistance) {
  // A 10 x 10 image: left half at 1 m, right half at 1.2 m (a depth step: two groups).
  std::vector<Eigen::Vector3f> points;
  std::vector<int> pixels;
  for (int v = 0; v < 10; ++v) {
    for (int u = 0; u < 10; ++u) {
      const float z = u < 5 ? 1.0f : 1.2f;
      points.emplace_back(0.002f * u, 0.002f * v, z);
      pixels.push_back(v * 10 + u);
    }
  }
  const auto clusters = organizedClusters(points, pixels, 10, 10, 0.01, 2, 1);
  ASSERT_EQ(clusters.size(), 2u);
  EXPECT_EQ(clusters[0].size(), 50u);
  EXPECT_EQ(clusters[1].size(), 50u);
  // A gap of two missing columns is bridged by a window of 2 pixels, not by 1.
  std::vector<Eigen::Vector3f> gap_points;
  std::vector<int> gap_pixels;
  for (int u : {0, 1, 2, 5, 6}) {
    gap_points.emplace_back(0.002f * u, 0, 1.0f);
    gap_pixels.push_back(u);
  }
  EXPECT_EQ(organizedClusters(gap_points, gap_pixels, 10, 1, 0.01, 2, 1).size(), 2u);
  EXPECT_EQ(organizedClusters(gap_points, gap_pixels, 10, 1, 0.01, 3, 1).size(), 1u);
}

}  // namespace
}  // namespace costar::perception
