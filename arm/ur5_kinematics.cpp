#include "arm/ur5_kinematics.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

#include "arm/chain_kinematics.h"

namespace costar::arm {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kTwoPi = 2.0 * std::numbers::pi;

// How far a cosine or sine computed from a pose may leave [-1, 1] and still be taken as its
// boundary value: rounding, or a pose within about 1e-10 m of the workspace's boundary.
constexpr double kTrigonometricSlack = 1e-10;
// Two branches of a joint closer than this (radians) are one: at a singularity they merge.
constexpr double kBranchMergeTolerance = 1e-10;

// `value` clamped into [-1, 1] when it lies within the slack; nullopt when it is further out.
std::optional<double> clampUnit(double value) {
  if (!(std::abs(value) <= 1.0 + kTrigonometricSlack)) {  // also false for NaN
    return std::nullopt;
  }
  return std::clamp(value, -1.0, 1.0);
}

bool isFinite(const world::Pose& pose) { return pose.matrix().allFinite(); }

void require(bool condition, const std::string& message) {
  if (!condition) {
    throw std::invalid_argument("Ur5Kinematics: " + message);
  }
}

}  // namespace

DhParameters dhParametersOf(const ChainGeometry& chain) {
  constexpr double kTolerance = 1e-9;
  if (chain.joints.size() != static_cast<std::size_t>(Ur5Kinematics::kJointCount)) {
    throw std::invalid_argument("joints: the UR closed form needs 6 joints, not " +
                                std::to_string(chain.joints.size()));
  }
  const auto where = [](std::size_t i) -> std::string {
    return i < static_cast<std::size_t>(Ur5Kinematics::kJointCount) ? "joints[" + std::to_string(i) + "]"
                                                                    : std::string("tool");
  };
  for (std::size_t i = 0; i < chain.joints.size(); ++i) {
    if (!chain.joints[i].axis.isApprox(Eigen::Vector3d::UnitZ(), kTolerance)) {
      throw std::invalid_argument(where(i) + ".axis: must be [0, 0, 1] in DH form");
    }
  }
  if (!chain.joints[0].origin.isApprox(world::Pose::Identity(), kTolerance)) {
    throw std::invalid_argument(
        "joints[0].origin: must be [0, 0, 0] with no rpy in DH form (joint 1 on the base frame)");
  }
  DhParameters parameters{};
  for (std::size_t i = 0; i < parameters.d.size(); ++i) {
    const world::Pose& next = i + 1 < chain.joints.size() ? chain.joints[i + 1].origin : chain.flange;
    const Eigen::Vector3d p = next.translation();
    const Eigen::Matrix3d r = next.linear();
    const double alpha = std::atan2(r(2, 1), r(1, 1));
    if (std::abs(p.y()) > kTolerance ||
        !r.isApprox(Eigen::AngleAxisd(alpha, Eigen::Vector3d::UnitX()).toRotationMatrix(), kTolerance)) {
      throw std::invalid_argument(where(i + 1) +
                                  ".origin: must be [a, 0, d] turned about x only (rpy [alpha, 0, 0]) in DH form");
    }
    if (!(std::abs(p.x()) <= 10.0 && std::abs(p.z()) <= 10.0)) {  // NaN too
      throw std::invalid_argument(where(i + 1) + ".origin: a and d must be from -10 to 10 m (no arm is 10 m long)");
    }
    parameters.d[i] = p.z();
    parameters.a[i] = p.x();
    parameters.alpha[i] = alpha;
  }
  return parameters;
}

