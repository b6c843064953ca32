#include "arm/ur5_kinematics.h"
#include "arm/test/published_arms.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <numbers>
#include <random>
#include <stdexcept>

namespace costar::arm {
namespace {

/// The UR5's joints.
constexpr int kJointCount = arm::Ur5Kinematics::kJointCount;

constexpr double kPi = std::numbers::pi;
constexpr double kTwoPi = 2.0 * std::numbers::pi;

// Accuracy every solution must reach: metres for the position, radians for the rotation.
constexpr double kPoseTolerance = 1e-9;

JointVector randomJoints(std::mt19937_64& random, double low = -kPi, double high = kPi) {
  std::uniform_real_distribution<double> angle(low, high);
  JointVector q = JointVector::zero(kJointCount);
  for (double& value : q) {
    value = angle(random);
  }
  return q;
}

// The DH product written independently of the library: Eigen's own rotation and translation
// types, one factor per elementary transform.
world::Pose dhProduct(const DhParameters& dh, const JointVector& q) {
  world::Pose pose = world::Pose::Identity();
  for (int i = 0; i < kJointCount; ++i) {
    pose = pose * Eigen::AngleAxisd(q[i], Eigen::Vector3d::UnitZ()) * Eigen::Translation3d(0, 0, dh.d[i]) *
           Eigen::Translation3d(dh.a[i], 0, 0) * Eigen::AngleAxisd(dh.alpha[i], Eigen::Vector3d::UnitX());
  }
  return pose;
}

double positionError(const world::Pose& a, const world::Pose& b) { return (a.translation() - b.translation()).norm(); }
double rotationError(const world::Pose& a, const world::Pose& b) {
  return Eigen::AngleAxisd(a.linear().transpose() * b.linear()).angle();
}

// Smallest distance (modulo 2*pi per joint) from `q` to any of the solutions.
double distanceToNearest(const std::vector<JointVector>& solutions, const JointVector& q) {
  double nearest = std::numeric_limits<double>::infinity();
  for (const JointVector& solution : solutions) {
    nearest = std::min(nearest, maxWrappedDifference(solution, q));
  }
  return nearest;
}

// Checks that every solution is finite, in (-pi, pi], distinct, and reaches `target`.
void expectValidSolutions(const Ur5Kinematics& kinematics, const world::Pose& target,
                          const std::vector<JointVector>& solutions) {
  for (std::size_t k = 0; k < solutions.size(); ++k) {
    const JointVector& solution = solutions[k];
    for (double angle : solution) {
      ASSERT_TRUE(std::isfinite(angle));
      EXPECT_GT(angle, -kPi);
      EXPECT_LE(angle, kPi);
    }
    const world::Pose reached = kinematics.forward(solution);
    EXPECT_LE(positionError(reached, target), kPoseTolerance) << "solution " << k;
    EXPECT_LE(rotationError(reached, target), kPoseTolerance) << "solution " << k;
    for (std::size_t other = 0; other < k; ++other) {
      EXPECT_GT(maxWrappedDifference(solution, solutions[other]), 1e-9) << "solutions " << other << " and " << k;
    }
  }
}

TEST(Ur5Kinematics, ForwardMatchesAnIndependentProductOfDhMatrices) {
  const Ur5Kinematics kinematics(published::ur5Dh(), published::ur5Limits());
  std::mt19937_64 random(1);
  for (int trial = 0; trial < 1000; ++trial) {
    const JointVector q = randomJoints(random, -2 * kTwoPi, 2 * kTwoPi);
    const world::Pose expected = dhProduct(published::ur5Dh(), q);
    EXPECT_LE((kinematics.forward(q).matrix() - expected.matrix()).cwiseAbs().maxCoeff(), 1e-14);
  }
}

TEST(Ur5Kinematics, ZeroConfigurationIsTheArmStretchedAlongMinusX) {
  // Published UR5 zero pose: flange at (a2 + a3, -(d4 + d6), d1 - d5), tool z along -y.
  const world::Pose flange =
      Ur5Kinematics(published::ur5Dh(), published::ur5Limits()).forward(JointVector::zero(kJointCount));
  EXPECT_NEAR(flange.translation().x(), -0.425 - 0.39225, 1e-15);
  EXPECT_NEAR(flange.translation().y(), -0.10915 - 0.0823, 1e-15);
  EXPECT_NEAR(flange.translation().z(), 0.089159 - 0.09465, 1e-15);
  EXPECT_LE((flange.linear().col(2) - Eigen::Vector3d(0, -1, 0)).norm(), 1e-15);
}

TEST(Ur5Kinematics, EverySolutionReachesThePoseAndTheOriginalIsAmongThem) {
  const Ur5Kinematics kinematics(published::ur5Dh(), published::ur5Limits());
  std::mt19937_64 random(2);
  std::array<JointVector, Ur5Kinematics::kMaxSolutions> solutions;
  int total_solutions = 0;
  double worst_recovery = 0.0;
  for (int trial = 0; trial < 10000; ++trial) {
    const JointVector q = randomJoints(random);
    const world::Pose target = kinematics.forward(q);
    const int count = kinematics.inverse(target, solutions);
    ASSERT_GE(count, 1) << "trial " << trial;
    ASSERT_LE(count, Ur5Kinematics::kMaxSolutions);
    const std::vector<JointVector> found(solutions.begin(), solutions.begin() + count);
    expectValidSolutions(kinematics, target, found);
    const double recovery = distanceToNearest(found, q);
    worst_recovery = std::max(worst_recovery, recovery);
    EXPECT_LE(recovery, 1e-7) << "trial " << trial;
    total_solutions += count;
    if (HasFailure()) {
      FAIL() << "stopped at trial " << trial;
    }
  }
  // A random pose reached by a random configuration has 8 solutions unless a branch falls
  // out of reach; most have all 8.
  EXPECT_GT(total_solutions, 10000 * 6);
  RecordProperty("worst_recovery_rad", std::to_string(worst_recovery));
}

TEST(Ur5Kinematics, VectorOverloadReturnsTheSameSolutions) {
  const Ur5Kinematics kinematics(published::ur5Dh(), published::ur5Limits());
  std::mt19937_64 random(3);
  std::array<JointVector, Ur5Kinematics::kMaxSolutions> solutions;
  for (int trial = 0; trial < 100; ++trial) {
    const world::Pose target = kinematics.forward(randomJoints(random));
    const int count = kinematics.inverse(target, solutions);
    const std::vector<JointVector> as_vector = kinematics.inverse(target);
    ASSERT_EQ(static_cast<int>(as_vector.size()), count);
    for (int k = 0; k < count; ++k) {
      EXPECT_EQ(as_vector[k], solutions[k]);
    }
  }
}

// Damped Newton from a random start with a numerical Jacobian: an independent way to find
// solutions. Returns nullopt when it does not converge.
std::optional<JointVector> numericalInverse(const Ur5Kinematics& kinematics, const world::Pose& target, JointVector q) {
  for (int iteration = 0; iteration < 100; ++iteration) {
    const auto error_of = [&](const JointVector& joints) {
      const world::Pose reached = kinematics.forward(joints);
      Eigen::Matrix<double, 6, 1> error;
      error.head<3>() = target.translation() - reached.translation();
      const Eigen::AngleAxisd rotation(target.linear() * reached.linear().transpose());
      error.tail<3>() = rotation.angle() * rotation.axis();
      return error;
    };
    const Eigen::Matrix<double, 6, 1> error = error_of(q);
    if (error.norm() < 1e-12) {
      return wrapAngles(q);
    }
    Eigen::Matrix<double, 6, 6> jacobian;
    for (int j = 0; j < kJointCount; ++j) {
      JointVector moved = q;
      moved[j] += 1e-7;
      jacobian.col(j) = (error - error_of(moved)) / 1e-7;
    }
    const Eigen::Matrix<double, 6, 6> damped =
        jacobian.transpose() * jacobian + 1e-8 * Eigen::Matrix<double, 6, 6>::Identity();
    const Eigen::Matrix<double, 6, 1> step = damped.ldlt().solve(jacobian.transpose() * error);
    for (int j = 0; j < kJointCount; ++j) {
      q[j] += std::clamp(step[j], -0.5, 0.5);
    }
  }
  return std::nullopt;
}

TEST(Ur5Kinematics, NoSolutionIsMissedComparedWithANumericalSearch) {
  const Ur5Kinematics kinematics(published::ur5Dh(), published::ur5Limits());
  std::mt19937_64 random(4);
  int numerical_solutions = 0;
  for (int trial = 0; trial < 100; ++trial) {
    const world::Pose target = kinematics.forward(randomJoints(random));
    const std::vector<JointVector> solutions = kinematics.inverse(target);
    for (int start = 0; start < 40; ++start) {
      const std::optional<JointVector> found = numericalInverse(kinematics, target, randomJoints(random));
      if (found) {
        ++numerical_solutions;
        EXPECT_LE(distanceToNearest(solutions, *found), 1e-6) << "trial " << trial << ": a solution was missed";
      }
    }
  }
  EXPECT_GT(numerical_solutions, 1000);  // the search itself works
}

TEST(Ur5Kinematics, WristSingularityGivesValidSolutionsWithTheChosenQ6) {
  // q5 = 0 or pi: joint 6's axis parallel to those of joints 2, 3 and 4, a one-parameter family
  // of solutions (q2, q3, q4 and q6 move together). q6 takes the chosen value.
  const Ur5Kinematics kinematics(published::ur5Dh(), published::ur5Limits());
  std::mt19937_64 random(5);
  int adjusted = 0;
  for (int trial = 0; trial < 1000; ++trial) {
    JointVector q = randomJoints(random);
    q[4] = trial % 2 == 0 ? 0.0 : kPi;
    const world::Pose target = kinematics.forward(q);
    const double chosen_q6 = 0.3;
    const std::vector<JointVector> solutions = kinematics.inverse(target, chosen_q6);
    ASSERT_GE(solutions.size(), 1u);
    expectValidSolutions(kinematics, target, solutions);
    int singular = 0;
    for (const JointVector& solution : solutions) {
      if (std::abs(std::sin(solution[4])) < Ur5Kinematics::kWristSingularityThreshold) {
        ++singular;
        // The chosen q6, unless joints 2 and 3 cannot reach with it: then they are at the edge
        // of their reach, stretched or folded.
        if (std::abs(solution[5] - chosen_q6) > 1e-12) {
          ++adjusted;
          EXPECT_LT(std::abs(std::sin(solution[2])), 1e-4) << "trial " << trial;
        }
      }
    }
    EXPECT_GE(singular, 1) << "trial " << trial;
    // Choosing the original's q6 gives back the original.
    EXPECT_LE(distanceToNearest(kinematics.inverse(target, q[5]), q), 1e-7) << "trial " << trial;
  }
  RecordProperty("adjusted_q6", adjusted);
}

TEST(Ur5Kinematics, ShoulderSingularityGivesValidSolutions) {
  // The wrist centre (origin of frame 5) at distance d4 from joint 1's axis: the two shoulder
  // branches merge. In frame 1 its x coordinate is a2 c2 + a3 c23 + d5 sin(q2 + q3 + q4); zero
  // puts it there.
  const Ur5Kinematics kinematics(published::ur5Dh(), published::ur5Limits());
  const DhParameters dh = published::ur5Dh();
  std::mt19937_64 random(6);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int trial = 0; trial < 1000; ++trial) {
    JointVector q = randomJoints(random);
    q[2] = (unit(random) > 0 ? 1.0 : -1.0) * (0.3 + 2.2 * std::abs(unit(random)));  // elbow bent
    q[4] = (unit(random) > 0 ? 1.0 : -1.0) * (0.3 + 2.5 * std::abs(unit(random)));  // wrist not singular
    // Choose q2 so that a2 c2 + a3 c23 = reach, with |reach| < d5: with A = a2 + a3 c3 and
    // B = a3 s3, A c2 - B s2 = hypot(A, B) cos(q2 + atan2(B, A)).
    const double reach = 0.95 * dh.d[4] * unit(random);
    const double along = dh.a[1] + dh.a[2] * std::cos(q[2]);
    const double across = dh.a[2] * std::sin(q[2]);
    q[1] = std::acos(reach / std::hypot(along, across)) - std::atan2(across, along);
    ASSERT_NEAR(dh.a[1] * std::cos(q[1]) + dh.a[2] * std::cos(q[1] + q[2]), reach, 1e-12);
    const double q234 = std::asin(-reach / dh.d[4]);
    q[3] = q234 - q[1] - q[2];
    const world::Pose target = kinematics.forward(q);
    const Eigen::Vector3d wrist_centre = target.translation() - dh.d[5] * target.linear().col(2);
    ASSERT_NEAR(std::hypot(wrist_centre.x(), wrist_centre.y()), dh.d[3], 1e-12);

    const std::vector<JointVector> solutions = kinematics.inverse(target);
    ASSERT_GE(solutions.size(), 1u) << "trial " << trial;
    expectValidSolutions(kinematics, target, solutions);
    EXPECT_LE(distanceToNearest(solutions, q), 1e-6) << "trial " << trial;  // sqrt(eps) conditioning
  }
}

TEST(Ur5Kinematics, ElbowSingularityGivesValidSolutions) {
  const Ur5Kinematics kinematics(published::ur5Dh(), published::ur5Limits());
  std::mt19937_64 random(7);
  for (int trial = 0; trial < 1000; ++trial) {
    JointVector q = randomJoints(random);
    q[2] = 0.0;  // upper arm and forearm aligned
    const world::Pose target = kinematics.forward(q);
    const std::vector<JointVector> solutions = kinematics.inverse(target);
    ASSERT_GE(solutions.size(), 1u);
    expectValidSolutions(kinematics, target, solutions);
    EXPECT_LE(distanceToNearest(solutions, q), 1e-6) << "trial " << trial;
  }
}

TEST(Ur5Kinematics, UnreachablePosesHaveNoSolution) {
  const Ur5Kinematics kinematics(published::ur5Dh(), published::ur5Limits());
  std::array<JointVector, Ur5Kinematics::kMaxSolutions> solutions;
  const auto expect_none = [&](const world::Pose& pose, const char* what) {
    EXPECT_EQ(kinematics.inverse(pose, solutions), 0) << what;
    EXPECT_TRUE(kinematics.inverse(pose).empty()) << what;
    EXPECT_FALSE(kinematics.nearestWithin(pose, JointVector::zero(kJointCount))) << what;
  };
  expect_none(world::poseFromXyzRpy(2.0, 0.0, 0.3, 0.0, 0.0, 0.0), "beyond the reach");
  expect_none(world::poseFromXyzRpy(0.0, 0.0, 1.2, 0.0, 0.0, 0.0), "straight up, too high");
  // Wrist centre on joint 1's axis, or closer to it than d4.
  expect_none(world::poseFromXyzRpy(0.0, 0.0, 0.5 + 0.0823, kPi, 0.0, 0.0), "wrist centre on the base axis");
  expect_none(world::poseFromXyzRpy(0.05, 0.0, 0.4 - 0.0823, 0.0, 0.0, 0.0), "wrist centre inside the d4 cylinder");
  world::Pose not_finite = world::Pose::Identity();
  not_finite.translation().x() = std::numeric_limits<double>::quiet_NaN();
  expect_none(not_finite, "NaN");
  not_finite.translation().x() = std::numeric_limits<double>::infinity();
  expect_none(not_finite, "infinity");

  // Random poses in a box twice the reach: never a NaN, and whatever is returned is valid.
  std::mt19937_64 random(8);
  std::uniform_real_distribution<double> coordinate(-2.0, 2.0);
  std::uniform_real_distribution<double> angle(-kPi, kPi);
  int unreachable = 0;
  for (int trial = 0; trial < 10000; ++trial) {
    const world::Pose pose = world::poseFromXyzRpy(coordinate(random), coordinate(random), coordinate(random),
                                                   angle(random), angle(random), angle(random));
    const int count = kinematics.inverse(pose, solutions);
    unreachable += count == 0;
    expectValidSolutions(kinematics, pose, std::vector<JointVector>(solutions.begin(), solutions.begin() + count));
  }
  EXPECT_GT(unreachable, 5000);
}

// The nearest configuration to `seed` among all solutions and their 2*pi-equivalents within
// `limits`, by exhaustive search (joints are independent once the solution is chosen).
std::optional<JointVector> bruteForceNearest(const std::vector<JointVector>& solutions, const JointVector& seed,
                                             const JointLimits* limits) {
  std::optional<JointVector> best;
  double best_distance = std::numeric_limits<double>::infinity();
  for (const JointVector& solution : solutions) {
    JointVector candidate = JointVector::zero(kJointCount);
    double sum = 0.0;
    for (int j = 0; j < kJointCount; ++j) {
      double best_angle = std::numeric_limits<double>::quiet_NaN();
      for (int turn = -4; turn <= 4; ++turn) {
        const double angle = solution[j] + turn * kTwoPi;
        const bool allowed =
            limits == nullptr || (angle >= limits->min_position[j] && angle <= limits->max_position[j]);
        if (allowed && !(std::abs(angle - seed[j]) >= std::abs(best_angle - seed[j]))) {
          best_angle = angle;
        }
      }
      candidate[j] = best_angle;
      sum += (best_angle - seed[j]) * (best_angle - seed[j]);
    }
    if (std::isfinite(sum) && sum < best_distance) {
      best_distance = sum;
      best = candidate;
    }
  }
  return best;
}

double euclidean(const JointVector& a, const JointVector& b) {
  double sum = 0.0;
  for (int j = 0; j < kJointCount; ++j) {
    sum += (a[j] - b[j]) * (a[j] - b[j]);
  }
  return std::sqrt(sum);
}

TEST(Ur5Kinematics, InverseNearestPicksTheClosestSolutionExpressedNearTheSeed) {
  const Ur5Kinematics kinematics(published::ur5Dh(), published::ur5Limits());
  std::mt19937_64 random(9);
  std::uniform_real_distribution<double> nudge(-0.02, 0.02);
  std::uniform_int_distribution<int> turns(-1, 1);
  int checked_near = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    const JointVector q = randomJoints(random);
    const world::Pose target = kinematics.forward(q);
    const std::vector<JointVector> solutions = kinematics.inverse(target);

    // A seed near q, some joints a whole turn away: the answer is q expressed near the seed,
    // unless another solution is about as close (near a singularity).
    JointVector seed = JointVector::zero(kJointCount);
    JointVector expected = JointVector::zero(kJointCount);
    for (int j = 0; j < kJointCount; ++j) {
      expected[j] = q[j] + turns(random) * kTwoPi;
      seed[j] = expected[j] + nudge(random);
    }
    double gap = std::numeric_limits<double>::infinity();  // to the nearest other solution
    for (const JointVector& solution : solutions) {
      if (maxWrappedDifference(solution, q) > 1e-6) {
        JointVector difference = JointVector::zero(kJointCount);
        for (int j = 0; j < kJointCount; ++j) {
          difference[j] = wrapAngle(solution[j] - q[j]);
        }
        gap = std::min(gap, euclidean(difference, JointVector::zero(kJointCount)));
      }
    }
    const std::optional<JointVector> nearest = kinematics.nearestWithin(target, seed);
    ASSERT_TRUE(nearest);
    if (gap > 0.2) {
      ++checked_near;
      for (int j = 0; j < kJointCount; ++j) {
        EXPECT_NEAR((*nearest)[j], expected[j], 1e-7) << "trial " << trial << " joint " << j + 1;
      }
    }

    // For a random seed, against the exhaustive search.
    const JointVector far_seed = randomJoints(random, -kTwoPi, kTwoPi);
    const std::optional<JointVector> chosen = kinematics.nearestWithin(target, far_seed);
    const std::optional<JointVector> best = bruteForceNearest(solutions, far_seed, nullptr);
    ASSERT_TRUE(chosen && best);
    EXPECT_NEAR(euclidean(*chosen, far_seed), euclidean(*best, far_seed), 1e-9) << "trial " << trial;
    for (int j = 0; j < kJointCount; ++j) {
      EXPECT_LE(std::abs((*chosen)[j] - far_seed[j]), kPi + 1e-12);
    }
    EXPECT_LE(positionError(kinematics.forward(*chosen), target), kPoseTolerance);
    EXPECT_LE(rotationError(kinematics.forward(*chosen), target), kPoseTolerance);
  }
  EXPECT_GT(checked_near, 1800);
}

