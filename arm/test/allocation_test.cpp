// The hot paths allocate nothing: the array overload of the inverse kinematics,
// nearestWithin(), the Kinematics interface's inverse(), solutionsNear() and inverseNearest(),
// and sampling a trajectory. Counted, not timed.

#include <gtest/gtest.h>

#include <random>

#include "arm/chain_kinematics.h"
#include "arm/test/dh_chain.h"
#include "arm/test/published_arms.h"
#include "arm/trajectory.h"
#include "arm/ur5_kinematics.h"
#include "bench/alloc_counter.h"

namespace costar::arm {
namespace {

/// The UR5's joints.
constexpr int kJointCount = arm::Ur5Kinematics::kJointCount;

TEST(ArmAllocation, NoneInInverseKinematics) {
  const Ur5Kinematics kinematics(published::ur5Dh(), published::ur5Limits());
  std::mt19937_64 random(21);
  std::uniform_real_distribution<double> angle(-3.0, 3.0);
  std::vector<world::Pose> poses;
  for (int k = 0; k < 100; ++k) {
    JointVector q = JointVector::zero(kJointCount);
    for (double& value : q) {
      value = angle(random);
    }
    poses.push_back(kinematics.forward(q));
  }
  std::array<JointVector, Ur5Kinematics::kMaxSolutions> solutions;
  int total = 0;
  const JointLimits limits = published::ur5Limits();
  const std::uint64_t before = bench::allocations();
  for (const world::Pose& pose : poses) {
    total += kinematics.inverse(pose, solutions);
    total += kinematics.nearestWithin(pose, JointVector::zero(kJointCount), &limits).has_value();
  }
  EXPECT_EQ(bench::allocations() - before, 0u);
  EXPECT_GT(total, 100);
  // Through the interface, as the arm component and SmartMove call it.
  const Kinematics& generic = kinematics;
  IkSolutions found;
  const JointVector seed = {0.1, -1.5, 1.5, -1.5, -1.5, 0.0};
  const std::uint64_t before_generic = bench::allocations();
  for (const world::Pose& pose : poses) {
    generic.inverse(pose, seed, found);
    generic.solutionsNear(pose, seed, found);
    total += found.size();
    total += generic.inverseNearest(pose, seed).has_value();
  }
  EXPECT_EQ(bench::allocations() - before_generic, 0u);
}

// The general chain solver (6 joints here: the UR5's DH table as a chain), through the
// interface; its geometry is built before counting.
TEST(ArmAllocation, NoneInTheChainSolver) {
  const ChainKinematics kinematics(testing::chainFromDh(published::ur5Dh()), published::ur5Limits());
  std::mt19937_64 random(22);
  std::uniform_real_distribution<double> angle(-3.0, 3.0);
  std::vector<world::Pose> poses;
  for (int k = 0; k < 50; ++k) {
    JointVector q = JointVector::zero(kJointCount);
    for (double& value : q) {
      value = angle(random);
    }
    poses.push_back(kinematics.forward(q));
  }
  const Kinematics& generic = kinematics;
  IkSolutions found;
  const JointVector seed = {0.1, -1.5, 1.5, -1.5, -1.5, 0.0};
  int total = 0;
  const std::uint64_t before = bench::allocations();
  for (const world::Pose& pose : poses) {
    generic.inverse(pose, seed, found);
    total += found.size();
    total += generic.inverseNearest(pose, seed).has_value();
  }
  EXPECT_EQ(bench::allocations() - before, 0u);
  EXPECT_GT(total, 50);
}

TEST(ArmAllocation, NoneWhenSampling) {
  const JointTrajectory trajectory = JointTrajectory::alongPath(
      {{0, 0, 0, 0, 0, 0}, {1, 0.5, 0, 0, 0, 0}, {1, 1, 1, 0, 0, 0}}, published::ur5Limits(), 0.8);
  double sum = 0.0;
  const std::uint64_t before = bench::allocations();
  for (Duration t(0); t <= trajectory.duration(); t += std::chrono::microseconds(100)) {
    sum += trajectory.sample(t).position[0];
  }
  EXPECT_EQ(bench::allocations() - before, 0u);
  EXPECT_GT(sum, 0.0);
}

}  // namespace
}  // namespace costar::arm
