// The node-free vote of transform_votes.h against PCL's own RigidTransformSpace: the same
// occupied cells in the same order, the same centres and the same averaged transforms, bit for
// bit, on hypotheses clustered as ObjRecRANSAC's are (many near a few poses, so that rotation
// cells and their neighbours share votes) and scattered.
#include <gtest/gtest.h>
#include <pcl/recognition/ransac_based/rigid_transform_space.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <random>
#include <vector>

#include "perception/transform_votes.h"

namespace costar::perception {
namespace {

struct Vote {
  float position[3];
  float transform[12];
};

std::vector<Vote> clusteredVotes(std::uint32_t seed, int count) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  std::normal_distribution<float> jitter(0.0f, 1.0f);
  // A few true poses; each vote is one of them disturbed by a few millimetres and degrees (as
  // the pairs of one instance vote), or anywhere (pairs that match by chance).
  std::vector<Eigen::Isometry3f> poses;
  for (int i = 0; i < 4; ++i) {
    Eigen::Isometry3f pose = Eigen::Isometry3f::Identity();
    pose.linear() = Eigen::Quaternionf::UnitRandom().toRotationMatrix();
    pose.translation() = Eigen::Vector3f(0.05f * unit(random), 0.05f * unit(random), 0.6f + 0.05f * unit(random));
    poses.push_back(pose);
  }
  std::vector<Vote> votes;
  for (int i = 0; i < count; ++i) {
    Eigen::Isometry3f pose = Eigen::Isometry3f::Identity();
    if (i % 5 == 4) {
      pose.linear() = Eigen::Quaternionf::UnitRandom().toRotationMatrix();
      pose.translation() = Eigen::Vector3f(0.1f * unit(random), 0.1f * unit(random), 0.6f + 0.1f * unit(random));
    } else {
      pose = poses[static_cast<std::size_t>(i % 4)];
      const Eigen::Vector3f axis(jitter(random), jitter(random), jitter(random));
      pose.linear() =
          Eigen::AngleAxisf(0.08f * std::abs(jitter(random)), axis.normalized()).toRotationMatrix() * pose.linear();
      pose.translation() += 0.004f * Eigen::Vector3f(jitter(random), jitter(random), jitter(random));
    }
    Vote vote{};
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) {
        vote.transform[3 * r + c] = pose.linear()(r, c);
      }
      vote.transform[9 + r] = pose.translation()[r];
      vote.position[r] = pose.translation()[r];
    }
    votes.push_back(vote);
  }
  return votes;
}

TEST(TransformVotes, AreTheSameAsPclsRigidTransformSpace) {
  const float bounds[6] = {-0.15f, 0.15f, -0.15f, 0.15f, 0.45f, 0.75f};
  TransformVotes ours;  // one, built again for each case: what it remembers must not change a vote
  for (const float position_cell : {0.02f, 0.03f}) {
    for (const std::uint32_t seed : {1u, 2u, 3u}) {
      const std::vector<Vote> votes = clusteredVotes(seed, 3000);
      const float rotation_cell = 5.0f * AUX_DEG_TO_RADIANS;
      pcl::recognition::RigidTransformSpace pcl_space;
      pcl_space.build(bounds, position_cell, rotation_cell);
      ours.build(bounds, position_cell, rotation_cell);
      pcl::recognition::ModelLibrary::Model* model = nullptr;  // one model: only its address is used
      for (const Vote& vote : votes) {
        ASSERT_TRUE(pcl_space.addRigidTransform(model, vote.position, vote.transform));
        ours.add(vote.position, vote.transform);
      }
      const std::vector<TransformVotes::Winner> winners = ours.winners();
      const auto& spaces = pcl_space.getRotationSpaces();
      ASSERT_EQ(winners.size(), spaces.size());
      ASSERT_GT(winners.size(), 4u);
      std::size_t i = 0;
      int shared = 0;  // cells whose winner averaged several votes
      for (const pcl::recognition::RotationSpace* space : spaces) {
        float expected[12];
        ASSERT_TRUE(space->getTransformWithMostVotes(model, expected));
        for (int k = 0; k < 3; ++k) {
          EXPECT_EQ(winners[i].centre[static_cast<std::size_t>(k)], space->getCenter()[k]) << "cell " << i;
        }
        for (int k = 0; k < 12; ++k) {
          EXPECT_EQ(winners[i].rigid_transform[static_cast<std::size_t>(k)], expected[k]) << "cell " << i << ", " << k;
        }
        const bool one_vote = std::any_of(votes.begin(), votes.end(), [&](const Vote& vote) {
          return vote.transform[9] == winners[i].rigid_transform[9] &&
                 vote.transform[10] == winners[i].rigid_transform[10];
        });
        shared += one_vote ? 0 : 1;
        ++i;
      }
      EXPECT_GT(shared, 0);
    }
  }
}

TEST(TransformVotes, DropsPositionsOutsideItsBounds) {
  const float bounds[6] = {0.0f, 0.1f, 0.0f, 0.1f, 0.0f, 0.1f};
  TransformVotes votes;
  votes.build(bounds, 0.01f, 5.0f * AUX_DEG_TO_RADIANS);
  const float identity[12] = {1, 0, 0, 0, 1, 0, 0, 0, 1, 0.05f, 0.05f, 0.05f};
  const float outside[3] = {0.5f, 0.05f, 0.05f};
  const float inside[3] = {0.05f, 0.05f, 0.05f};
  votes.add(outside, identity);
  EXPECT_TRUE(votes.winners().empty());
  votes.add(inside, identity);
  votes.add(inside, identity);
  const auto winners = votes.winners();
  ASSERT_EQ(winners.size(), 1u);
  EXPECT_FLOAT_EQ(winners[0].rigid_transform[0], 1.0f);
  EXPECT_FLOAT_EQ(winners[0].rigid_transform[9], 0.05f);
}

}  // namespace
}  // namespace costar::perception