TEST(Ur5Kinematics, InverseNearestRespectsJointLimits) {
  const Ur5Kinematics kinematics(published::ur5Dh(), published::ur5Limits());
  const JointVector q = {0.3, -1.2, 1.5, -1.9, -1.4, 0.6};  // elbow "up" (q3 > 0)
  const world::Pose target = kinematics.forward(q);
  const std::vector<JointVector> solutions = kinematics.inverse(target);

  // Without limits: q itself.
  const std::optional<JointVector> free = kinematics.nearestWithin(target, q);
  ASSERT_TRUE(free);
  EXPECT_LE(maxWrappedDifference(*free, q), 1e-9);

  // Elbow limited to negative angles: another solution, with q3 < 0, the nearest allowed.
  JointLimits limits = published::ur5Limits();
  limits.max_position[2] = 0.0;
  const std::optional<JointVector> limited = kinematics.nearestWithin(target, q, &limits);
  ASSERT_TRUE(limited);
  EXPECT_LT((*limited)[2], 0.0);
  for (int j = 0; j < kJointCount; ++j) {
    EXPECT_GE((*limited)[j], limits.min_position[j]);
    EXPECT_LE((*limited)[j], limits.max_position[j]);
  }
  EXPECT_LE(positionError(kinematics.forward(*limited), target), kPoseTolerance);
  EXPECT_LE(rotationError(kinematics.forward(*limited), target), kPoseTolerance);
  const std::optional<JointVector> best_limited = bruteForceNearest(solutions, q, &limits);
  ASSERT_TRUE(best_limited);
  EXPECT_NEAR(euclidean(*limited, q), euclidean(*best_limited, q), 1e-9);

  // Random seeds and random limits, against the exhaustive search.
  std::mt19937_64 random(19);
  std::uniform_real_distribution<double> bound(0.0, 2 * kTwoPi);
  int found = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    JointLimits random_limits = published::ur5Limits();
    for (int j = 0; j < kJointCount; ++j) {
      random_limits.min_position[j] = -bound(random);
      random_limits.max_position[j] = random_limits.min_position[j] + bound(random);
    }
    const JointVector seed = randomJoints(random, -kTwoPi, kTwoPi);
    const std::optional<JointVector> chosen = kinematics.nearestWithin(target, seed, &random_limits);
    const std::optional<JointVector> best = bruteForceNearest(solutions, seed, &random_limits);
    ASSERT_EQ(chosen.has_value(), best.has_value()) << "trial " << trial;
    if (chosen) {
      ++found;
      EXPECT_NEAR(euclidean(*chosen, seed), euclidean(*best, seed), 1e-9) << "trial " << trial;
      for (int j = 0; j < kJointCount; ++j) {
        EXPECT_GE((*chosen)[j], random_limits.min_position[j]);
        EXPECT_LE((*chosen)[j], random_limits.max_position[j]);
      }
    }
  }
  EXPECT_GT(found, 500);

  // A seed near the upper limit of joint 1, whose nearest equivalent is beyond it.
  JointVector seed = q;
  seed[0] = q[0] + kTwoPi - 0.001;
  JointLimits tight = published::ur5Limits();
  tight.max_position[0] = q[0] + kTwoPi - 0.01;
  const std::optional<JointVector> unlimited = kinematics.nearestWithin(target, seed);
  ASSERT_TRUE(unlimited);
  EXPECT_NEAR((*unlimited)[0], q[0] + kTwoPi, 1e-9);
  const std::optional<JointVector> wrapped = kinematics.nearestWithin(target, seed, &tight);
  ASSERT_TRUE(wrapped);
  EXPECT_LE((*wrapped)[0], tight.max_position[0]);
  EXPECT_NEAR(euclidean(*wrapped, seed), euclidean(*bruteForceNearest(solutions, seed, &tight), seed), 1e-9);

  // Limits no solution satisfies: none.
  JointLimits impossible = published::ur5Limits();
  impossible.min_position[4] = 3.0;
  impossible.max_position[4] = 3.0;
  EXPECT_FALSE(kinematics.nearestWithin(target, q, &impossible));
}