Ur5Kinematics::Ur5Kinematics(DhParameters parameters, JointLimits limits)
    : Kinematics(std::move(limits)), parameters_(parameters) {
  require(jointCount() == kJointCount, "the limits are for " + std::to_string(jointCount()) + " joints, not 6");
  const auto& [d, a, alpha] = parameters_;
  for (int i = 0; i < kJointCount; ++i) {
    require(std::isfinite(d[i]) && std::isfinite(a[i]) && std::isfinite(alpha[i]),
            "DH parameters of joint " + std::to_string(i + 1) + " are not finite");
  }
  const std::array<double, kJointCount> ur_alpha = {kPi / 2, 0.0, 0.0, kPi / 2, -kPi / 2, 0.0};
  for (int i = 0; i < kJointCount; ++i) {
    require(std::abs(alpha[i] - ur_alpha[i]) < 1e-12,
            "the closed form needs alpha = {pi/2, 0, 0, pi/2, -pi/2, 0}; alpha" + std::to_string(i + 1) + " = " +
                std::to_string(alpha[i]));
  }
  require(a[0] == 0.0 && a[3] == 0.0 && a[4] == 0.0 && a[5] == 0.0, "the closed form needs a1 = a4 = a5 = a6 = 0");
  require(d[1] == 0.0 && d[2] == 0.0, "the closed form needs d2 = d3 = 0");
  require(a[1] != 0.0 && a[2] != 0.0, "the closed form needs non-zero a2 and a3");
  require(d[5] != 0.0, "the closed form needs a non-zero d6");
  for (int i = 0; i < kJointCount; ++i) {
    // Exact zeros for the right angles, so that forward() has no 6e-17 cross terms.
    cos_alpha_[i] = std::abs(std::cos(alpha[i])) < 1e-15 ? 0.0 : std::cos(alpha[i]);
    sin_alpha_[i] = std::abs(std::sin(alpha[i])) < 1e-15 ? 0.0 : std::sin(alpha[i]);
  }
}

namespace {

// Rz(theta) * Tz(d) * Tx(a) * Rx(alpha), given cos/sin of theta and alpha.
world::Pose dhTransform(double cos_theta, double sin_theta, double d, double a, double cos_alpha, double sin_alpha) {
  world::Pose transform;
  Eigen::Matrix4d& m = transform.matrix();
  m << cos_theta, -sin_theta * cos_alpha, sin_theta * sin_alpha, a * cos_theta,  //
      sin_theta, cos_theta * cos_alpha, -cos_theta * sin_alpha, a * sin_theta,   //
      0.0, sin_alpha, cos_alpha, d,                                              //
      0.0, 0.0, 0.0, 1.0;
  return transform;
}

}  // namespace

world::Pose Ur5Kinematics::forward(const JointVector& q) const {
  assert(q.size() == kJointCount);
  world::Pose pose = world::Pose::Identity();
  for (int i = 0; i < kJointCount; ++i) {
    pose = pose * dhTransform(std::cos(q[i]), std::sin(q[i]), parameters_.d[i], parameters_.a[i], cos_alpha_[i],
                              sin_alpha_[i]);
  }
  return pose;
}

// At the wrist singularity (q5 = 0 or pi) the axes of joints 2, 3, 4 and 6 are parallel: the
// orientation fixes only q2 + q3 + q4 + q6 (or ... - q6 when q5 = pi), and turning q6 swings
// frame 4's origin on a circle of radius d5 around the wrist centre, in frame 1's xy plane,
// where joints 2 and 3 must reach it. Returns `preferred` when they can, else the q6 nearest to
// it for which they can (joints 2 and 3 then stretched or folded), or nullopt when no q6 works.
// `wrist_centre` is in frame 1; `frame_1_to_4_at_zero` is frame 4 in frame 1 for q6 = 0.
std::optional<double> Ur5Kinematics::wristSingularQ6(const Eigen::Vector3d& wrist_centre,
                                                     const world::Pose& frame_1_to_4_at_zero, double q5,
                                                     double preferred) const {
  const auto& d = parameters_.d;
  const auto& a = parameters_.a;
  // q234 = theta_zero - turn_sign * q6.
  const double theta_zero = std::atan2(frame_1_to_4_at_zero.linear()(1, 0), frame_1_to_4_at_zero.linear()(0, 0));
  const double turn_sign = std::cos(q5) > 0.0 ? 1.0 : -1.0;
  const double preferred_theta = theta_zero - turn_sign * preferred;
  // Frame 4's origin for q234 = theta: wrist_centre - d5 * (sin theta, -cos theta). Its
  // distance r from joint 2's axis must lie in [| |a2| - |a3| |, |a2| + |a3|]:
  // r^2 = rho^2 + d5^2 - 2 d5 rho sin(theta - beta), (rho, beta) the wrist centre's polar form.
  const double rho = std::hypot(wrist_centre.x(), wrist_centre.y());
  if (d[4] == 0.0 || rho == 0.0) {
    return preferred;  // the distance does not depend on q6
  }
  const double longest = std::abs(a[1]) + std::abs(a[2]);
  const double shortest = std::abs(std::abs(a[1]) - std::abs(a[2]));
  const double common = rho * rho + d[4] * d[4];
  const double low = (common - longest * longest) / (2.0 * d[4] * rho);
  const double high = (common - shortest * shortest) / (2.0 * d[4] * rho);
  if (low > 1.0 + kTrigonometricSlack || high < -1.0 - kTrigonometricSlack || low > high) {
    return std::nullopt;
  }
  const double beta = std::atan2(wrist_centre.y(), wrist_centre.x());
  const double preferred_u = wrapAngle(preferred_theta - beta);
  const double sine = std::sin(preferred_u);
  if (sine >= low && sine <= high) {
    return preferred;
  }
  // The nearest boundary of the reachable set of u = theta - beta.
  double best_u = preferred_u;
  double best_distance = std::numeric_limits<double>::infinity();
  for (double bound : {std::clamp(low, -1.0, 1.0), std::clamp(high, -1.0, 1.0)}) {
    for (double u : {std::asin(bound), kPi - std::asin(bound)}) {
      const double distance = std::abs(wrapAngle(u - preferred_u));
      if (distance < best_distance) {
        best_distance = distance;
        best_u = u;
      }
    }
  }
  return wrapAngle(turn_sign * (theta_zero - (beta + best_u)));
}

