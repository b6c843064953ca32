#pragma once
// Joint-space vocabulary shared by the arm's kinematics and trajectories: a joint vector of
// any length up to kMaxJoints (the length comes from the robot), the joint limits, and angle
// helpers. Units: radians, rad/s, rad/s^2.

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <cstddef>
#include <initializer_list>
#include <numbers>
#include <stdexcept>
#include <string>

namespace costar::arm {

/// Most joints of an arm handled here (6 for the UR family, 7 for the LBR iiwa).
inline constexpr int kMaxJoints = 8;

/// One value per joint, joint 1 (base) first. Radians for positions, rad/s for velocities,
/// rad/s^2 for accelerations. A value type of fixed capacity (kMaxJoints) whose length is set
/// when it is made: it never allocates, so the planning and trajectory loops that copy joint
/// vectors stay free of heap allocations. Default-constructed it is empty (length 0); use
/// JointVector::zero(n) for n zeros. Values beyond the length are always 0.
class JointVector {
 public:
  using value_type = double;
  using size_type = int;
  using iterator = double*;
  using const_iterator = const double*;

  constexpr JointVector() = default;
  /// `count` joints, each `value`. Throws std::length_error unless 0 <= count <= kMaxJoints.
  explicit JointVector(int count, double value = 0.0) : size_(checkedSize(count)) {
    std::fill_n(values_.begin(), size_, value);
  }
  /// JointVector{q1, q2, ...}. Throws std::length_error for more than kMaxJoints values.
  JointVector(std::initializer_list<double> values) : size_(checkedSize(static_cast<int>(values.size()))) {
    std::copy(values.begin(), values.end(), values_.begin());
  }
  /// From an Eigen vector (or expression) of at most kMaxJoints elements.
  template <typename Derived>
  static JointVector fromEigen(const Eigen::DenseBase<Derived>& values) {
    JointVector q(static_cast<int>(values.size()));
    for (int j = 0; j < q.size_; ++j) {
      q.values_[j] = values(j);
    }
    return q;
  }
  /// `count` zeros.
  static JointVector zero(int count) { return JointVector(count, 0.0); }

  int size() const { return size_; }
  bool empty() const { return size_ == 0; }
  static constexpr int capacity() { return kMaxJoints; }

  double& operator[](int j) {
    assert(j >= 0 && j < size_);
    return values_[j];
  }
  double operator[](int j) const {
    assert(j >= 0 && j < size_);
    return values_[j];
  }
  /// Bounds-checked access: throws std::out_of_range.
  double at(int j) const {
    if (j < 0 || j >= size_) {
      throw std::out_of_range("joint " + std::to_string(j + 1) + " of a " + std::to_string(size_) + "-joint vector");
    }
    return values_[j];
  }

  double* data() { return values_.data(); }
  const double* data() const { return values_.data(); }
  iterator begin() { return values_.data(); }
  iterator end() { return values_.data() + size_; }
  const_iterator begin() const { return values_.data(); }
  const_iterator end() const { return values_.data() + size_; }

  void fill(double value) { std::fill_n(values_.begin(), size_, value); }

  /// Views for Eigen arithmetic, no copy.
  Eigen::Map<Eigen::VectorXd> eigen() { return {values_.data(), size_}; }
  Eigen::Map<const Eigen::VectorXd> eigen() const { return {values_.data(), size_}; }

  /// Same length and equal values.
  friend bool operator==(const JointVector& a, const JointVector& b) {
    return a.size_ == b.size_ && std::equal(a.begin(), a.end(), b.begin());
  }

 private:
  static int checkedSize(int count) {
    if (count < 0 || count > kMaxJoints) {
      throw std::length_error("a joint vector holds 0 to " + std::to_string(kMaxJoints) + " joints, not " +
                              std::to_string(count));
    }
    return count;
  }

  std::array<double, kMaxJoints> values_{};
  int size_ = 0;
};

/// Limits of each joint. Positions in radians, velocities in rad/s, accelerations in rad/s^2.
/// Velocity and acceleration limits are magnitudes (> 0) and apply symmetrically. All four
/// vectors have one value per joint of the arm.
struct JointLimits {
  JointVector min_position;
  JointVector max_position;
  JointVector max_velocity;
  JointVector max_acceleration;

  /// Number of joints (the length of min_position).
  int size() const { return min_position.size(); }
};

/// `angle` wrapped into (-pi, pi]. Finite input only (NaN stays NaN).
inline double wrapAngle(double angle) {
  if (angle > -std::numbers::pi && angle <= std::numbers::pi) {
    return angle;  // the common case, without the division
  }
  constexpr double kTwoPi = 2.0 * std::numbers::pi;
  double wrapped = std::remainder(angle, kTwoPi);  // in [-pi, pi]
  if (wrapped <= -std::numbers::pi) {
    wrapped += kTwoPi;
  }
  return wrapped;
}

/// Every element of `q` wrapped into (-pi, pi].
inline JointVector wrapAngles(const JointVector& q) {
  JointVector wrapped = q;
  for (double& value : wrapped) {
    value = wrapAngle(value);
  }
  return wrapped;
}

/// Largest absolute element-wise difference between two joint vectors of the same length, each
/// difference wrapped into (-pi, pi] first: the distance between two configurations modulo
/// 2*pi per joint.
inline double maxWrappedDifference(const JointVector& a, const JointVector& b) {
  assert(a.size() == b.size());
  double largest = 0.0;
  for (int j = 0; j < a.size(); ++j) {
    largest = std::fmax(largest, std::abs(wrapAngle(a[j] - b[j])));
  }
  return largest;
}

/// Largest absolute element-wise difference between two joint vectors of the same length.
inline double maxAbsDifference(const JointVector& a, const JointVector& b) {
  assert(a.size() == b.size());
  double largest = 0.0;
  for (int j = 0; j < a.size(); ++j) {
    largest = std::max(largest, std::abs(a[j] - b[j]));
  }
  return largest;
}

/// Largest absolute element.
inline double maxAbs(const JointVector& q) {
  double largest = 0.0;
  for (double value : q) {
    largest = std::max(largest, std::abs(value));
  }
  return largest;
}

/// True when every element of `q` is finite (no NaN, no infinity).
inline bool allFinite(const JointVector& q) {
  for (double value : q) {
    if (!std::isfinite(value)) {
      return false;
    }
  }
  return true;
}

}  // namespace costar::arm