TEST(Ur5Kinematics, InverseNearestKeepsTheSeedsQ6AtTheWristSingularity) {
  const Ur5Kinematics kinematics(published::ur5Dh(), published::ur5Limits());
  const JointVector q = {0.5, -1.0, 1.2, -0.7, 0.0, 0.4};
  const world::Pose target = kinematics.forward(q);
  JointVector seed = q;
  seed[5] = 1.1;
  const std::optional<JointVector> nearest = kinematics.nearestWithin(target, seed);
  ASSERT_TRUE(nearest);
  EXPECT_DOUBLE_EQ((*nearest)[5], 1.1);
  EXPECT_LE(positionError(kinematics.forward(*nearest), target), kPoseTolerance);
  EXPECT_LE(rotationError(kinematics.forward(*nearest), target), kPoseTolerance);
  // Seeded with the configuration itself, it comes back.
  const std::optional<JointVector> same = kinematics.nearestWithin(target, q);
  ASSERT_TRUE(same);
  EXPECT_LE(maxWrappedDifference(*same, q), 1e-9);
}

TEST(Ur5Kinematics, InverseNearestRejectsANonFiniteSeed) {
  const Ur5Kinematics kinematics(published::ur5Dh(), published::ur5Limits());
  JointVector seed = JointVector::zero(kJointCount);
  seed[2] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(kinematics.nearestWithin(kinematics.forward(JointVector::zero(kJointCount)), seed),
               std::invalid_argument);
}

