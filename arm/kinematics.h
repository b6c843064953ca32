#pragma once
// The kinematics of an arm, whatever the robot: how many joints it has, their limits, where the
// flange is for a joint configuration (forward), and the joint configurations that put the
// flange at a pose (inverse). The arm component, SmartMove and the benchmarks hold this
// interface; each robot family brings one implementation (arm/ur5_kinematics.h: the closed
// form of the UR arms; a 7-joint arm parameterises its redundancy).
//
// Frames: the base frame is the robot's mounting frame; the flange frame is the robot's tool
// flange (where a tool is bolted on). Units: metres and radians.
//
// Joint angles: solvers return each solution as it comes out of their formulas; for revolute
// joints q and q +/- 2*pi are the same configuration. solutionsNear() and inverseNearest()
// express every solution as the 2*pi-equivalent nearest a seed configuration, within the
// joint limits. None of the calls allocates (the hot loops of planning call them thousands of
// times), except through a caller's `acceptable` predicate.

#include <array>
#include <functional>
#include <optional>

#include "arm/joints.h"
#include "world/pose.h"

namespace costar::arm {

/// Most solutions one inverse() call returns: the 8 branches of the UR closed form, or a
/// sample of the self-motion of a redundant arm.
inline constexpr int kMaxIkSolutions = 16;

/// A bounded list of inverse-kinematics solutions, stored in place (no heap allocation).
class IkSolutions {
 public:
  int size() const { return size_; }
  bool empty() const { return size_ == 0; }
  static constexpr int capacity() { return kMaxIkSolutions; }
  const JointVector& operator[](int i) const { return items_[i]; }
  JointVector& operator[](int i) { return items_[i]; }
  const JointVector* begin() const { return items_.data(); }
  const JointVector* end() const { return items_.data() + size_; }
  JointVector* begin() { return items_.data(); }
  JointVector* end() { return items_.data() + size_; }
  void clear() { size_ = 0; }
  /// Appends `q`; false (and nothing added) when the list is full.
  bool push_back(const JointVector& q) {
    if (size_ == kMaxIkSolutions) {
      return false;
    }
    items_[size_++] = q;
    return true;
  }
  /// Keeps the first `count` solutions.
  void truncate(int count) { size_ = count < size_ ? (count < 0 ? 0 : count) : size_; }

 private:
  std::array<JointVector, kMaxIkSolutions> items_{};
  int size_ = 0;
};

class Kinematics {
 public:
  /// A solution the caller accepts (e.g. free of collisions); called nearest-first.
  using Acceptable = std::function<bool(const JointVector&)>;

  virtual ~Kinematics() = default;
  Kinematics(const Kinematics&) = delete;
  Kinematics& operator=(const Kinematics&) = delete;

  /// Number of joints (1 to kMaxJoints).
  int jointCount() const { return limits_.size(); }
  /// Position, velocity and acceleration limits of every joint.
  const JointLimits& limits() const { return limits_; }

  /// Pose of the flange in the base frame for the joint configuration `q` (jointCount()
  /// angles, any range). Does not allocate.
  virtual world::Pose forward(const JointVector& q) const = 0;

  /// Every solution for the flange pose `flange` (in the base frame), replacing the contents
  /// of `solutions`; at most kMaxIkSolutions, each with jointCount() angles in whatever range
  /// the solver gives. `seed` (a configuration, e.g. where the arm is now) settles what the
  /// pose leaves free: a redundant arm's self-motion, or the UR wrist's angle at its
  /// singularity. Unreachable poses and non-finite input give no solution. Does not allocate.
  virtual void inverse(const world::Pose& flange, const JointVector& seed, IkSolutions& solutions) const = 0;

  /// The solution nearest `seed` (Euclidean distance in joint space), each joint within its
  /// position limits and expressed as the 2*pi-equivalent nearest the seed's, for which
  /// `acceptable` (when given) returns true; nullopt when there is none.
  /// Throws std::invalid_argument when `seed` has a non-finite entry or the wrong length.
  virtual std::optional<JointVector> inverseNearest(const world::Pose& flange, const JointVector& seed,
                                                    const Acceptable& acceptable) const;
  std::optional<JointVector> inverseNearest(const world::Pose& flange, const JointVector& seed) const {
    return inverseNearest(flange, seed, Acceptable());
  }

  /// Every solution of inverse(), each joint moved by whole turns to the equivalent nearest the
  /// seed's and then, when that is outside the joint's limits, by whole turns into them;
  /// solutions with a joint that has no equivalent within its limits are dropped. Sorted
  /// nearest the seed first (Euclidean distance). Does not allocate.
  void solutionsNear(const world::Pose& flange, const JointVector& seed, IkSolutions& solutions) const;

 protected:
  /// Throws std::invalid_argument "WHO: the seed has ..." unless `seed` has jointCount() finite
  /// angles (the check every inverseNearest makes).
  void checkSeed(const JointVector& seed, const char* who) const;

  /// Throws std::invalid_argument when `limits` are not valid (see JointTrajectory::validate:
  /// one finite interval, a positive velocity and acceleration per joint, 1 to kMaxJoints
  /// joints).
  explicit Kinematics(JointLimits limits);

 private:
  JointLimits limits_;
};

}  // namespace costar::arm
