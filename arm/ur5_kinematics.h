#pragma once
// Closed-form forward and inverse kinematics of the Universal Robots UR5 (and of every arm with
// the same Denavit-Hartenberg structure: UR3, UR10, the e-Series, given their parameters).
//
// Frames: the base frame is the robot's mounting frame (z up along joint 1, origin on the
// mounting flange, the frame of UR's DH tables); the flange frame is frame 6 of the standard DH
// convention, with every joint offset zero (theta_i = q_i). Units: metres and radians.
// Convention: frame_i = frame_{i-1} * Rz(q_i) * Tz(d_i) * Tx(a_i) * Rx(alpha_i).
//
// Inverse kinematics follows the geometric solution of K. P. Hawkins, "Analytic Inverse
// Kinematics for the Universal Robots UR-5/UR-10 Arms" (2013): joint 1 from the wrist centre,
// joint 5 from the height of the flange along joint 2's axis, joint 6 from the orientation,
// then joints 2-4 as a planar two-link arm. Up to 8 solutions (shoulder left/right x wrist
// up/down x elbow up/down).

#include <array>
#include <optional>
#include <vector>

#include "arm/joints.h"
#include "arm/kinematics.h"
#include "world/pose.h"

namespace costar::arm {

/// Standard Denavit-Hartenberg parameters of a six-joint arm: link offsets d and lengths a in
/// metres, twists alpha in radians, joint 1 first.
struct DhParameters {
  std::array<double, 6> d;
  std::array<double, 6> a;
  std::array<double, 6> alpha;
};

struct ChainGeometry;

/// The DH table of a chain written in DH form (robots/ur5/ur5.json): joint 1 at the base frame,
/// joint i+1 (and then the flange) at translation (a_i, 0, d_i) turned by alpha_i about x in
/// joint i's frame, every axis +z. Throws std::invalid_argument naming the joint when the chain
/// has not 6 joints or is not of that form (an origin off the x-z plane, a turn about another
/// axis than x, an axis other than z) or a length is beyond 10 m.
DhParameters dhParametersOf(const ChainGeometry& chain);

/// Forward and analytic inverse kinematics of a UR-structured arm, one implementation of the
/// Kinematics interface. Immutable after construction, so one instance may be shared by
/// threads.
class Ur5Kinematics final : public Kinematics {
 public:
  /// Joints of a UR-structured arm.
  static constexpr int kJointCount = 6;
  /// Most solutions a pose has away from singularities.
  static constexpr int kMaxSolutions = 8;
  /// |sin(q5)| below which the wrist is treated as singular (joint 6's axis parallel to those
  /// of joints 2-4): q6 is then not determined by the pose and takes a chosen value (see
  /// inverse()).
  static constexpr double kWristSingularityThreshold = 1e-10;

  /// Throws std::invalid_argument when `parameters` do not have the UR structure the closed
  /// form relies on: a1 = a4 = a5 = a6 = 0, d2 = d3 = 0, alpha = {pi/2, 0, 0, pi/2, -pi/2, 0},
  /// a2 and a3 non-zero, d6 non-zero, every value finite; or when `limits` are not valid
  /// limits of six joints.
  Ur5Kinematics(DhParameters parameters, JointLimits limits);

  const DhParameters& parameters() const { return parameters_; }

  /// Pose of the flange (frame 6) in the base frame for joint angles `q` (radians, any range;
  /// six of them).
  world::Pose forward(const JointVector& q) const override;

  /// Kinematics::inverse: the solutions of inverse() below, with q6 at a wrist singularity
  /// taken from the seed (seed[5]).
  void inverse(const world::Pose& flange, const JointVector& seed, IkSolutions& solutions) const override;

  /// Every analytic solution for the flange pose `flange` (in the base frame), written to
  /// `solutions[0 .. count)`; returns count, 0 to 8. Does not allocate. Each solution
  /// reproduces the pose to about 1e-12 m and rad away from singularities (the tests require
  /// 1e-9, singular poses included).
  ///
  /// Each angle is in (-pi, pi]; q +/- 2*pi on any joint is the same configuration (see
  /// inverseNearest() to express a solution near a given one). Solutions that coincide at a
  /// singular pose (two branches merging) are returned once.
  /// - Wrist singularity (|sin q5| < kWristSingularityThreshold: joint 6's axis parallel to
  ///   those of joints 2, 3 and 4, a one-parameter family of solutions in which q2, q3, q4 and
  ///   q6 move together): q6 is set to `wrist_singular_q6` (radians) and joints 2-4 make up
  ///   the rest. Where joints 2 and 3 cannot reach with that q6 (the pose near the edge of the
  ///   workspace), q6 is the nearest value with which they can, so a reachable pose always
  ///   gets its solutions.
  /// - Shoulder singularity (the wrist centre at distance |d4| from joint 1's axis): the two
  ///   shoulder branches merge and are returned once.
  /// - Unreachable poses, and a `flange` with non-finite entries: 0 solutions. Poses just
  ///   outside the workspace by rounding (within about 1e-10 m) are solved on its boundary.
  /// Precondition: `flange.linear()` is a rotation matrix (orthonormal, determinant +1).
  int inverse(const world::Pose& flange, std::array<JointVector, kMaxSolutions>& solutions,
              double wrist_singular_q6 = 0.0) const;

  /// As above, returned as a vector (allocates).
  std::vector<JointVector> inverse(const world::Pose& flange, double wrist_singular_q6 = 0.0) const;

  /// The solution for `flange` nearest to `seed` (Euclidean distance in joint space), each
  /// joint expressed as the 2*pi-equivalent angle closest to the seed's (so a solution may lie
  /// outside (-pi, pi] when the seed does). With `limits`, each joint is the equivalent closest
  /// to the seed within [min_position, max_position], and solutions with a joint that has no
  /// equivalent within its limits are discarded. At a wrist singularity q6 stays at the seed's
  /// where the arm can reach so (see inverse()).
  /// Returns nullopt when the pose is unreachable or no solution is within limits.
  /// Throws std::invalid_argument when `seed` has a non-finite entry or not six joints.
  std::optional<JointVector> nearestWithin(const world::Pose& flange, const JointVector& seed,
                                           const JointLimits* limits = nullptr) const;

  /// Kinematics::inverseNearest: nearestWithin(flange, seed, &limits()), among the solutions
  /// that `acceptable` accepts (asked nearest first).
  std::optional<JointVector> inverseNearest(const world::Pose& flange, const JointVector& seed,
                                            const Acceptable& acceptable) const override;
  using Kinematics::inverseNearest;

 private:
  std::optional<JointVector> nearest(const world::Pose& flange, const JointVector& seed, const JointLimits* limits,
                                     const Acceptable* acceptable) const;
  std::optional<double> wristSingularQ6(const Eigen::Vector3d& wrist_centre, const world::Pose& frame_1_to_4_at_zero,
                                        double q5, double preferred) const;

  DhParameters parameters_;
  std::array<double, kJointCount> cos_alpha_;
  std::array<double, kJointCount> sin_alpha_;
};

}  // namespace costar::arm