TEST(Ur5Kinematics, OtherUrArmsWork) {
  // UR10 (CB-series) parameters.
  DhParameters ur10 = published::ur5Dh();
  ur10.d = {0.1273, 0.0, 0.0, 0.163941, 0.1157, 0.0922};
  ur10.a = {0.0, -0.612, -0.5723, 0.0, 0.0, 0.0};
  const Ur5Kinematics kinematics(ur10, published::ur5Limits());
  std::mt19937_64 random(10);
  for (int trial = 0; trial < 1000; ++trial) {
    const JointVector q = randomJoints(random);
    const world::Pose target = kinematics.forward(q);
    EXPECT_LE((target.matrix() - dhProduct(ur10, q).matrix()).cwiseAbs().maxCoeff(), 1e-14);
    const std::vector<JointVector> solutions = kinematics.inverse(target);
    expectValidSolutions(kinematics, target, solutions);
    EXPECT_LE(distanceToNearest(solutions, q), 1e-7);
  }
}

TEST(Ur5Kinematics, RejectsParametersWithoutTheUrStructure) {
  DhParameters offset_wrist = published::ur5Dh();
  offset_wrist.a[3] = 0.05;
  EXPECT_THROW(Ur5Kinematics(offset_wrist, published::ur5Limits()), std::invalid_argument);
  DhParameters twisted = published::ur5Dh();
  twisted.alpha[1] = 0.1;
  EXPECT_THROW(Ur5Kinematics(twisted, published::ur5Limits()), std::invalid_argument);
  DhParameters no_flange = published::ur5Dh();
  no_flange.d[5] = 0.0;
  EXPECT_THROW(Ur5Kinematics(no_flange, published::ur5Limits()), std::invalid_argument);
  DhParameters not_finite = published::ur5Dh();
  not_finite.d[0] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(Ur5Kinematics(not_finite, published::ur5Limits()), std::invalid_argument);
}

