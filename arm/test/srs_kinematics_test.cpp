// The LBR iiwa 14's analytic kinematics: against its description file, against KDL on the URDF
// generated from that file, and the inverse against the forward on random poses (fixed seeds).

#include "arm/srs_kinematics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <numbers>
#include <random>

#include "arm/robot_description.h"
#include "arm/test/published_arms.h"
#include "planning/robot_model.h"

namespace costar::arm {
namespace {

constexpr double kDegree = std::numbers::pi / 180.0;

Joints7 degrees(std::initializer_list<double> values) {
  Joints7 q;
  int i = 0;
  for (double value : values) {
    q[i++] = value * kDegree;
  }
  return q;
}

/// Uniform within the limits shrunk by `margin` radians.
Joints7 randomWithin(const SrsLimits& limits, std::mt19937_64& random, double margin = 0.0) {
  Joints7 q;
  for (int i = 0; i < 7; ++i) {
    q[i] = std::uniform_real_distribution<double>(limits.lower[i] + margin, limits.upper[i] - margin)(random);
  }
  return q;
}

double positionError(const world::Pose& a, const world::Pose& b) { return (a.translation() - b.translation()).norm(); }

void expectSamePose(const world::Pose& actual, const world::Pose& expected, double tolerance) {
  EXPECT_LT(positionError(actual, expected), tolerance);
  EXPECT_LT(world::rotationAngle(actual, expected), tolerance);
}

// ---------------------------------------------------------------------------------------------
// The description file and the generated URDF

TEST(SrsDescription, FileMatchesTheBuiltInIiwa14) {
  const SrsArmDescription description = readSrsArmDescription(COSTAR_IIWA14_DESCRIPTION);
  const SrsGeometry expected = published::iiwa14Geometry();
  EXPECT_EQ(description.name, "iiwa14");
  EXPECT_EQ(description.base_link, "iiwa_link_0");
  EXPECT_EQ(description.tool_frame, "tool0");
  EXPECT_EQ(description.joint_names[0], "iiwa_joint_1");
  EXPECT_EQ(description.joint_names[6], "iiwa_joint_7");
  EXPECT_NEAR(description.geometry.base_to_shoulder, 0.360, 1e-12);
  EXPECT_NEAR(description.geometry.shoulder_to_elbow, 0.420, 1e-12);
  EXPECT_NEAR(description.geometry.elbow_to_wrist, 0.400, 1e-12);
  EXPECT_TRUE(description.geometry.wrist_to_flange.isApprox(expected.wrist_to_flange, 1e-12));
  EXPECT_EQ(description.geometry.axis_sign, expected.axis_sign);
  EXPECT_TRUE(description.limits.lower.isApprox(published::iiwa14Limits().lower, 1e-12));
  EXPECT_TRUE(description.limits.upper.isApprox(published::iiwa14Limits().upper, 1e-12));
  EXPECT_TRUE(description.max_velocity.isApprox(degrees({85, 85, 100, 75, 130, 135, 135}), 1e-12));
  EXPECT_TRUE(description.home.isApprox(degrees({0, 6, 0, -108, 0, 66, -90}), 1e-12));
}

class SrsDescriptionErrors : public ::testing::Test {
 protected:
  /// The iiwa's description with `from` replaced by `to`, written to a temporary file.
  std::filesystem::path variant(const std::string& from, const std::string& to) {
    std::ifstream in(COSTAR_IIWA14_DESCRIPTION);
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::size_t at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    if (at != std::string::npos) {
      text.replace(at, from.size(), to);
    }
    path_ = std::filesystem::temp_directory_path() /
            ("srs_description_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "_" +
             ::testing::UnitTest::GetInstance()->current_test_info()->name() + ".json");
    std::ofstream(path_) << text;
    return path_;
  }
  void TearDown() override { std::filesystem::remove(path_); }
  std::filesystem::path path_;
};

TEST_F(SrsDescriptionErrors, NameTheFileAndTheField) {
  const auto expectError = [](const std::filesystem::path& file, const std::string& field) {
    try {
      readSrsArmDescription(file);
      ADD_FAILURE() << "no error for " << field;
    } catch (const std::runtime_error& error) {
      const std::string message = error.what();
      EXPECT_NE(message.find(file.string()), std::string::npos) << message;
      EXPECT_NE(message.find(field), std::string::npos) << message;
    }
  };
  expectError(variant("\"axis\": [0, -1, 0]", "\"axis\": [1, 0, 0]"), "joints[3].axis");
  expectError(variant("\"origin\": [0, 0, 0.2045]", "\"origin\": [0.01, 0, 0.2045]"), "joints[2].origin");
  expectError(variant("\"lower_deg\": -120, \"upper_deg\": 120, \"velocity_deg_s\": 75",
                      "\"lower_deg\": 120, \"upper_deg\": -120, \"velocity_deg_s\": 75"),
              "joints[3]");
  expectError(variant("\"home_deg\": [0, 6, 0, -108, 0, 66, -90]", "\"home_deg\": [0, 30, 0, -80, 0, 70]"), "home_deg");
  expectError(variant("\"home_deg\": [0, 6, 0, -108, 0, 66, -90]", "\"home_deg\": [0, 130, 0, -80, 0, 70, 0]"),
              "home_deg");
  expectError(variant("\"velocity_deg_s\": 85, \"acceleration_deg_s2\"",
                      "\"velocity_deg_s\": \"fast\", \"acceleration_deg_s2\""),
              "joints[0].velocity_deg_s");
  expectError(variant("\"tool\": {", "\"tool\": {} , \"x\": {"), "tool");
  expectError(variant("\"format\"", "\"format\" ]"), "not valid JSON");
  EXPECT_THROW(readSrsArmDescription("/nonexistent/robot.json"), std::runtime_error);
}

TEST(SrsKinematics, ForwardMatchesKdlOnTheGeneratedUrdf) {
  const planning::RobotModel model = planning::RobotModel::fromUrdf(COSTAR_IIWA14_URDF, "iiwa_link_0", "tool0");
  ASSERT_EQ(model.dof(), 7u);
  const SrsLimits limits = published::iiwa14Limits();
  EXPECT_TRUE(model.lowerLimits().isApprox(limits.lower, 1e-9));
  EXPECT_TRUE(model.upperLimits().isApprox(limits.upper, 1e-9));
  const SrsKinematics kinematics(published::iiwa14Geometry());
  std::mt19937_64 random(11);
  double worst_position = 0.0;
  double worst_angle = 0.0;
  for (int n = 0; n < 1000; ++n) {
    const Joints7 q = randomWithin(limits, random);
    const world::Pose analytic = kinematics.forward(q);
    const world::Pose kdl = model.forward(q);
    worst_position = std::max(worst_position, positionError(analytic, kdl));
    worst_angle = std::max(worst_angle, world::rotationAngle(analytic, kdl));
  }
  EXPECT_LT(worst_position, 1e-9);
  EXPECT_LT(worst_angle, 1e-9);
}

TEST(SrsKinematics, ForwardKnownConfigurations) {
  const SrsKinematics kinematics(published::iiwa14Geometry());
  // Straight up: the flange 0.36 + 0.42 + 0.40 + 0.126 m above the base, parallel to it.
  expectSamePose(kinematics.forward(Joints7::Zero()), world::Pose(Eigen::Translation3d(0, 0, 1.306)), 1e-12);
  // Joint 2 at +90 degrees lays the arm along +x (about +y).
  const world::Pose forward = kinematics.forward(degrees({0, 90, 0, 0, 0, 0, 0}));
  EXPECT_LT((forward.translation() - Eigen::Vector3d(0.946, 0, 0.36)).norm(), 1e-12);
  EXPECT_LT((forward.linear().col(2) - Eigen::Vector3d::UnitX()).norm(), 1e-12);
  // Joint 4 turns about -y: +90 degrees folds the forearm toward -x.
  const world::Pose folded = kinematics.forward(degrees({0, 0, 0, 90, 0, 0, 0}));
  EXPECT_LT((folded.translation() - Eigen::Vector3d(-0.526, 0, 0.78)).norm(), 1e-12);
}

// ---------------------------------------------------------------------------------------------
// Closed-form solutions at a given arm angle

TEST(SrsKinematics, EverySolutionAtAnArmAngleReproducesThePose) {
  const SrsKinematics kinematics(published::iiwa14Geometry());
  std::mt19937_64 random(12);
  std::uniform_real_distribution<double> angle(-std::numbers::pi, std::numbers::pi);
  std::array<Joints7, SrsKinematics::kMaxSolutions> solutions;
  int generic = 0;
  for (int n = 0; n < 2000; ++n) {
    Joints7 q;
    for (int i = 0; i < 7; ++i) {
      q[i] = angle(random);
    }
    const world::Pose pose = kinematics.forward(q);
    const double psi = angle(random);
    const int count = kinematics.inverse(pose, psi, solutions);
    generic += count == 8;
    ASSERT_GE(count, 4);
    for (int s = 0; s < count; ++s) {
      ASSERT_TRUE(solutions[s].allFinite());
      expectSamePose(kinematics.forward(solutions[s]), pose, 1e-9);
      EXPECT_NEAR(kinematics.armAngle(solutions[s]), psi, 1e-7) << "solution " << s;
    }
    // At its own arm angle, the generating configuration is one of the solutions.
    const int own = kinematics.inverse(pose, kinematics.armAngle(q), solutions);
    double nearest = 1e9;
    for (int s = 0; s < own; ++s) {
      Joints7 difference = solutions[s] - q;
      for (int i = 0; i < 7; ++i) {
        difference[i] = std::remainder(difference[i], 2.0 * std::numbers::pi);
      }
      nearest = std::min(nearest, difference.cwiseAbs().maxCoeff());
    }
    EXPECT_LT(nearest, 1e-7);
  }
  EXPECT_EQ(generic, 2000);
}

// ---------------------------------------------------------------------------------------------
// The nearest solution within limits

struct RoundTripStatistics {
  int poses = 0;
  int solved = 0;
  double worst_position = 0.0;
  double worst_angle = 0.0;
  int outside_limits = 0;
};

RoundTripStatistics roundTrip(std::uint64_t seed, int poses, bool random_seed_configuration) {
  const SrsKinematics kinematics(published::iiwa14Geometry());
  const SrsLimits limits = published::iiwa14Limits();
  const Joints7 home = degrees({0, 30, 0, -80, 0, 70, 0});
  std::mt19937_64 random(seed);
  RoundTripStatistics statistics;
  for (int n = 0; n < poses; ++n) {
    const world::Pose pose = kinematics.forward(randomWithin(limits, random));
    const Joints7 start = random_seed_configuration ? randomWithin(limits, random) : home;
    const std::optional<Joints7> q = kinematics.inverseNearest(pose, start, limits);
    ++statistics.poses;
    if (!q) {
      continue;
    }
    ++statistics.solved;
    const world::Pose reached = kinematics.forward(*q);
    statistics.worst_position = std::max(statistics.worst_position, positionError(reached, pose));
    statistics.worst_angle = std::max(statistics.worst_angle, world::rotationAngle(reached, pose));
    statistics.outside_limits += !limits.contains(*q);
  }
  return statistics;
}

void expectRoundTrip(const RoundTripStatistics& statistics, const char* what) {
  const double fraction = static_cast<double>(statistics.solved) / statistics.poses;
  std::cout << what << ": solved " << statistics.solved << " of " << statistics.poses << " (" << 100.0 * fraction
            << " %), worst error " << statistics.worst_position << " m, " << statistics.worst_angle << " rad\n";
  ::testing::Test::RecordProperty(std::string(what) + "_solved", statistics.solved);
  EXPECT_GE(fraction, 0.999);
  EXPECT_LT(statistics.worst_position, 1e-6);
  EXPECT_LT(statistics.worst_angle, 1e-6);
  EXPECT_EQ(statistics.outside_limits, 0);
}

TEST(SrsKinematics, RoundTripFromHomeOnTenThousandReachablePoses) {
  expectRoundTrip(roundTrip(2017, 10000, false), "from_home");
}

TEST(SrsKinematics, RoundTripFromRandomSeedsOnTenThousandReachablePoses) {
  expectRoundTrip(roundTrip(2008, 10000, true), "from_random_seeds");
}

TEST(SrsKinematics, NearestToASolutionIsThatSolution) {
  const SrsKinematics kinematics(published::iiwa14Geometry());
  const SrsLimits limits = published::iiwa14Limits();
  std::mt19937_64 random(13);
  for (int n = 0; n < 1000; ++n) {
    const Joints7 q = randomWithin(limits, random);
    const std::optional<Joints7> solution = kinematics.inverseNearest(kinematics.forward(q), q, limits);
    ASSERT_TRUE(solution.has_value());
    EXPECT_LT((*solution - q).cwiseAbs().maxCoeff(), 1e-7);
  }
}

TEST(SrsKinematics, SmallPoseChangeGivesSmallJointChange) {
  const SrsKinematics kinematics(published::iiwa14Geometry());
  const SrsLimits limits = published::iiwa14Limits();
  std::mt19937_64 random(14);
  std::normal_distribution<double> noise(0.0, 1.0);
  double worst = 0.0;
  int tried = 0;
  while (tried < 2000) {
    const Joints7 q = randomWithin(limits, random, 10 * kDegree);
    // Away from the shoulder, elbow and wrist singularities, where joint speeds are unbounded.
    if (std::abs(q[1]) < 15 * kDegree || std::abs(q[3]) < 15 * kDegree || std::abs(q[5]) < 15 * kDegree) {
      continue;
    }
    ++tried;
    // 1 mm and 0.1 degree.
    const Eigen::Vector3d shift(noise(random), noise(random), noise(random));
    const Eigen::Vector3d axis(noise(random), noise(random), noise(random));
    world::Pose moved = kinematics.forward(q);
    moved.translation() += 0.001 * shift.normalized();
    moved.linear() = Eigen::AngleAxisd(0.1 * kDegree, axis.normalized()).toRotationMatrix() * moved.linear();
    const std::optional<Joints7> solution = kinematics.inverseNearest(moved, q, limits);
    ASSERT_TRUE(solution.has_value());
    expectSamePose(kinematics.forward(*solution), moved, 1e-9);
    worst = std::max(worst, (*solution - q).cwiseAbs().maxCoeff());
  }
  std::cout << "largest joint change for 1 mm and 0.1 degree: " << worst / kDegree << " degrees\n";
  EXPECT_LT(worst, 3 * kDegree);
}

TEST(SrsKinematics, UnreachablePosesHaveNoSolution) {
  const SrsKinematics kinematics(published::iiwa14Geometry());
  const SrsLimits limits = published::iiwa14Limits();
  const Joints7 home = degrees({0, 30, 0, -80, 0, 70, 0});
  std::array<Joints7, SrsKinematics::kMaxSolutions> solutions;
  // Beyond reach: the wrist centre 0.82 m from the shoulder at most.
  for (const Eigen::Vector3d& position :
       {Eigen::Vector3d(1.0, 0, 0.36), Eigen::Vector3d(0, 0, 1.31), Eigen::Vector3d(0.5, 0.5, 1.2)}) {
    const world::Pose pose{Eigen::Translation3d(position)};
    EXPECT_EQ(kinematics.inverse(pose, 0.0, solutions), 0) << position.transpose();
    EXPECT_FALSE(kinematics.inverseNearest(pose, home, limits).has_value()) << position.transpose();
  }
  // Too near: the wrist centre on the shoulder (closer than 0.42 - 0.40 m).
  const world::Pose at_shoulder(Eigen::Translation3d(0, 0, 0.36 + 0.126));
  EXPECT_EQ(kinematics.inverse(at_shoulder, 0.0, solutions), 0);
  // Reachable by the geometry but only with the elbow folded past 120 degrees.
  const world::Pose folded = kinematics.forward(degrees({0, 10, 0, 150, 0, 0, 0}));
  EXPECT_GT(kinematics.inverse(folded, 0.0, solutions), 0);
  EXPECT_FALSE(kinematics.inverseNearest(folded, home, limits).has_value());
  // Non-finite input.
  world::Pose broken = world::Pose::Identity();
  broken.translation().x() = std::nan("");
  EXPECT_EQ(kinematics.inverse(broken, 0.0, solutions), 0);
  EXPECT_EQ(kinematics.inverse(kinematics.forward(home), std::nan(""), solutions), 0);
  EXPECT_FALSE(kinematics.inverseNearest(broken, home, limits).has_value());
  Joints7 bad_seed = home;
  bad_seed[2] = std::nan("");
  EXPECT_THROW(kinematics.inverseNearest(kinematics.forward(home), bad_seed, limits), std::invalid_argument);
}

TEST(SrsKinematics, SingularConfigurationsGiveFiniteExactSolutions) {
  const SrsKinematics kinematics(published::iiwa14Geometry());
  const SrsLimits limits = published::iiwa14Limits();
  const Joints7 home = degrees({0, 30, 0, -80, 0, 70, 0});
  // The wrist centre on joint 1's axis: x = 0.42 sin(q2) + 0.40 sin(q2 - q4) = 0 with q3 = 0
  // (joint 4 turns about -y).
  const double q2 = 0.5;
  const double q4 = q2 - std::asin(-0.42 * std::sin(q2) / 0.40);
  Joints7 wrist_on_axis;
  wrist_on_axis << 0.3, q2, 0.0, q4, 0.4, 0.7, -0.1;
  const world::Pose on_axis = kinematics.forward(wrist_on_axis);
  ASSERT_LT((on_axis.translation() - 0.126 * on_axis.linear().col(2)).head<2>().norm(), 1e-12);
  const std::vector<Joints7> singular = {
      Joints7::Zero(),                        // everything aligned, elbow straight
      degrees({20, 40, 10, 0, -30, 50, 60}),  // elbow straight
      degrees({20, 0, 10, 60, -30, 50, 60}),  // joints 1 and 3 aligned
      degrees({20, 40, 10, 60, -30, 0, 60}),  // joints 5 and 7 aligned
      degrees({20, 0, 10, 0, -30, 0, 60}),    // all of them
      wrist_on_axis,                          // the reference plane undefined
      degrees({0, 0, 0, 120, 0, 120, 0}),     // at the limits
  };
  std::array<Joints7, SrsKinematics::kMaxSolutions> solutions;
  for (const Joints7& q : singular) {
    const world::Pose pose = kinematics.forward(q);
    const double psi = kinematics.armAngle(q);
    ASSERT_TRUE(std::isfinite(psi));
    for (double angle : {psi, psi + 0.5, 0.0}) {
      const int count = kinematics.inverse(pose, angle, solutions);
      ASSERT_GT(count, 0) << q.transpose();
      for (int s = 0; s < count; ++s) {
        ASSERT_TRUE(solutions[s].allFinite()) << q.transpose();
        expectSamePose(kinematics.forward(solutions[s]), pose, 1e-9);
      }
    }
    for (const Joints7& seed : {q, home, Joints7::Zero().eval()}) {
      const std::optional<Joints7> solution = kinematics.inverseNearest(pose, seed, limits);
      ASSERT_TRUE(solution.has_value()) << q.transpose();
      ASSERT_TRUE(solution->allFinite());
      EXPECT_TRUE(limits.contains(*solution));
      expectSamePose(kinematics.forward(*solution), pose, 1e-9);
    }
    // From the configuration itself: that configuration (the aligned pair keeps the seed's split).
    EXPECT_LT((*kinematics.inverseNearest(pose, q, limits) - q).cwiseAbs().maxCoeff(), 1e-6) << q.transpose();
  }
}

TEST(SrsKinematics, AcceptableCallbackChoosesAmongSolutions) {
  const SrsKinematics kinematics(published::iiwa14Geometry());
  const SrsLimits limits = published::iiwa14Limits();
  const Joints7 q = degrees({10, 40, 0, -70, 20, 60, 0});
  const world::Pose pose = kinematics.forward(q);
  // Without a callback: q itself. With one that wants joint 3 above 30 degrees: another arm
  // angle, still the pose, still within limits.
  int calls = 0;
  const auto wants_joint_3_up = [&](const Joints7& candidate) {
    ++calls;
    return candidate[2] > 30 * kDegree;
  };
  const std::optional<Joints7> solution = kinematics.inverseNearest(pose, q, limits, wants_joint_3_up);
  ASSERT_TRUE(solution.has_value());
  EXPECT_GT((*solution)[2], 30 * kDegree);
  EXPECT_GT(calls, 1);
  EXPECT_TRUE(limits.contains(*solution));
  expectSamePose(kinematics.forward(*solution), pose, 1e-9);
  // Joint 4 (which turns about -y) does not depend on the arm angle: wanting it positive means
  // the other elbow branch; the callback sees the same angles the caller gets.
  const auto wants_elbow_positive = [](const Joints7& candidate) { return candidate[3] > 0.0; };
  const std::optional<Joints7> other_elbow = kinematics.inverseNearest(pose, q, limits, wants_elbow_positive);
  ASSERT_TRUE(other_elbow.has_value());
  EXPECT_NEAR((*other_elbow)[3], 70 * kDegree, 1e-9);
  EXPECT_TRUE(limits.contains(*other_elbow));
  expectSamePose(kinematics.forward(*other_elbow), pose, 1e-9);
  // A callback that accepts nothing: no solution, not garbage.
  EXPECT_FALSE(kinematics.inverseNearest(pose, q, limits, [](const Joints7&) { return false; }).has_value());
}

TEST(SrsKinematics, KdlLevenbergMarquardtBaselineSolvesTheUrdf) {
  // The paper's solver on the same arm, as the benchmark's baseline: with 10 random restarts it
  // finds most poses; every answer it gives is within limits and reaches the pose.
  const planning::RobotModel model = planning::RobotModel::fromUrdf(COSTAR_IIWA14_URDF, "iiwa_link_0", "tool0");
  const SrsKinematics kinematics(published::iiwa14Geometry());
  const SrsLimits limits = published::iiwa14Limits();
  const Joints7 home = degrees({0, 30, 0, -80, 0, 70, 0});
  std::mt19937_64 random(15);
  int solved = 0;
  for (int n = 0; n < 100; ++n) {
    const world::Pose pose = kinematics.forward(randomWithin(limits, random));
    const std::optional<Eigen::VectorXd> q = model.inverse(pose, home, 10, n);
    if (q) {
      ++solved;
      EXPECT_TRUE(limits.contains(*q));
      expectSamePose(kinematics.forward(*q), pose, 1e-4);
    }
  }
  EXPECT_GE(solved, 80);
}

TEST(SrsKinematics, RejectsBadGeometry) {
  SrsGeometry geometry = published::iiwa14Geometry();
  geometry.shoulder_to_elbow = 0.0;
  EXPECT_THROW(SrsKinematics{geometry}, std::invalid_argument);
  geometry = published::iiwa14Geometry();
  geometry.axis_sign[2] = 0;
  EXPECT_THROW(SrsKinematics{geometry}, std::invalid_argument);
  geometry = published::iiwa14Geometry();
  geometry.wrist_to_flange.linear() *= 2.0;
  EXPECT_THROW(SrsKinematics{geometry}, std::invalid_argument);
}

// ---------------------------------------------------------------------------------------------
// SrsArmKinematics: the solver as the arm's Kinematics (arm/kinematics.h)

class SrsAdapter : public ::testing::Test {
 protected:
  SrsAdapter() : kinematics_(makeKinematics(loadRobotDescription(COSTAR_IIWA14_DESCRIPTION))) {}
  static JointVector toVector(const Joints7& q) { return JointVector::fromEigen(q); }
  std::shared_ptr<const Kinematics> kinematics_;
};

TEST_F(SrsAdapter, TheFactoryMakesItFromTheDescription) {
  ASSERT_NE(dynamic_cast<const SrsArmKinematics*>(kinematics_.get()), nullptr);
  EXPECT_EQ(kinematics_->jointCount(), 7);
  EXPECT_DOUBLE_EQ(kinematics_->limits().max_position[6], 175 * kDegree);
  EXPECT_DOUBLE_EQ(kinematics_->limits().max_velocity[0], 85 * kDegree);
  const SrsKinematics reference(published::iiwa14Geometry());
  std::mt19937_64 random(11);
  for (int trial = 0; trial < 50; ++trial) {
    const Joints7 q = randomWithin(published::iiwa14Limits(), random);
    EXPECT_TRUE(kinematics_->forward(toVector(q)).isApprox(reference.forward(q), 1e-15)) << trial;
  }
}

// Every solution inverse() gives reaches the pose within the limits, sorted nearest the seed by
// solutionsNear(); the seed itself is the first when it solves the pose; poses of random
// configurations always have solutions.
TEST_F(SrsAdapter, SolutionsNearTheSeedReachThePoseWithinLimits) {
  std::mt19937_64 random(2026);
  const SrsLimits limits = published::iiwa14Limits();
  int total = 0;
  for (int trial = 0; trial < 500; ++trial) {
    const Joints7 target = randomWithin(limits, random, 0.05);
    const world::Pose pose = kinematics_->forward(toVector(target));
    const JointVector seed = toVector(randomWithin(limits, random, 0.05));
    IkSolutions solutions;
    kinematics_->solutionsNear(pose, seed, solutions);
    ASSERT_FALSE(solutions.empty()) << "trial " << trial;
    total += solutions.size();
    double previous = 0.0;
    for (const JointVector& q : solutions) {
      expectSamePose(kinematics_->forward(q), pose, 1e-9);
      for (int j = 0; j < 7; ++j) {
        EXPECT_GE(q[j], kinematics_->limits().min_position[j]);
        EXPECT_LE(q[j], kinematics_->limits().max_position[j]);
      }
      double distance = 0.0;
      for (int j = 0; j < 7; ++j) {
        distance += (q[j] - seed[j]) * (q[j] - seed[j]);
      }
      EXPECT_GE(distance, previous);
      previous = distance;
    }
    // Seeded with the configuration itself: it comes first.
    kinematics_->solutionsNear(pose, toVector(target), solutions);
    ASSERT_FALSE(solutions.empty());
    for (int j = 0; j < 7; ++j) {
      EXPECT_NEAR(solutions[0][j], target[j], 1e-9) << "trial " << trial << " joint " << j;
    }
  }
  EXPECT_GT(total, 500 * 4);  // several branches and arm angles per pose, not only one
}

TEST_F(SrsAdapter, InverseNearestAsksTheCallersPredicate) {
  const Joints7 home = degrees({0, 6, 0, -108, 0, 66, -90});
  const world::Pose pose = kinematics_->forward(toVector(home));
  const auto nearest = kinematics_->inverseNearest(pose, toVector(home));
  ASSERT_TRUE(nearest.has_value());
  EXPECT_NEAR((*nearest)[3], home[3], 1e-9);
  // Refusing every solution with the elbow's arm angle of the seed: another one is found.
  int asked = 0;
  const auto other = kinematics_->inverseNearest(pose, toVector(home), [&](const JointVector& q) {
    ++asked;
    return std::abs(q[0] - home[0]) > 0.1;
  });
  ASSERT_TRUE(other.has_value());
  EXPECT_GT(asked, 1);
  EXPECT_GT(std::abs((*other)[0] - home[0]), 0.1);
  expectSamePose(kinematics_->forward(*other), pose, 1e-9);
  // Unreachable: nothing, and a wrong seed is refused.
  world::Pose far = pose;
  far.translation() = Eigen::Vector3d(2.0, 0, 0.5);
  EXPECT_FALSE(kinematics_->inverseNearest(far, toVector(home)).has_value());
  EXPECT_THROW(kinematics_->inverseNearest(pose, JointVector::zero(6)), std::invalid_argument);
}

}  // namespace
}  // namespace costar::arm
