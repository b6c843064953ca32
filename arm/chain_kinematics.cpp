#include "arm/chain_kinematics.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>

#include "core/files.h"
#include "core/json_file.h"

namespace costar::arm {

namespace {

using Vector6 = Eigen::Matrix<double, 6, 1>;

std::runtime_error fieldError(const std::filesystem::path& file, const std::string& field, const std::string& problem) {
  return std::runtime_error(file.string() + ": " + field + ": " + problem);
}

Eigen::Vector3d vec3(const nlohmann::json& object, const char* key, const std::filesystem::path& file,
                     const std::string& field, bool optional) {
  if (!object.contains(key)) {
    if (optional) {
      return Eigen::Vector3d::Zero();
    }
    throw fieldError(file, field + "." + key, "missing");
  }
  const nlohmann::json& value = object[key];
  if (!value.is_array() || value.size() != 3 || !value[0].is_number() || !value[1].is_number() ||
      !value[2].is_number()) {
    throw fieldError(file, field + "." + key, "must be 3 numbers, not " + value.dump());
  }
  return {value[0].get<double>(), value[1].get<double>(), value[2].get<double>()};
}

/// URDF's origin: translation, then R = Rz(yaw) Ry(pitch) Rx(roll).
world::Pose frame(const Eigen::Vector3d& origin, const Eigen::Vector3d& rpy) {
  world::Pose pose = world::Pose::Identity();
  pose.translate(origin);
  pose.rotate(Eigen::AngleAxisd(rpy.z(), Eigen::Vector3d::UnitZ()) *
              Eigen::AngleAxisd(rpy.y(), Eigen::Vector3d::UnitY()) *
              Eigen::AngleAxisd(rpy.x(), Eigen::Vector3d::UnitX()));
  return pose;
}

/// The radical inverse of `index` in `base` (Halton's sequence), in [0, 1).
double radicalInverse(int index, int base) {
  double result = 0.0;
  double fraction = 1.0 / base;
  while (index > 0) {
    result += fraction * (index % base);
    index /= base;
    fraction /= base;
  }
  return result;
}

double squaredDistance(const JointVector& a, const JointVector& b) {
  double sum = 0.0;
  for (int j = 0; j < a.size(); ++j) {
    sum += (a[j] - b[j]) * (a[j] - b[j]);
  }
  return sum;
}

bool distinctFromAll(const JointVector& q, const IkSolutions& solutions) {
  return std::none_of(solutions.begin(), solutions.end(),
                      [&q](const JointVector& other) { return maxAbsDifference(q, other) < 1e-3; });
}

}  // namespace

ChainGeometry readChainGeometry(const std::filesystem::path& file) {
  nlohmann::json root;
  try {
    root = core::parseJson(readFile(file, "robot description"));
  } catch (const core::JsonSyntaxError& error) {
    throw std::runtime_error(file.string() + ": not valid JSON: " + error.what());
  }
  const nlohmann::json& joints = root.contains("joints") ? root["joints"] : nlohmann::json();
  if (!joints.is_array() || joints.empty() || joints.size() > static_cast<std::size_t>(kMaxJoints)) {
    throw fieldError(file, "joints", "must be a list of 1 to " + std::to_string(kMaxJoints) + " joints");
  }
  ChainGeometry geometry;
  for (std::size_t i = 0; i < joints.size(); ++i) {
    const std::string field = "joints[" + std::to_string(i) + "]";
    if (!joints[i].is_object()) {
      throw fieldError(file, field, "must be an object");
    }
    ChainJoint joint;
    joint.origin = frame(vec3(joints[i], "origin", file, field, false), vec3(joints[i], "rpy", file, field, true));
    const Eigen::Vector3d axis = vec3(joints[i], "axis", file, field, false);
    if (!(std::abs(axis.norm() - 1.0) < 1e-9)) {
      throw fieldError(file, field + ".axis", "must be a unit vector");
    }
    joint.axis = axis;
    geometry.joints.push_back(joint);
  }
  if (!root.contains("tool") || !root["tool"].is_object()) {
    throw fieldError(file, "tool", "missing (the flange: name, parent, origin, rpy)");
  }
  geometry.flange =
      frame(vec3(root["tool"], "origin", file, "tool", false), vec3(root["tool"], "rpy", file, "tool", true));
  return geometry;
}

ChainKinematics::ChainKinematics(ChainGeometry geometry, JointLimits limits, ChainIkOptions options)
    : Kinematics(std::move(limits)), geometry_(std::move(geometry)), options_(options) {
  if (static_cast<int>(geometry_.joints.size()) != jointCount()) {
    throw std::invalid_argument("ChainKinematics: the chain has " + std::to_string(geometry_.joints.size()) +
                                " joints, the limits " + std::to_string(jointCount()));
  }
  if (options_.iterations < 1 || options_.restarts < 0 || options_.solutions < 1 ||
      options_.solutions > kMaxIkSolutions || !(options_.position_tolerance > 0.0) ||
      !(options_.angle_tolerance > 0.0)) {
    throw std::invalid_argument("ChainKinematics: options out of range");
  }
}

world::Pose ChainKinematics::forward(const JointVector& q) const {
  world::Pose pose = world::Pose::Identity();
  for (int j = 0; j < jointCount(); ++j) {
    pose = pose * geometry_.joints[j].origin * Eigen::AngleAxisd(q[j], geometry_.joints[j].axis);
  }
  return pose * geometry_.flange;
}

namespace {

/// Rotation by `angle` about the unit `axis` (Rodrigues).
Eigen::Matrix3d rotationAbout(const Eigen::Vector3d& axis, double angle) {
  const double c = std::cos(angle);
  const double s = std::sin(angle);
  Eigen::Matrix3d skew;
  skew << 0, -axis.z(), axis.y(), axis.z(), 0, -axis.x(), -axis.y(), axis.x(), 0;
  return Eigen::Matrix3d::Identity() + s * skew + (1.0 - c) * skew * skew;
}

/// One Levenberg-Marquardt descent (ChainKinematics::descend) with N joints known at compile
/// time (6 and 7: the common arms, without dynamic sizes in the inner loop) or Eigen::Dynamic.
template <int N>
std::optional<JointVector> descendChain(const ChainGeometry& geometry, const JointLimits& bounds,
                                        const ChainIkOptions& options, const world::Pose& flange,
                                        const JointVector& start) {
  const int n = static_cast<int>(geometry.joints.size());
  constexpr int kMax = N == Eigen::Dynamic ? kMaxJoints : N;
  using JacobianN = Eigen::Matrix<double, 6, N, 0, 6, kMax>;
  using SquareN = Eigen::Matrix<double, N, N, 0, kMax, kMax>;
  using ColumnN = Eigen::Matrix<double, N, 1, 0, kMax, 1>;
  JointVector q = start;
  for (int j = 0; j < n; ++j) {
    q[j] = std::clamp(q[j], bounds.min_position[j], bounds.max_position[j]);
  }
  const Eigen::Matrix3d target_rotation = flange.linear();
  const Eigen::Vector3d target_position = flange.translation();
  JacobianN jacobian(6, n);
  std::array<Eigen::Vector3d, kMax> axes;
  std::array<Eigen::Vector3d, kMax> points;
  // Sugihara's lambda = w E + lambda_bar: w < 1 lets the steps grow far from the pose (fewer
  // iterations than w = 1 on random starts); lambda_bar keeps a step bounded at a singularity.
  // Units: m^2 and rad^2, as E.
  constexpr double kEnergyWeight = 0.03;
  constexpr double kDampingFloor = 1e-5;
  // A start that stops improving (a joint against its limit, a local minimum) is given up soon:
  // a restart costs less than waiting.
  constexpr int kPatience = 3;
  double best_energy = std::numeric_limits<double>::infinity();
  int since_improvement = 0;
  for (int iteration = 0;; ++iteration) {
    Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
    Eigen::Vector3d position = Eigen::Vector3d::Zero();
    for (int j = 0; j < n; ++j) {
      const ChainJoint& joint = geometry.joints[j];
      position += rotation * joint.origin.translation();
      rotation = rotation * joint.origin.linear();
      axes[j] = rotation * joint.axis;
      points[j] = position;
      if (joint.axis.z() == 1.0) {  // about z (URDF's and DH's usual axis): two columns turn
        const double c = std::cos(q[j]);
        const double s = std::sin(q[j]);
        const Eigen::Vector3d x = rotation.col(0);
        rotation.col(0) = c * x + s * rotation.col(1);
        rotation.col(1) = c * rotation.col(1) - s * x;
      } else {
        rotation = rotation * rotationAbout(joint.axis, q[j]);
      }
    }
    position += rotation * geometry.flange.translation();
    rotation = rotation * geometry.flange.linear();
    Vector6 error;
    error.head<3>() = target_position - position;
    // The rotation vector of target * reached^-1: its skew part is sin(angle) axis, its trace
    // 1 + 2 cos(angle); near a half turn the axis comes from Eigen's conversion instead.
    const Eigen::Matrix3d turn = target_rotation * rotation.transpose();
    const Eigen::Vector3d sine_axis =
        0.5 * Eigen::Vector3d(turn(2, 1) - turn(1, 2), turn(0, 2) - turn(2, 0), turn(1, 0) - turn(0, 1));
    const double sine = sine_axis.norm();
    const double cosine = 0.5 * (turn.trace() - 1.0);
    if (sine > 1e-6 || cosine > 0.0) {
      error.tail<3>() = sine > 0.0 ? (std::atan2(sine, cosine) / sine) * sine_axis : sine_axis;
    } else {
      const Eigen::AngleAxisd half_turn(turn);
      error.tail<3>() = half_turn.angle() * half_turn.axis();
    }
    if (error.head<3>().norm() < options.position_tolerance && error.tail<3>().norm() < options.angle_tolerance) {
      return q;
    }
    const double energy = 0.5 * error.squaredNorm();
    if (energy < best_energy * 0.999) {
      best_energy = energy;
      since_improvement = 0;
    } else if (++since_improvement > kPatience) {
      return std::nullopt;
    }
    if (iteration == options.iterations) {
      return std::nullopt;
    }
    for (int j = 0; j < n; ++j) {
      jacobian.template block<3, 1>(0, j) = axes[j].cross(position - points[j]);
      jacobian.template block<3, 1>(3, j) = axes[j];
    }
    SquareN normal = jacobian.transpose() * jacobian;
    normal.diagonal().array() += kEnergyWeight * energy + kDampingFloor;
    ColumnN step = normal.ldlt().solve(jacobian.transpose() * error);
    // A joint at its limit that the step pushes further out is held there, and the others
    // take up its share (a second solve without its column).
    bool held = false;
    for (int j = 0; j < n; ++j) {
      if ((q[j] <= bounds.min_position[j] && step[j] < 0.0) || (q[j] >= bounds.max_position[j] && step[j] > 0.0)) {
        jacobian.col(j).setZero();
        held = true;
      }
    }
    if (held) {
      normal = jacobian.transpose() * jacobian;
      normal.diagonal().array() += kEnergyWeight * energy + kDampingFloor;
      step = normal.ldlt().solve(jacobian.transpose() * error);
    }
    for (int j = 0; j < n; ++j) {
      q[j] = std::clamp(q[j] + step[j], bounds.min_position[j], bounds.max_position[j]);
    }
  }
}

}  // namespace

std::optional<JointVector> ChainKinematics::descend(const world::Pose& flange, const JointVector& start) const {
  switch (jointCount()) {
    case 6:
      return descendChain<6>(geometry_, limits(), options_, flange, start);
    case 7:
      return descendChain<7>(geometry_, limits(), options_, flange, start);
    default:
      return descendChain<Eigen::Dynamic>(geometry_, limits(), options_, flange, start);
  }
}

JointVector ChainKinematics::restartStart(int k, const JointVector& seed) const {
  static constexpr std::array<int, kMaxJoints> kPrimes = {2, 3, 5, 7, 11, 13, 17, 19};
  // The first restart stays near the seed (within 0.2 rad per joint: the seed's own start may
  // have failed at a singularity or a limit, and the answer near it is the one wanted), the
  // others spread over the range less a tenth at each end (a start at a limit is held there).
  constexpr double kMargin = 0.1;
  constexpr int kNearSeed = 1;
  constexpr double kNearSeedSpan = 0.4;
  const JointLimits& bounds = limits();
  JointVector q(jointCount());
  for (int j = 0; j < jointCount(); ++j) {
    const double u = radicalInverse(k + 1, kPrimes[j]);
    q[j] = k < kNearSeed
               ? std::clamp(seed[j] + (u - 0.5) * kNearSeedSpan, bounds.min_position[j], bounds.max_position[j])
               : bounds.min_position[j] +
                     (kMargin + (1.0 - 2.0 * kMargin) * u) * (bounds.max_position[j] - bounds.min_position[j]);
  }
  return q;
}

void ChainKinematics::inverse(const world::Pose& flange, const JointVector& seed, IkSolutions& solutions) const {
  solutions.clear();
  if (!flange.matrix().allFinite() || seed.size() != jointCount() || !allFinite(seed)) {
    return;
  }
  if (const auto q = descend(flange, seed)) {
    solutions.push_back(*q);
  }
  for (int k = 0; k < options_.restarts && solutions.size() < options_.solutions; ++k) {
    const auto q = descend(flange, restartStart(k, seed));
    if (q && distinctFromAll(*q, solutions)) {
      solutions.push_back(*q);
    }
  }
}

std::optional<JointVector> ChainKinematics::inverseNearest(const world::Pose& flange, const JointVector& seed,
                                                           const Acceptable& acceptable) const {
  checkSeed(seed, "ChainKinematics::inverseNearest");
  if (!flange.matrix().allFinite()) {
    return std::nullopt;
  }
  const auto near = descend(flange, seed);
  if (near && (!acceptable || acceptable(*near))) {
    return near;
  }
  // The restarts' solutions, nearest the seed first; more restarts while none is acceptable.
  IkSolutions found;
  if (near) {
    found.push_back(*near);
  }
  int next = 0;
  while (next < options_.restarts) {
    IkSolutions batch;
    for (; next < options_.restarts && batch.size() < options_.solutions; ++next) {
      const auto q = descend(flange, restartStart(next, seed));
      if (q && distinctFromAll(*q, found) && distinctFromAll(*q, batch)) {
        batch.push_back(*q);
      }
    }
    std::sort(batch.begin(), batch.end(), [&seed](const JointVector& a, const JointVector& b) {
      return squaredDistance(a, seed) < squaredDistance(b, seed);
    });
    for (const JointVector& q : batch) {
      if (!acceptable || acceptable(q)) {
        return q;
      }
      if (!found.push_back(q)) {
        return std::nullopt;  // as many distinct solutions as a call keeps, none acceptable
      }
    }
  }
  return std::nullopt;
}

}  // namespace costar::arm
