// The general serial-chain solver (arm/chain_kinematics.h) held against the closed forms: its
// forward kinematics against the UR5's (a chain built here from UR's published DH table) and
// the iiwa's (the chain read from robots/iiwa14/iiwa14.json), and its inverse kinematics on
// random reachable poses from random seeds.

#include "arm/chain_kinematics.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>

#include "arm/robot_description.h"
#include "arm/srs_kinematics.h"
#include "arm/test/dh_chain.h"
#include "arm/test/published_arms.h"
#include "arm/ur5_kinematics.h"

namespace costar::arm {
namespace {

using testing::chainFromDh;

JointVector randomWithin(const JointLimits& limits, std::mt19937_64& random) {
  JointVector q(limits.size());
  for (int j = 0; j < q.size(); ++j) {
    q[j] = std::uniform_real_distribution<double>(limits.min_position[j], limits.max_position[j])(random);
  }
  return q;
}

bool within(const JointVector& q, const JointLimits& limits) {
  for (int j = 0; j < q.size(); ++j) {
    if (q[j] < limits.min_position[j] || q[j] > limits.max_position[j]) {
      return false;
    }
  }
  return true;
}

const RobotDescription& iiwa() {
  static const RobotDescription robot = loadRobotDescription(COSTAR_IIWA14_DESCRIPTION);
  return robot;
}

TEST(ChainKinematics, ForwardMatchesTheUr5ClosedFormOnAThousandConfigurations) {
  const Ur5Kinematics closed(published::ur5Dh(), published::ur5Limits());
  const ChainKinematics chain(chainFromDh(published::ur5Dh()), published::ur5Limits());
  std::mt19937_64 random(3501);
  for (int k = 0; k < 1000; ++k) {
    const JointVector q = randomWithin(published::ur5Limits(), random);
    const world::Pose a = closed.forward(q);
    const world::Pose b = chain.forward(q);
    ASSERT_LT((a.translation() - b.translation()).norm(), 1e-12) << k;
    ASSERT_LT(world::rotationAngle(a, b), 1e-9) << k;
  }
}

TEST(ChainKinematics, ForwardFromTheIiwaDescriptionMatchesTheSrsClosedForm) {
  const std::shared_ptr<const Kinematics> closed = makeKinematics(iiwa());
  const ChainKinematics chain(readChainGeometry(iiwa().file), iiwa().limits);
  std::mt19937_64 random(3502);
  for (int k = 0; k < 1000; ++k) {
    const JointVector q = randomWithin(iiwa().limits, random);
    const world::Pose a = closed->forward(q);
    const world::Pose b = chain.forward(q);
    ASSERT_LT((a.translation() - b.translation()).norm(), 1e-12) << k;
    ASSERT_LT(world::rotationAngle(a, b), 1e-9) << k;
  }
}

// The issue's target: >= 99.5 % of reachable poses solved from random seeds (`at_least` of
// 1000), every answer within the limits and on the pose.
void expectSolvesReachablePoses(const Kinematics& kinematics, std::uint64_t seed, int at_least) {
  std::mt19937_64 random(seed);
  constexpr int kPoses = 1000;
  int solved = 0;
  for (int k = 0; k < kPoses; ++k) {
    const world::Pose target = kinematics.forward(randomWithin(kinematics.limits(), random));
    const JointVector start = randomWithin(kinematics.limits(), random);
    const std::optional<JointVector> q = kinematics.inverseNearest(target, start);
    if (!q) {
      continue;
    }
    ASSERT_TRUE(within(*q, kinematics.limits())) << k;
    const world::Pose reached = kinematics.forward(*q);
    ASSERT_LT((reached.translation() - target.translation()).norm(), 1e-6) << k;
    ASSERT_LT(world::rotationAngle(reached, target), 1e-6) << k;
    ++solved;
  }
  EXPECT_GE(solved, at_least) << "of " << kPoses;
}

TEST(ChainKinematics, SolvesReachableIiwaPosesFromRandomSeeds) {
  expectSolvesReachablePoses(ChainKinematics(readChainGeometry(iiwa().file), iiwa().limits), 3503, 995);
}

// The Panda, whose solver this is (robots/panda/panda.json names "chain").
TEST(ChainKinematics, SolvesReachablePandaPosesFromRandomSeeds) {
  const RobotDescription panda = loadRobotDescription(COSTAR_PANDA_DESCRIPTION);
  const std::shared_ptr<const Kinematics> kinematics = makeKinematics(panda);
  ASSERT_NE(dynamic_cast<const ChainKinematics*>(kinematics.get()), nullptr);
  expectSolvesReachablePoses(*kinematics, 3506, 995);
}

// The UR5 keeps its closed form; here the general solver is only cross-checked on it. Its misses
// (6 of 1000 on this seed) are folded-elbow poses, joint 3 within 0.25 rad of +/-pi, where the
// elbow is singular.
TEST(ChainKinematics, SolvesReachableUr5PosesFromRandomSeeds) {
  expectSolvesReachablePoses(ChainKinematics(chainFromDh(published::ur5Dh()), published::ur5Limits()), 3504, 990);
}

// A Cartesian move's call: the seed within 0.05 rad per joint of a configuration, the answer the
// configuration itself (within 0.1 rad; the redundant arm could slide along its self-motion).
// On this seed 1 of 200 is not: joint 4 at -0.11 rad (the elbow stretched, singular) and joint 6
// at its limit, where the seed's own descent fails and a restart's answer is 0.9 rad away.
TEST(ChainKinematics, ASeedNearTheAnswerGivesTheAnswerNearIt) {
  const ChainKinematics chain(readChainGeometry(iiwa().file), iiwa().limits);
  std::mt19937_64 random(3505);
  int near = 0;
  for (int k = 0; k < 200; ++k) {
    const JointVector q = randomWithin(iiwa().limits, random);
    JointVector seed = q;
    for (int j = 0; j < seed.size(); ++j) {
      seed[j] = std::clamp(seed[j] + std::uniform_real_distribution<double>(-0.05, 0.05)(random),
                           iiwa().limits.min_position[j], iiwa().limits.max_position[j]);
    }
    const std::optional<JointVector> answer = chain.inverseNearest(chain.forward(q), seed);
    ASSERT_TRUE(answer) << k;
    near += maxAbsDifference(*answer, q) < 0.1;
  }
  EXPECT_GE(near, 199);
}

TEST(ChainKinematics, AnswersAreReproducibleAndUnreachablePosesHaveNone) {
  const ChainKinematics chain(readChainGeometry(iiwa().file), iiwa().limits);
  const JointVector home = iiwa().home;
  world::Pose target = chain.forward(JointVector{0.4, 0.5, -0.3, -1.2, 0.2, 0.8, 0.1});
  IkSolutions first;
  IkSolutions second;
  chain.inverse(target, home, first);
  chain.inverse(target, home, second);
  ASSERT_FALSE(first.empty());
  ASSERT_EQ(first.size(), second.size());
  for (int s = 0; s < first.size(); ++s) {
    EXPECT_EQ(maxAbsDifference(first[s], second[s]), 0.0);
  }
  EXPECT_THROW(chain.inverseNearest(target, JointVector::zero(6)), std::invalid_argument);
  target.translation() = Eigen::Vector3d(2.0, 0.0, 0.5);  // 2 m away: beyond the 1.3 m reach
  chain.inverse(target, home, first);
  EXPECT_TRUE(first.empty());
  EXPECT_FALSE(chain.inverseNearest(target, home));
}

TEST(ChainKinematics, AnAcceptablePredicateRefusingTheSeedsAnswerGetsAnotherBranch) {
  const ChainKinematics chain(readChainGeometry(iiwa().file), iiwa().limits);
  const JointVector q{0.4, 0.5, -0.3, -1.2, 0.2, 0.8, 0.1};
  const world::Pose target = chain.forward(q);
  // Refuse every configuration with the elbow (joint 4) bent the way the seed's is.
  const std::optional<JointVector> other =
      chain.inverseNearest(target, q, [](const JointVector& candidate) { return candidate[3] > 0.0; });
  ASSERT_TRUE(other);
  EXPECT_GT((*other)[3], 0.0);
  EXPECT_LT((chain.forward(*other).translation() - target.translation()).norm(), 1e-6);
}

TEST(ChainGeometryFile, ABadAxisOrAMissingOriginIsRefusedNamingTheField) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "chain_kinematics_test";
  std::filesystem::create_directories(dir);
  const auto refused = [&dir](const std::string& text) {
    const std::filesystem::path file = dir / "robot.json";
    std::ofstream(file) << text;
    try {
      readChainGeometry(file);
    } catch (const std::runtime_error& error) {
      return std::string(error.what());
    }
    return std::string("accepted");
  };
  EXPECT_NE(refused(R"({"joints": [{"origin": [0,0,0.1], "axis": [0,0,2]}], "tool": {"origin": [0,0,0]}})")
                .find("joints[0].axis: must be a unit vector"),
            std::string::npos);
  EXPECT_NE(
      refused(R"({"joints": [{"axis": [0,0,1]}], "tool": {"origin": [0,0,0]}})").find("joints[0].origin: missing"),
      std::string::npos);
  EXPECT_NE(refused(R"({"joints": [{"origin": [0,0,0.1], "axis": [0,0,1]}]})").find("tool: missing"),
            std::string::npos);
  EXPECT_NE(refused(R"({"joints": []})").find("joints: must be a list of 1 to 8 joints"), std::string::npos);
  EXPECT_EQ(refused(R"({"joints": [{"origin": [0,0,0.1], "rpy": [0,1.5707963,0], "axis": [0,0,1]}],
                        "tool": {"origin": [0,0,0.05]}})"),
            "accepted");
}

}  // namespace
}  // namespace costar::arm