// --- the Kinematics interface --------------------------------------------------------------

TEST(Kinematics, TheUr5ThroughTheInterfaceGivesItsClosedFormWithinItsLimits) {
  const std::shared_ptr<const Kinematics> kinematics =
      std::make_shared<Ur5Kinematics>(published::ur5Dh(), published::ur5Limits());
  EXPECT_EQ(kinematics->jointCount(), 6);
  EXPECT_EQ(kinematics->limits().max_velocity, published::ur5Limits().max_velocity);
  const Ur5Kinematics& concrete = static_cast<const Ur5Kinematics&>(*kinematics);
  std::mt19937_64 random(5);
  std::uniform_real_distribution<double> angle(-3.0, 3.0);
  const JointLimits limits = published::ur5Limits();
  for (int trial = 0; trial < 200; ++trial) {
    JointVector q = JointVector::zero(kJointCount);
    for (double& value : q) {
      value = angle(random);
    }
    const world::Pose target = kinematics->forward(q);
    IkSolutions all;
    kinematics->inverse(target, q, all);
    EXPECT_EQ(all.size(), static_cast<int>(concrete.inverse(target, q[5]).size()));
    // Nearest: the same as the closed form's own within the UR5's limits.
    const auto nearest = kinematics->inverseNearest(target, q);
    ASSERT_TRUE(nearest) << "trial " << trial;
    EXPECT_EQ(*nearest, *concrete.nearestWithin(target, q, &limits));
    EXPECT_LE(maxWrappedDifference(*nearest, q), 1e-9);
    // solutionsNear: every solution within the limits, nearest first, the first the nearest.
    IkSolutions near;
    kinematics->solutionsNear(target, q, near);
    ASSERT_FALSE(near.empty());
    EXPECT_LE(maxWrappedDifference(near[0], q), 1e-9);
    for (int k = 1; k < near.size(); ++k) {
      EXPECT_LE((near[k - 1].eigen() - q.eigen()).norm(), (near[k].eigen() - q.eigen()).norm());
    }
    for (const JointVector& solution : near) {
      EXPECT_LE(positionError(kinematics->forward(solution), target), kPoseTolerance);
      for (int j = 0; j < kJointCount; ++j) {
        EXPECT_GE(solution[j], limits.min_position[j]);
        EXPECT_LE(solution[j], limits.max_position[j]);
      }
    }
  }
}

