#pragma once
// Forward and inverse kinematics of any serial chain of revolute joints, from the joints of a
// robot description (format costar-robot-description/1: each joint's origin and rpy in its
// parent link's frame and its axis, as in URDF). The arms without a closed form use it (the
// Franka Panda: its elbow is offset, so it is neither a UR nor an S-R-S arm); the UR and the
// iiwa keep their closed forms, and a test checks this solver against both.
//
// Inverse kinematics is Levenberg-Marquardt with the damping set by the error (T. Sugihara,
// "Solvability-unconcerned inverse kinematics by the Levenberg-Marquardt method", IEEE T-RO
// 27(5), 2011: lambda = E + lambda_bar, quadratic near a solution, well damped far from one and
// at singularities), each step clamped to the joint limits, started from the seed and then, when
// that does not converge or its answer is refused, from restarts near the seed and then over the
// whole range (a fixed sequence: the same pose and seed always give the same answers); a joint
// at its limit that a step pushes further out is held there while the others move. Units: metres and radians.

#include <Eigen/Geometry>
#include <filesystem>
#include <string>
#include <vector>

#include "arm/kinematics.h"
#include "world/pose.h"

namespace costar::arm {

/// One revolute joint: its frame at zero angle in the parent joint's frame (the first joint's in
/// the base frame) and the axis it turns about in its own frame (unit length).
struct ChainJoint {
  world::Pose origin = world::Pose::Identity();
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();
};

/// A serial chain: its joints, base first, and the flange in the last joint's frame.
struct ChainGeometry {
  std::vector<ChainJoint> joints;
  world::Pose flange = world::Pose::Identity();
};

/// The chain of a costar-robot-description/1 file: joints[].origin, .rpy (optional, URDF's
/// fixed-axis roll, pitch, yaw) and .axis, and tool.origin, .rpy (the flange). Throws
/// std::runtime_error "FILE: FIELD: PROBLEM" for a missing or ill-typed field, an axis that is
/// not a direction, or a joint count outside 1..kMaxJoints.
ChainGeometry readChainGeometry(const std::filesystem::path& file);

/// How hard inverse() tries. Tolerances: the flange within `position_tolerance` (m) and
/// `angle_tolerance` (rad) of the pose.
struct ChainIkOptions {
  double position_tolerance = 1e-6;
  double angle_tolerance = 1e-6;
  int iterations = 40;  // per start
  int restarts = 40;    // starts after the seed's, drawn within the limits
  int solutions = 4;    // inverse() stops after this many distinct solutions
};

class ChainKinematics final : public Kinematics {
 public:
  /// Throws std::invalid_argument when the limits' joint count is not the chain's or a limit is
  /// not an interval.
  ChainKinematics(ChainGeometry geometry, JointLimits limits, ChainIkOptions options = {});

  world::Pose forward(const JointVector& q) const override;

  /// The seed's solution first (when its start converges within the limits), then those of the
  /// restarts, distinct (more than 1e-3 rad apart on some joint), up to options.solutions. Every
  /// solution is within the joint limits. Does not allocate.
  void inverse(const world::Pose& flange, const JointVector& seed, IkSolutions& solutions) const override;

  /// The seed's solution when it is acceptable (the usual case in a Cartesian move: one start,
  /// a few iterations); otherwise the nearest acceptable one among the restarts' solutions.
  std::optional<JointVector> inverseNearest(const world::Pose& flange, const JointVector& seed,
                                            const Acceptable& acceptable) const override;
  using Kinematics::inverseNearest;

  /// One Levenberg-Marquardt descent from `start`: the configuration within limits that reaches
  /// `flange` within the tolerances, or nullopt. Does not allocate.
  std::optional<JointVector> descend(const world::Pose& flange, const JointVector& start) const;

  const ChainGeometry& geometry() const { return geometry_; }
  const ChainIkOptions& options() const { return options_; }

 private:
  /// The start of restart `k` (0-based): near `seed` for the first few, then spread over the
  /// limits; points of a fixed low-discrepancy sequence, so every call is reproducible.
  JointVector restartStart(int k, const JointVector& seed) const;

  ChainGeometry geometry_;
  ChainIkOptions options_;
};

}  // namespace costar::arm