int Ur5Kinematics::inverse(const world::Pose& flange, std::array<JointVector, kMaxSolutions>& solutions,
                           double wrist_singular_q6) const {
  if (!isFinite(flange) || !std::isfinite(wrist_singular_q6)) {
    return 0;
  }
  const auto& d = parameters_.d;
  const auto& a = parameters_.a;
  const auto& ca = cos_alpha_;
  const auto& sa = sin_alpha_;
  const Eigen::Matrix3d rotation = flange.linear();
  const Eigen::Vector3d position = flange.translation();

  // Joint 1. The wrist centre (origin of frame 5, where the axes of joints 5 and 6 meet) lies
  // d6 behind the flange along the tool z axis. Joints 2-4 turn about z1 = (sin q1, -cos q1, 0)
  // and frames 1 to 5 advance d4 along it, so wrist_centre . z1 = d4:
  // r * sin(q1 - phi) = d4 with (r, phi) the wrist centre's polar coordinates.
  const Eigen::Vector3d wrist_centre = position - d[5] * rotation.col(2);
  const double radius = std::hypot(wrist_centre.x(), wrist_centre.y());
  if (radius == 0.0) {
    return 0;  // d4 != 0 keeps the wrist centre off joint 1's axis
  }
  const std::optional<double> shoulder_sine = clampUnit(d[3] / radius);
  if (!shoulder_sine) {
    return 0;  // the wrist centre is closer than |d4| to joint 1's axis
  }
  const double phi = std::atan2(wrist_centre.y(), wrist_centre.x());
  const double shoulder_offset = std::asin(*shoulder_sine);
  const double q1_branches[2] = {phi + shoulder_offset, phi + kPi - shoulder_offset};
  // Branches merge at singularities (shoulder: the offset is +-pi/2; wrist: q5 = 0 or pi;
  // elbow: q3 = 0 or pi); a merged pair gives one solution.
  const auto merged = [](double magnitude) {
    return magnitude < kBranchMergeTolerance || magnitude > kPi - kBranchMergeTolerance;
  };
  const int q1_branch_count = std::abs(std::abs(shoulder_offset) - kPi / 2) < kBranchMergeTolerance ? 1 : 2;

  int count = 0;
  for (int q1_branch = 0; q1_branch < q1_branch_count; ++q1_branch) {
    const double q1 = q1_branches[q1_branch];
    const double c1 = std::cos(q1);
    const double s1 = std::sin(q1);
    // Joint 5. z1 expressed in the flange frame is (sin q5 cos q6, -sin q5 sin q6, cos q5):
    // q5 from its components, with atan2 (well conditioned at the wrist singularity, where
    // acos of the z component alone would lose half the digits).
    const double z1_along_x6 = rotation(0, 0) * s1 - rotation(1, 0) * c1;
    const double z1_along_y6 = rotation(0, 1) * s1 - rotation(1, 1) * c1;
    const double z1_along_z6 = rotation(0, 2) * s1 - rotation(1, 2) * c1;
    const double sin_q5_magnitude = std::hypot(z1_along_x6, z1_along_y6);
    const double q5_magnitude = std::atan2(sin_q5_magnitude, z1_along_z6);
    const world::Pose base_to_1_inverse = dhTransform(c1, s1, d[0], a[0], ca[0], sa[0]).inverse(Eigen::Isometry);
    const double q5_branches[2] = {q5_magnitude, -q5_magnitude};
    for (int q5_branch = 0; q5_branch < (merged(q5_magnitude) ? 1 : 2); ++q5_branch) {
      const double q5 = q5_branches[q5_branch];
      const double s5 = q5_branch == 0 ? sin_q5_magnitude : -sin_q5_magnitude;
      const world::Pose frame_4_to_5 = dhTransform(z1_along_z6, s5, d[4], a[4], ca[4], sa[4]);
      // Frame 4 in frame 1 (what joints 2, 3 and 4 must produce), given cos and sin of q6.
      const auto frame_1_to_4_for = [&](double c6, double s6) {
        const world::Pose frame_5_to_6 = dhTransform(c6, s6, d[5], a[5], ca[5], sa[5]);
        return world::Pose(base_to_1_inverse * flange * (frame_4_to_5 * frame_5_to_6).inverse(Eigen::Isometry));
      };
      double q6 = 0.0;
      world::Pose frame_1_to_4;
      if (std::abs(s5) >= kWristSingularityThreshold) {
        // From the orientation: cos q6 and sin q6 are z1's flange components over sin q5.
        const double c6 = z1_along_x6 / s5;
        const double s6 = -z1_along_y6 / s5;
        q6 = std::atan2(s6, c6);
        frame_1_to_4 = frame_1_to_4_for(c6, s6);
      } else {
        const std::optional<double> reaching =
            wristSingularQ6(base_to_1_inverse * wrist_centre, frame_1_to_4_for(1.0, 0.0), q5, wrist_singular_q6);
        if (!reaching) {
          continue;
        }
        q6 = *reaching;
        frame_1_to_4 = frame_1_to_4_for(std::cos(q6), std::sin(q6));
      }
      // Origin of frame 3 (the wrist end of the forearm) in frame 1: joints 2 and 3 form a
      // planar two-link arm in frame 1's xy plane reaching it.
      const Eigen::Vector3d forearm_end = frame_1_to_4.translation() - d[3] * frame_1_to_4.linear().col(1);
      const double reach_squared = forearm_end.x() * forearm_end.x() + forearm_end.y() * forearm_end.y();
      const std::optional<double> c3 = clampUnit((reach_squared - a[1] * a[1] - a[2] * a[2]) / (2.0 * a[1] * a[2]));
      if (!c3) {
        continue;
      }
      const double q3_magnitude = std::acos(*c3);
      const double sin_q3_magnitude = std::sqrt(1.0 - *c3 * *c3);
      // Joints 2-4 all turn about z1: frame 4's x axis in frame 1 is at angle q2 + q3 + q4.
      const double q234 = std::atan2(frame_1_to_4.linear()(1, 0), frame_1_to_4.linear()(0, 0));
      const double forearm_angle = std::atan2(forearm_end.y(), forearm_end.x());
      const double q3_branches[2] = {q3_magnitude, -q3_magnitude};
      for (int q3_branch = 0; q3_branch < (merged(q3_magnitude) ? 1 : 2); ++q3_branch) {
        const double q3 = q3_branches[q3_branch];
        const double s3 = q3_branch == 0 ? sin_q3_magnitude : -sin_q3_magnitude;
        // forearm_end = e^{i q2} (a2 + a3 e^{i q3}) in the complex plane.
        const double q2 = forearm_angle - std::atan2(a[2] * s3, a[1] + a[2] * *c3);
        const double q4 = q234 - q2 - q3;
        solutions[count++] = wrapAngles({q1, q2, q3, q4, q5, q6});
      }
    }
  }
  return count;
}

