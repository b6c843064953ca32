#include "arm/trajectory.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <numbers>
#include <random>
#include <stdexcept>

#include "arm/test/published_arms.h"
#include "arm/ur5_kinematics.h"

namespace costar::arm {
namespace {

/// The UR5's joints.
constexpr int kJointCount = arm::Ur5Kinematics::kJointCount;

using std::chrono::milliseconds;
using testing::HasSubstr;

constexpr double kPi = std::numbers::pi;
constexpr Duration kStep = milliseconds(1);
// Relative slack on the velocity and acceleration limits (rounding only).
constexpr double kLimitSlack = 1e-9;

double norm(const JointVector& v) {
  double sum = 0.0;
  for (double value : v) {
    sum += value * value;
  }
  return std::sqrt(sum);
}

JointVector minus(const JointVector& a, const JointVector& b) {
  JointVector result = JointVector::zero(kJointCount);
  for (int j = 0; j < kJointCount; ++j) {
    result[j] = a[j] - b[j];
  }
  return result;
}

double distance(const JointVector& a, const JointVector& b) { return norm(minus(a, b)); }

// Euclidean distance from `point` to the segment [start, end] in joint space.
double distanceToSegment(const JointVector& point, const JointVector& start, const JointVector& end) {
  const JointVector along = minus(end, start);
  const JointVector offset = minus(point, start);
  double dot = 0.0;
  double length_squared = 0.0;
  for (int j = 0; j < kJointCount; ++j) {
    dot += along[j] * offset[j];
    length_squared += along[j] * along[j];
  }
  const double fraction = length_squared > 0.0 ? std::clamp(dot / length_squared, 0.0, 1.0) : 0.0;
  double sum = 0.0;
  for (int j = 0; j < kJointCount; ++j) {
    const double difference = offset[j] - fraction * along[j];
    sum += difference * difference;
  }
  return std::sqrt(sum);
}

// Samples the whole trajectory every millisecond (and its last instant) and checks, at every
// sample, the velocity and acceleration limits (scaled by `scale`) and, when asked, the
// position limits; between samples, the continuity of position and velocity: velocity changes
// by at most a_max * dt, and position by the trapezoidal integral of the velocity within the
// error a Lipschitz velocity allows (a_max dt^2 / 4). Where the acceleration changes between two
// samples, the change is located to the nanosecond by bisection and both sides are compared.
// `visit` sees every sample.
void checkMotion(const JointTrajectory& trajectory, const JointLimits& limits, double scale, bool check_position_limits,
                 const std::function<void(Duration, const TrajectoryPoint&)>& visit = {}) {
  JointVector max_velocity = JointVector::zero(kJointCount);
  JointVector max_acceleration = JointVector::zero(kJointCount);
  for (int j = 0; j < kJointCount; ++j) {
    max_velocity[j] = limits.max_velocity[j] * scale * (1.0 + kLimitSlack);
    max_acceleration[j] = limits.max_acceleration[j] * scale * (1.0 + kLimitSlack);
  }
  // Plain comparisons first (this runs tens of millions of times), the assertion on failure.
  const auto check_sample = [&](Duration t, const TrajectoryPoint& point) {
    for (int j = 0; j < kJointCount; ++j) {
      const bool finite =
          std::isfinite(point.position[j]) && std::isfinite(point.velocity[j]) && std::isfinite(point.acceleration[j]);
      const bool within_position = !check_position_limits || (point.position[j] >= limits.min_position[j] - 1e-12 &&
                                                              point.position[j] <= limits.max_position[j] + 1e-12);
      if (!finite || !within_position || !(std::abs(point.velocity[j]) <= max_velocity[j]) ||
          !(std::abs(point.acceleration[j]) <= max_acceleration[j])) {
        FAIL() << "joint " << j + 1 << " at " << t.count() << " ns: position " << point.position[j] << " in ["
               << limits.min_position[j] << ", " << limits.max_position[j] << "], velocity " << point.velocity[j]
               << " (max " << max_velocity[j] << "), acceleration " << point.acceleration[j] << " (max "
               << max_acceleration[j] << ")";
      }
    }
  };
  const auto check_continuity = [&](Duration t1, const TrajectoryPoint& p1, Duration t2, const TrajectoryPoint& p2) {
    const double dt = toSeconds(t2 - t1);
    for (int j = 0; j < kJointCount; ++j) {
      const double velocity_change = std::abs(p2.velocity[j] - p1.velocity[j]);
      if (!(velocity_change <= max_acceleration[j] * dt + 1e-12)) {
        FAIL() << "velocity jump of " << velocity_change << " rad/s, joint " << j + 1 << " between " << t1.count()
               << " and " << t2.count() << " ns";
      }
      const double integral = 0.5 * (p1.velocity[j] + p2.velocity[j]) * dt;
      const double position_error = std::abs(p2.position[j] - p1.position[j] - integral);
      if (!(position_error <= 0.25 * max_acceleration[j] * dt * dt + 1e-12)) {
        FAIL() << "position jump of " << position_error << " rad, joint " << j + 1 << " between " << t1.count()
               << " and " << t2.count() << " ns";
      }
    }
  };
  const Duration end = trajectory.duration();
  Duration previous_time(0);
  TrajectoryPoint previous = trajectory.sample(previous_time);
  check_sample(previous_time, previous);
  if (visit) {
    visit(previous_time, previous);
  }
  while (previous_time < end) {
    const Duration time = std::min(previous_time + kStep, end);
    const TrajectoryPoint current = trajectory.sample(time);
    check_sample(time, current);
    check_continuity(previous_time, previous, time, current);
    if (current.acceleration != previous.acceleration) {
      Duration low = previous_time;
      Duration high = time;
      while (high - low > Duration(1)) {
        const Duration middle = low + (high - low) / 2;
        (trajectory.sample(middle).acceleration == previous.acceleration ? low : high) = middle;
      }
      check_continuity(low, trajectory.sample(low), high, trajectory.sample(high));
    }
    if (testing::Test::HasFatalFailure()) {
      return;
    }
    if (visit) {
      visit(time, current);
    }
    previous_time = time;
    previous = current;
  }
}

void expectAtRestAt(const TrajectoryPoint& point, const JointVector& position, double tolerance = 1e-12) {
  for (int j = 0; j < kJointCount; ++j) {
    EXPECT_NEAR(point.position[j], position[j], tolerance) << "joint " << j + 1;
    EXPECT_EQ(point.velocity[j], 0.0) << "joint " << j + 1;
  }
}

JointVector randomInside(std::mt19937_64& random, const JointLimits& limits, double margin = 0.0) {
  JointVector q = JointVector::zero(kJointCount);
  for (int j = 0; j < kJointCount; ++j) {
    q[j] = std::uniform_real_distribution<double>(limits.min_position[j] + margin,
                                                  limits.max_position[j] - margin)(random);
  }
  return q;
}

JointVector clampInside(JointVector q, const JointLimits& limits) {
  for (int j = 0; j < kJointCount; ++j) {
    q[j] = std::clamp(q[j], limits.min_position[j], limits.max_position[j]);
  }
  return q;
}

// Limits with different values per joint, to exercise the synchronization.
JointLimits unevenLimits() {
  JointLimits limits = published::ur5Limits();
  limits.max_velocity = {2.0, 2.5, 3.0, 3.1, 1.5, 1.2};
  limits.max_acceleration = {1.0, 4.0, 8.0, 2.0, 6.0, 3.0};
  limits.min_position[2] = -3.0;
  limits.max_position[2] = 3.0;
  return limits;
}

// A random start and target: far apart, nearby, or a few milliradians apart.
std::pair<JointVector, JointVector> randomMove(std::mt19937_64& random, const JointLimits& limits) {
  const JointVector from = randomInside(random, limits);
  const double spans[] = {1e-3, 0.3, 20.0};
  const double span = spans[std::uniform_int_distribution<int>(0, 2)(random)];
  JointVector to = JointVector::zero(kJointCount);
  for (int j = 0; j < kJointCount; ++j) {
    to[j] = from[j] + std::uniform_real_distribution<double>(-span, span)(random);
  }
  return {from, clampInside(to, limits)};
}

// --- pointToPoint ------------------------------------------------------------------------------

TEST(PointToPoint, RandomMovesRespectTheLimitsAndStartAndEndAtRest) {
  std::mt19937_64 random(11);
  std::uniform_real_distribution<double> scale_distribution(0.3, 1.0);
  for (int trial = 0; trial < 10000; ++trial) {
    const JointLimits limits = trial % 2 == 0 ? published::ur5Limits() : unevenLimits();
    // Not a structured binding: the lambda below uses `from` (clang before 16 cannot capture one).
    const auto move = randomMove(random, limits);
    const JointVector& from = move.first;
    const JointVector& to = move.second;
    const double scale = trial % 10 == 0 ? 1.0 : scale_distribution(random);
    const JointTrajectory trajectory = JointTrajectory::pointToPoint(from, to, limits, scale);
    SCOPED_TRACE("trial " + std::to_string(trial));
    expectAtRestAt(trajectory.sample(Duration(0)), from, 0.0);
    expectAtRestAt(trajectory.sample(trajectory.duration()), to, 0.0);
    EXPECT_EQ(trajectory.finalPosition(), to);
    // On the straight line, every joint at the same fraction of its way.
    const JointVector displacement = minus(to, from);
    const int reference =
        static_cast<int>(std::max_element(displacement.begin(), displacement.end(),
                                          [](double a, double b) { return std::abs(a) < std::abs(b); }) -
                         displacement.begin());
    double worst_fraction = 0.0;  // how far the fraction leaves [0, 1]
    double worst_off_line = 0.0;
    checkMotion(trajectory, limits, scale, true, [&](Duration, const TrajectoryPoint& point) {
      if (displacement[reference] == 0.0) {
        return;
      }
      const double fraction = (point.position[reference] - from[reference]) / displacement[reference];
      worst_fraction = std::max({worst_fraction, -fraction, fraction - 1.0});
      for (int j = 0; j < kJointCount; ++j) {
        worst_off_line = std::max(worst_off_line, std::abs(point.position[j] - from[j] - fraction * displacement[j]));
      }
    });
    EXPECT_LE(worst_fraction, 1e-12);
    EXPECT_LE(worst_off_line, 1e-9);
    if (HasFailure()) {
      return;
    }
  }
}

// Time of the synchronized trapezoid for a unit path with speed limit v and acceleration limit a.
double trapezoidTime(double v, double a) { return v * v / a >= 1.0 ? 2.0 * std::sqrt(1.0 / a) : 1.0 / v + v / a; }

TEST(PointToPoint, DurationIsTheAnalyticTrapezoidTime) {
  std::mt19937_64 random(12);
  for (int trial = 0; trial < 1000; ++trial) {
    const JointLimits limits = trial % 2 == 0 ? published::ur5Limits() : unevenLimits();
    const auto [from, to] = randomMove(random, limits);
    const double scale = 0.5 + 0.5 * (trial % 3) / 2.0;
    const JointTrajectory trajectory = JointTrajectory::pointToPoint(from, to, limits, scale);
    // In units of the fraction s of the way: s' <= min_j v_j / |D_j|, s'' <= min_j a_j / |D_j|.
    double speed = std::numeric_limits<double>::infinity();
    double acceleration = std::numeric_limits<double>::infinity();
    for (int j = 0; j < kJointCount; ++j) {
      const double moved = std::abs(to[j] - from[j]);
      speed = std::min(speed, scale * limits.max_velocity[j] / moved);
      acceleration = std::min(acceleration, scale * limits.max_acceleration[j] / moved);
    }
    const double expected = trapezoidTime(speed, acceleration);
    EXPECT_NEAR(toSeconds(trajectory.duration()), expected, 1e-9 * expected + 1e-9) << "trial " << trial;
  }
}

TEST(PointToPoint, WithEqualLimitsTheLongestJointMoveSetsTheDuration) {
  // UR5 limits (pi rad/s, 4 rad/s^2 on every joint): joint 2 moves furthest.
  const JointVector from = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
  const JointVector to = {0.5, -3.0, 1.0, 0.1, -0.2, 2.9};
  // Joint 2 moves 3 rad, more than the v^2 / a = pi^2 / 4 = 2.47 rad it needs to reach full
  // speed and stop: a trapezoid, d / v + v / a.
  const JointTrajectory full = JointTrajectory::pointToPoint(from, to, published::ur5Limits(), 1.0);
  EXPECT_NEAR(toSeconds(full.duration()), 3.0 / kPi + kPi / 4.0, 1e-9);
  // Half speed scales velocity and acceleration: 3 / (pi / 2) + (pi / 2) / 2.
  const JointTrajectory half = JointTrajectory::pointToPoint(from, to, published::ur5Limits(), 0.5);
  EXPECT_NEAR(toSeconds(half.duration()), 6.0 / kPi + kPi / 4.0, 1e-9);
  // A short move is triangular: 2 * sqrt(d / a).
  const JointVector near = {0.0, 0.1, 0.0, 0.0, 0.0, 0.0};
  EXPECT_NEAR(toSeconds(JointTrajectory::pointToPoint(from, near, published::ur5Limits(), 1.0).duration()),
              2.0 * std::sqrt(0.1 / 4.0), 1e-9);
}

TEST(PointToPoint, NoMotionHasZeroDuration) {
  const JointVector q = {0.1, 0.2, 0.3, 0.4, 0.5, 0.6};
  const JointTrajectory trajectory = JointTrajectory::pointToPoint(q, q, published::ur5Limits(), 1.0);
  EXPECT_EQ(trajectory.duration(), Duration(0));
  expectAtRestAt(trajectory.sample(Duration(0)), q, 0.0);
  expectAtRestAt(trajectory.sample(milliseconds(5)), q, 0.0);
}

TEST(PointToPoint, RejectsInvalidInputWithClearMessages) {
  const JointLimits limits = published::ur5Limits();
  const JointVector zero = JointVector::zero(kJointCount);
  JointVector not_finite = JointVector::zero(kJointCount);
  not_finite[1] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(JointTrajectory::pointToPoint(zero, not_finite, limits, 1.0), std::invalid_argument);
  EXPECT_THROW(JointTrajectory::pointToPoint(not_finite, zero, limits, 1.0), std::invalid_argument);
  for (double scale : {0.0, -0.5, 1.5, std::numeric_limits<double>::quiet_NaN()}) {
    EXPECT_THROW(JointTrajectory::pointToPoint(zero, zero, limits, scale), std::invalid_argument) << scale;
  }
  EXPECT_NO_THROW(JointTrajectory::pointToPoint(zero, zero, limits, 1.0));

  JointVector beyond = JointVector::zero(kJointCount);
  beyond[2] = 2 * kPi + 0.5;
  try {
    JointTrajectory::pointToPoint(zero, beyond, limits, 1.0);
    FAIL() << "no exception";
  } catch (const std::invalid_argument& error) {
    EXPECT_THAT(error.what(), HasSubstr("joint 3"));
    EXPECT_THAT(error.what(), HasSubstr("by 0.5 rad"));
    EXPECT_THAT(error.what(), HasSubstr("target"));
  }
  try {
    JointTrajectory::pointToPoint(zero, zero, limits, 2.0);
    FAIL() << "no exception";
  } catch (const std::invalid_argument& error) {
    EXPECT_THAT(error.what(), HasSubstr("speed_scale"));
  }
  JointLimits no_velocity = limits;
  no_velocity.max_velocity[4] = 0.0;
  EXPECT_THROW(JointTrajectory::pointToPoint(zero, zero, no_velocity, 1.0), std::invalid_argument);
  JointLimits inverted = limits;
  inverted.min_position[0] = 1.0;
  inverted.max_position[0] = -1.0;
  EXPECT_THROW(JointTrajectory::pointToPoint(zero, zero, inverted, 1.0), std::invalid_argument);
}

TEST(JointTrajectory, SampleClampsOutsideTheMotionAndCopiesAreEqual) {
  const JointVector from = {0.0, -1.0, 1.0, 0.0, 0.5, 0.0};
  const JointVector to = {1.0, -0.5, 0.2, 0.3, 0.5, -1.0};
  const JointTrajectory trajectory = JointTrajectory::pointToPoint(from, to, published::ur5Limits(), 0.7);
  expectAtRestAt(trajectory.sample(Duration(-5'000'000)), from, 0.0);
  expectAtRestAt(trajectory.sample(trajectory.duration() + milliseconds(100)), to, 0.0);
  EXPECT_EQ(trajectory.initialPosition(), from);
  const JointTrajectory copy = trajectory;
  EXPECT_EQ(copy.duration(), trajectory.duration());
  for (Duration t(0); t <= trajectory.duration(); t += milliseconds(7)) {
    EXPECT_EQ(copy.sample(t).position, trajectory.sample(t).position);
  }
  const JointTrajectory empty;
  EXPECT_EQ(empty.duration(), Duration(0));
  EXPECT_TRUE(empty.sample(Duration(0)).position.empty());  // no joints: the length comes from a robot
}

// --- alongPath ---------------------------------------------------------------------------------

// Random paths of four kinds: sparse via points, dense smooth curves, dense zig-zags (many
// small sharp corners), and Cartesian straight lines converted to joints point by point.
std::vector<JointVector> randomPath(std::mt19937_64& random, const JointLimits& limits, int kind) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::vector<JointVector> path;
  if (kind == 3) {
    static const Ur5Kinematics kinematics(published::ur5Dh(), published::ur5Limits());
    JointVector q = randomInside(random, limits, 0.5);
    q[1] = -1.0 + 0.5 * unit(random);
    q[2] = 1.5 + 0.5 * unit(random);  // away from the elbow singularity
    q[4] = 1.2 + 0.3 * unit(random);  // away from the wrist singularity
    const world::Pose start = kinematics.forward(q);
    const Eigen::Vector3d offset = 0.2 * Eigen::Vector3d(unit(random), unit(random), unit(random));
    const int steps = std::uniform_int_distribution<int>(10, 200)(random);
    path.push_back(q);
    for (int step = 1; step <= steps; ++step) {
      world::Pose pose = start;
      pose.translation() += offset * (static_cast<double>(step) / steps);
      const std::optional<JointVector> next = kinematics.nearestWithin(pose, path.back(), &limits);
      if (!next || distance(*next, path.back()) > 0.2) {
        break;  // out of reach or through a singularity: keep the path so far
      }
      path.push_back(*next);
    }
    return path;
  }
  if (kind == 0) {
    const int count = std::uniform_int_distribution<int>(2, 7)(random);
    const double span = std::uniform_real_distribution<double>(0.01, 2.0)(random);
    path.push_back(randomInside(random, limits));
    for (int k = 1; k < count; ++k) {
      JointVector next = path.back();
      for (double& value : next) {
        value += span * unit(random);
      }
      path.push_back(clampInside(next, limits));
      if (k == 2 && unit(random) > 0.6) {
        path.push_back(path.back());  // a repeated point
      }
    }
    return path;
  }
  const int count = std::uniform_int_distribution<int>(20, 200)(random);
  const JointVector centre = randomInside(random, limits, 1.5);
  JointVector amplitude = JointVector::zero(kJointCount);
  JointVector frequency = JointVector::zero(kJointCount);
  JointVector phase = JointVector::zero(kJointCount);
  for (int j = 0; j < kJointCount; ++j) {
    amplitude[j] = std::uniform_real_distribution<double>(0.01, 1.0)(random);
    frequency[j] = std::uniform_real_distribution<double>(0.5, 6.0)(random);
    phase[j] = kPi * unit(random);
  }
  const double noise = kind == 2 ? std::uniform_real_distribution<double>(1e-4, 3e-3)(random) : 0.0;
  for (int k = 0; k < count; ++k) {
    const double s = static_cast<double>(k) / (count - 1);
    JointVector point = JointVector::zero(kJointCount);
    for (int j = 0; j < kJointCount; ++j) {
      point[j] = centre[j] + amplitude[j] * std::sin(frequency[j] * s + phase[j]) + noise * unit(random);
    }
    path.push_back(clampInside(point, limits));
  }
  return path;
}

// Checks a trajectory along `path`: limits and continuity (checkMotion), at rest at both ends,
// within `tolerance` of the piecewise-linear path at every sample, and within `tolerance` of
// every point of the path at some instant.
void checkAlongPath(const JointTrajectory& trajectory, const std::vector<JointVector>& input_path,
                    const JointLimits& limits, double scale, double tolerance) {
  expectAtRestAt(trajectory.sample(Duration(0)), input_path.front(), 0.0);
  expectAtRestAt(trajectory.sample(trajectory.duration()), input_path.back(), 0.0);
  EXPECT_EQ(trajectory.finalPosition(), input_path.back());
  std::vector<JointVector> path;  // without repeated points (zero-length segments)
  for (const JointVector& point : input_path) {
    if (path.empty() || point != path.back()) {
      path.push_back(point);
    }
  }
  const double allowed = tolerance * (1.0 + 1e-9) + 1e-12;
  std::vector<double> cumulative(path.size(), 0.0);  // path length up to each point
  for (std::size_t k = 1; k < path.size(); ++k) {
    cumulative[k] = cumulative[k - 1] + distance(path[k], path[k - 1]);
  }
  const double max_speed = norm(limits.max_velocity) * scale;
  std::vector<double> closest(path.size(), std::numeric_limits<double>::infinity());
  std::vector<Duration> closest_time(path.size());
  std::size_t segment = 0;  // the segment the arm is at; it only moves forward
  const auto last_segment = path.size() >= 2 ? path.size() - 2 : 0;
  checkMotion(trajectory, limits, scale, true, [&](Duration t, const TrajectoryPoint& point) {
    if (path.size() >= 2) {
      // Look ahead as far as the arm can have gone in one step, and pick the nearest segment.
      const double reach = cumulative[segment + 1] + max_speed * toSeconds(kStep) + 4 * tolerance;
      double nearest = std::numeric_limits<double>::infinity();
      std::size_t nearest_segment = segment;
      for (std::size_t i = segment; i <= last_segment && cumulative[i] <= reach; ++i) {
        const double d = distanceToSegment(point.position, path[i], path[i + 1]);
        if (d < nearest) {
          nearest = d;
          nearest_segment = i;
        }
      }
      ASSERT_LE(nearest, allowed) << "off the path at " << t.count() << " ns";
      for (std::size_t k = segment; k <= nearest_segment + 1; ++k) {
        const double d = distance(point.position, path[k]);
        if (d < closest[k]) {
          closest[k] = d;
          closest_time[k] = t;
        }
      }
      segment = nearest_segment;
    }
  });
  if (testing::Test::HasFatalFailure()) {
    return;
  }
  // Points not seen within the tolerance at a sample: search the closest approach between the
  // neighbouring samples (golden section on the distance, unimodal there).
  for (std::size_t k = 0; k < path.size(); ++k) {
    if (closest[k] <= allowed) {
      continue;
    }
    const auto distance_at = [&](double seconds) {
      return distance(trajectory.sample(fromSeconds(seconds)).position, path[k]);
    };
    double low = std::max(0.0, toSeconds(closest_time[k] - kStep));
    double high = std::min(toSeconds(trajectory.duration()), toSeconds(closest_time[k] + kStep));
    const double ratio = (std::sqrt(5.0) - 1.0) / 2.0;
    for (int iteration = 0; iteration < 40 && high - low > 1e-9; ++iteration) {
      const double a = high - ratio * (high - low);
      const double b = low + ratio * (high - low);
      if (distance_at(a) < distance_at(b)) {
        high = b;
      } else {
        low = a;
      }
    }
    const double refined = std::min(closest[k], distance_at(0.5 * (low + high)));
    EXPECT_LE(refined, allowed) << "path point " << k << " of " << path.size() << " missed";
  }
}

TEST(AlongPath, RandomPathsRespectTheLimitsAndTheTolerance) {
  std::mt19937_64 random(13);
  std::uniform_real_distribution<double> scale_distribution(0.3, 1.0);
  int kinds[4] = {0, 0, 0, 0};  // paths of at least 10 points, per kind
  for (int trial = 0; trial < 10000; ++trial) {
    const JointLimits limits = trial % 3 == 0 ? unevenLimits() : published::ur5Limits();
    const int kind = trial % 4;
    const std::vector<JointVector> path = randomPath(random, limits, kind);
    kinds[kind] += path.size() >= 10;
    const double scale = trial % 10 == 0 ? 1.0 : scale_distribution(random);
    const double tolerance = trial % 5 == 0 ? 1e-2 : JointTrajectory::kDefaultPathTolerance;
    const JointTrajectory trajectory = JointTrajectory::alongPath(path, limits, scale, tolerance);
    SCOPED_TRACE("trial " + std::to_string(trial) + ", kind " + std::to_string(kind) + ", " +
                 std::to_string(path.size()) + " points");

    checkAlongPath(trajectory, path, limits, scale, tolerance);
    if (HasFailure()) {
      return;
    }
  }
  // Most Cartesian lines became real paths (the rest ran into a limit or a singularity).
  EXPECT_GT(kinds[3], 2000);
  EXPECT_EQ(kinds[1] + kinds[2], 5000);
}

TEST(AlongPath, TwoPointsOrCollinearPointsGiveThePointToPointMotion) {
  std::mt19937_64 random(14);
  for (int trial = 0; trial < 200; ++trial) {
    const JointLimits limits = trial % 2 == 0 ? published::ur5Limits() : unevenLimits();
    const auto [from, to] = randomMove(random, limits);
    const double scale = 0.3 + 0.7 * (trial % 5) / 4.0;
    const JointTrajectory direct = JointTrajectory::pointToPoint(from, to, limits, scale);
    const JointTrajectory two_points = JointTrajectory::alongPath({from, to}, limits, scale);
    EXPECT_EQ(two_points.duration(), direct.duration());
    std::vector<JointVector> dense;
    const int count = 2 + trial % 300;
    for (int k = 0; k <= count; ++k) {
      JointVector point = JointVector::zero(kJointCount);
      for (int j = 0; j < kJointCount; ++j) {
        point[j] = from[j] + (to[j] - from[j]) * k / count;
      }
      dense.push_back(k == count ? to : clampInside(point, limits));
    }
    const JointTrajectory collinear = JointTrajectory::alongPath(dense, limits, scale);
    EXPECT_NEAR(toSeconds(collinear.duration()), toSeconds(direct.duration()), 1e-6) << "trial " << trial;
    for (Duration t(0); t <= direct.duration(); t += milliseconds(3)) {
      const TrajectoryPoint a = direct.sample(t);
      const TrajectoryPoint b = collinear.sample(t);
      const TrajectoryPoint c = two_points.sample(t);
      for (int j = 0; j < kJointCount; ++j) {
        ASSERT_NEAR(a.position[j], b.position[j], 1e-5) << "trial " << trial;
        ASSERT_NEAR(a.position[j], c.position[j], 1e-12) << "trial " << trial;
      }
    }
  }
}

TEST(AlongPath, BlendsCornersInsteadOfStopping) {
  // Two legs at right angles: blended, the motion takes less than two stops would, and it
  // passes the corner within the tolerance without stopping there.
  const JointLimits limits = published::ur5Limits();
  const JointVector a = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
  const JointVector b = {1.0, 0.0, 0.0, 0.0, 0.0, 0.0};
  const JointVector c = {1.0, 1.0, 0.0, 0.0, 0.0, 0.0};
  for (double tolerance : {1e-3, 1e-2, 0.1}) {
    const JointTrajectory trajectory = JointTrajectory::alongPath({a, b, c}, limits, 1.0, tolerance);
    const double stopping = toSeconds(JointTrajectory::pointToPoint(a, b, limits, 1.0).duration()) +
                            toSeconds(JointTrajectory::pointToPoint(b, c, limits, 1.0).duration());
    EXPECT_LT(toSeconds(trajectory.duration()), stopping) << tolerance;
    checkAlongPath(trajectory, {a, b, c}, limits, 1.0, tolerance);
    double slowest_near_corner = std::numeric_limits<double>::infinity();
    for (Duration t(0); t <= trajectory.duration(); t += Duration(100'000)) {
      const TrajectoryPoint point = trajectory.sample(t);
      if (distance(point.position, b) < 2 * tolerance) {
        slowest_near_corner = std::min(slowest_near_corner, norm(point.velocity));
      }
    }
    EXPECT_GT(slowest_near_corner, 0.01) << tolerance;
  }
  // A dense, gently curving path (a quarter circle in joints 1-2, 500 points) is followed
  // at a good fraction of full speed.
  std::vector<JointVector> arc;
  for (int k = 0; k <= 500; ++k) {
    const double angle = 0.5 * kPi * k / 500;
    arc.push_back({2.0 * std::cos(angle), 2.0 * std::sin(angle), 0.0, 0.0, 0.0, 0.0});
  }
  const JointTrajectory along_arc = JointTrajectory::alongPath(arc, limits, 1.0);
  checkAlongPath(along_arc, arc, limits, 1.0, JointTrajectory::kDefaultPathTolerance);
  // Length pi; joint-space curvature 1/2: speed through the curve up to sqrt(a / k) = 2.8 rad/s;
  // at 2.8 rad/s with 0.7 s more to speed up and slow down: about 1.8 s.
  EXPECT_LT(toSeconds(along_arc.duration()), 2.0);
}

TEST(AlongPath, ReversalsAndSinglePoints) {
  const JointLimits limits = published::ur5Limits();
  const JointVector a = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
  const JointVector b = {0.5, -0.5, 0.2, 0.0, 0.0, 0.1};
  const JointTrajectory there_and_back = JointTrajectory::alongPath({a, b, a}, limits, 1.0);
  checkAlongPath(there_and_back, {a, b, a}, limits, 1.0, JointTrajectory::kDefaultPathTolerance);

  const JointTrajectory single = JointTrajectory::alongPath({b}, limits, 0.5);
  EXPECT_EQ(single.duration(), Duration(0));
  expectAtRestAt(single.sample(milliseconds(3)), b, 0.0);
  const JointTrajectory repeated = JointTrajectory::alongPath({b, b, b}, limits, 0.5);
  EXPECT_EQ(repeated.duration(), Duration(0));
}

TEST(AlongPath, RejectsInvalidInputWithClearMessages) {
  const JointLimits limits = published::ur5Limits();
  EXPECT_THROW(JointTrajectory::alongPath({}, limits, 1.0), std::invalid_argument);
  const JointVector zero = JointVector::zero(kJointCount);
  JointVector not_finite = JointVector::zero(kJointCount);
  not_finite[5] = std::numeric_limits<double>::infinity();
  EXPECT_THROW(JointTrajectory::alongPath({zero, not_finite}, limits, 1.0), std::invalid_argument);
  EXPECT_THROW(JointTrajectory::alongPath({zero, zero}, limits, 0.0), std::invalid_argument);
  EXPECT_THROW(JointTrajectory::alongPath({zero, zero}, limits, 1.0, 0.0), std::invalid_argument);
  EXPECT_THROW(JointTrajectory::alongPath({zero, zero}, limits, 1.0, -1.0), std::invalid_argument);
  JointVector below = JointVector::zero(kJointCount);
  below[0] = -2 * kPi - 0.25;
  try {
    JointTrajectory::alongPath({zero, zero, below}, limits, 1.0);
    FAIL() << "no exception";
  } catch (const std::invalid_argument& error) {
    EXPECT_THAT(error.what(), HasSubstr("path point 2"));
    EXPECT_THAT(error.what(), HasSubstr("joint 1"));
    EXPECT_THAT(error.what(), HasSubstr("by 0.25 rad"));
  }
  try {
    JointTrajectory::alongPath({}, limits, 1.0);
    FAIL() << "no exception";
  } catch (const std::invalid_argument& error) {
    EXPECT_THAT(error.what(), HasSubstr("empty"));
  }
}

// --- stopFrom ----------------------------------------------------------------------------------

TEST(StopFrom, StopsAlongTheDirectionOfMotionWithinTheAccelerationLimits) {
  std::mt19937_64 random(15);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int trial = 0; trial < 10000; ++trial) {
    const JointLimits limits = trial % 2 == 0 ? published::ur5Limits() : unevenLimits();
    const double scale = 0.2 + 0.8 * unit(random);
    // A state in the middle of a motion: a point-to-point move or a path.
    const bool straight = trial % 3 != 0;
    JointVector from = JointVector::zero(kJointCount);
    JointVector to = JointVector::zero(kJointCount);
    JointTrajectory moving;
    if (straight) {
      std::tie(from, to) = randomMove(random, limits);
      moving = JointTrajectory::pointToPoint(from, to, limits, scale);
    } else {
      moving = JointTrajectory::alongPath(randomPath(random, limits, trial % 4), limits, scale);
    }
    const Duration when = fromSeconds(unit(random) * toSeconds(moving.duration()));
    const TrajectoryPoint state = moving.sample(when);
    const JointTrajectory stop = JointTrajectory::stopFrom(state, limits);
    SCOPED_TRACE("trial " + std::to_string(trial));

    double expected_time = 0.0;
    for (int j = 0; j < kJointCount; ++j) {
      expected_time = std::max(expected_time, std::abs(state.velocity[j]) / limits.max_acceleration[j]);
    }
    EXPECT_NEAR(toSeconds(stop.duration()), expected_time, 1e-9);
    const TrajectoryPoint start = stop.sample(Duration(0));
    EXPECT_EQ(start.position, state.position);
    EXPECT_EQ(start.velocity, state.velocity);
    expectAtRestAt(stop.sample(stop.duration()), stop.finalPosition(), 0.0);
    // Decelerates along its current direction: v(t) = v0 (1 - t / T), every joint together.
    // Position limits: only for a straight move, whose target lies on the same line beyond.
    checkMotion(stop, limits, 1.0, straight, [&](Duration t, const TrajectoryPoint& point) {
      const double remaining = expected_time > 0.0 ? std::max(0.0, 1.0 - toSeconds(t) / expected_time) : 0.0;
      for (int j = 0; j < kJointCount; ++j) {
        EXPECT_NEAR(point.velocity[j], state.velocity[j] * remaining, 1e-9);
      }
    });
    if (straight && from != to) {
      // It stops no further than the move's target.
      const JointVector displacement = minus(to, from);
      double stopped_at = 0.0;
      double length_squared = 0.0;
      for (int j = 0; j < kJointCount; ++j) {
        stopped_at += (stop.finalPosition()[j] - from[j]) * displacement[j];
        length_squared += displacement[j] * displacement[j];
      }
      EXPECT_LE(stopped_at / length_squared, 1.0 + 1e-9);
    }
    if (HasFailure()) {
      return;
    }
  }
}

TEST(StopFrom, AtRestStaysPut) {
  TrajectoryPoint state;
  state.position = {0.1, 0.2, 0.3, 0.4, 0.5, 0.6};
  state.velocity = JointVector::zero(kJointCount);
  state.acceleration = {1.0, 0.0, 0.0, 0.0, 0.0, 0.0};  // ignored
  const JointTrajectory stop = JointTrajectory::stopFrom(state, published::ur5Limits());
  EXPECT_EQ(stop.duration(), Duration(0));
  expectAtRestAt(stop.sample(Duration(0)), state.position, 0.0);
}

TEST(StopFrom, RejectsNonFiniteStates) {
  TrajectoryPoint state;
  state.position = JointVector::zero(kJointCount);
  state.velocity = JointVector::zero(kJointCount);
  state.velocity[3] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(JointTrajectory::stopFrom(state, published::ur5Limits()), std::invalid_argument);
}

TEST(JointLengths, TrajectoriesTakeTheirLengthFromTheLimits) {
  // A 7-joint arm: the same generators, the length from the data.
  JointLimits seven{JointVector(7, -3.0), JointVector(7, 3.0), JointVector(7, 1.5), JointVector(7, 4.0)};
  const JointVector from = JointVector::zero(7);
  const JointVector to = {0.5, -0.5, 1.0, 0.2, 0.0, -1.0, 2.0};
  const JointTrajectory move = JointTrajectory::pointToPoint(from, to, seven, 1.0);
  EXPECT_EQ(move.sample(Duration(0)).position.size(), 7);
  EXPECT_EQ(move.finalPosition(), to);
  // Joint 7 moves furthest (2 rad at 1.5 rad/s at most): it sets the duration.
  EXPECT_GT(toSeconds(move.duration()), 2.0 / 1.5);
  const JointTrajectory path = JointTrajectory::alongPath({from, to, from}, seven, 0.5);
  EXPECT_EQ(path.finalPosition(), from);
  // A 6-joint point against 7-joint limits is refused, naming both lengths.
  try {
    JointTrajectory::pointToPoint(JointVector::zero(6), JointVector::zero(6), seven, 1.0);
    ADD_FAILURE() << "a 6-joint motion with 7-joint limits was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_THAT(e.what(), HasSubstr("has 6 joints, the limits 7"));
  }
  // Limits whose vectors differ in length are refused.
  seven.max_velocity = JointVector(6, 1.5);
  EXPECT_THROW(JointTrajectory::validate(seven), std::invalid_argument);
}

TEST(JointLengths, AJointVectorHoldsUpToItsCapacityWithoutAllocating) {
  const JointVector q = {1, 2, 3, 4, 5, 6, 7, 8};
  EXPECT_EQ(q.size(), kMaxJoints);
  EXPECT_EQ(q.eigen().sum(), 36.0);
  EXPECT_THROW(JointVector(kMaxJoints + 1), std::length_error);
  EXPECT_THROW((JointVector{1, 2, 3, 4, 5, 6, 7, 8, 9}), std::length_error);
  EXPECT_NE(JointVector::zero(6), JointVector::zero(7));  // lengths differ
  EXPECT_EQ(JointVector::fromEigen(q.eigen()), q);
  EXPECT_THROW(static_cast<void>(q.at(8)), std::out_of_range);
  EXPECT_TRUE(JointVector().empty());
}

}  // namespace
}  // namespace costar::arm