TEST(Kinematics, InverseNearestSkipsWhatTheCallerRejects) {
  const Ur5Kinematics kinematics(published::ur5Dh(), published::ur5Limits());
  const JointVector q = {0.3, -1.2, 1.4, -0.9, -1.5, 0.2};
  const world::Pose target = kinematics.forward(q);
  IkSolutions near;
  kinematics.solutionsNear(target, q, near);
  ASSERT_GE(near.size(), 2);
  // Rejecting the nearest gives the second nearest; rejecting all gives none.
  const auto second = kinematics.inverseNearest(
      target, q, [&q](const JointVector& candidate) { return maxWrappedDifference(candidate, q) > 1e-6; });
  ASSERT_TRUE(second);
  EXPECT_LE(maxWrappedDifference(*second, near[1]), 1e-9);
  EXPECT_FALSE(kinematics.inverseNearest(target, q, [](const JointVector&) { return false; }));
  // The seed must be the arm's length.
  EXPECT_THROW(kinematics.inverseNearest(target, JointVector::zero(7)), std::invalid_argument);
}

TEST(Kinematics, LimitsOfTheWrongLengthAreRefused) {
  JointLimits seven{JointVector(7, -3.0), JointVector(7, 3.0), JointVector(7, 1.0), JointVector(7, 1.0)};
  EXPECT_THROW(Ur5Kinematics(published::ur5Dh(), seven), std::invalid_argument);
  JointLimits broken = published::ur5Limits();
  broken.max_velocity[2] = 0.0;
  EXPECT_THROW(Ur5Kinematics(published::ur5Dh(), broken), std::invalid_argument);
}

}  // namespace
}  // namespace costar::arm