std::vector<JointVector> Ur5Kinematics::inverse(const world::Pose& flange, double wrist_singular_q6) const {
  std::array<JointVector, kMaxSolutions> solutions;
  const int count = inverse(flange, solutions, wrist_singular_q6);
  return std::vector<JointVector>(solutions.begin(), solutions.begin() + count);
}

void Ur5Kinematics::inverse(const world::Pose& flange, const JointVector& seed, IkSolutions& solutions) const {
  static_assert(kMaxSolutions <= kMaxIkSolutions);
  std::array<JointVector, kMaxSolutions> found;
  const int count = inverse(flange, found, seed.size() == kJointCount ? seed[5] : 0.0);
  solutions.clear();
  for (int k = 0; k < count; ++k) {
    solutions.push_back(found[k]);
  }
}

std::optional<JointVector> Ur5Kinematics::nearestWithin(const world::Pose& flange, const JointVector& seed,
                                                        const JointLimits* limits) const {
  return nearest(flange, seed, limits, nullptr);
}

std::optional<JointVector> Ur5Kinematics::inverseNearest(const world::Pose& flange, const JointVector& seed,
                                                         const Acceptable& acceptable) const {
  return nearest(flange, seed, &limits(), acceptable ? &acceptable : nullptr);
}

std::optional<JointVector> Ur5Kinematics::nearest(const world::Pose& flange, const JointVector& seed,
                                                  const JointLimits* limits, const Acceptable* acceptable) const {
  if (seed.size() != kJointCount) {
    throw std::invalid_argument("Ur5Kinematics::inverseNearest: the seed has " + std::to_string(seed.size()) +
                                " joints, not 6");
  }
  if (!allFinite(seed)) {
    throw std::invalid_argument("Ur5Kinematics::inverseNearest: the seed has a non-finite joint angle");
  }
  std::array<JointVector, kMaxSolutions> solutions;
  const int count = inverse(flange, solutions, seed[5]);
  std::array<double, kMaxSolutions> distances_squared{};
  int candidates = 0;
  std::optional<JointVector> nearest;
  double nearest_distance_squared = 0.0;
  for (int k = 0; k < count; ++k) {
    JointVector candidate = JointVector::zero(kJointCount);
    bool within_limits = true;
    double distance_squared = 0.0;
    for (int j = 0; j < kJointCount && within_limits; ++j) {
      double angle = seed[j] + wrapAngle(solutions[k][j] - seed[j]);  // the equivalent closest to the seed
      if (limits != nullptr) {
        const double low = limits->min_position[j];
        const double high = limits->max_position[j];
        // Move toward the interval by whole turns: the first equivalent inside it is the one
        // closest to the seed among those inside.
        if (angle < low) {
          angle += kTwoPi * std::ceil((low - angle) / kTwoPi);
        } else if (angle > high) {
          angle -= kTwoPi * std::ceil((angle - high) / kTwoPi);
        }
        within_limits = angle >= low && angle <= high;
      }
      candidate[j] = angle;
      distance_squared += (angle - seed[j]) * (angle - seed[j]);
    }
    if (!within_limits) {
      continue;
    }
    if (acceptable != nullptr) {  // kept, to be asked nearest first below
      solutions[candidates] = candidate;
      distances_squared[candidates++] = distance_squared;
    } else if (!nearest || distance_squared < nearest_distance_squared) {
      nearest = candidate;
      nearest_distance_squared = distance_squared;
    }
  }
  if (acceptable != nullptr) {
    // Nearest first: the acceptable one with the smallest distance (ties: the earlier one).
    std::array<int, kMaxSolutions> order{};
    for (int k = 0; k < candidates; ++k) {
      order[k] = k;
    }
    for (int k = 1; k < candidates; ++k) {  // insertion sort: stable, and no allocation
      for (int i = k; i > 0 && distances_squared[order[i]] < distances_squared[order[i - 1]]; --i) {
        std::swap(order[i], order[i - 1]);
      }
    }
    for (int k = 0; k < candidates; ++k) {
      if ((*acceptable)(solutions[order[k]])) {
        return solutions[order[k]];
      }
    }
  }
  return nearest;
}

}  // namespace costar::arm
