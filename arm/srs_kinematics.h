#pragma once
// Forward and analytic inverse kinematics of 7-joint S-R-S arms (spherical shoulder, revolute
// elbow, spherical wrist): the KUKA LBR iiwa 14 R820 (robots/iiwa14/iiwa14.json) and, with
// other lengths, the LBR iiwa 7 R800 and other arms of the same form.
//
// Frames: the base frame is the robot's mounting frame (z up along joint 1); at zero angles
// the arm stands straight up, every link frame is parallel to the base frame and the joints
// turn about z, y, z, y, z, y, z (each possibly negated, see SrsGeometry::axis_sign).
// Units: metres and radians.
//
// Inverse kinematics follows the arm-angle method of M. Shimizu, H. Kakuya, W.-K. Yoon,
// K. Kitagaki and K. Kosuge, "Analytical Inverse Kinematic Computation for 7-DOF Redundant
// Manipulators With Joint Limits and Its Application to Redundancy Resolution", IEEE T-RO 24(5),
// 2008. The redundancy is the arm angle psi: the rotation of the shoulder-elbow-wrist plane about
// the shoulder-wrist line, measured from the reference plane in which joint 3 is zero. For one
// pose and one psi there are up to 8 solutions in closed form (signs of joints 2, 4 and 6).
// Each joint angle is a sinusoidal function of psi, so the values of psi at which a joint meets
// a limit are found in closed form too; inverseNearest() uses them to find the feasible arm
// angles exactly instead of sampling them.

#include <Eigen/Core>
#include <array>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "arm/kinematics.h"
#include "world/pose.h"

namespace costar::arm {

/// One value per joint of a 7-joint arm, joint 1 (base) first. Radians.
using Joints7 = Eigen::Matrix<double, 7, 1>;

/// The geometry of an S-R-S arm.
struct SrsGeometry {
  /// Base frame origin to the shoulder (the point where the axes of joints 1-3 meet), along z.
  double base_to_shoulder = 0.0;
  /// Shoulder to elbow (joint 4's axis) and elbow to wrist (where the axes of joints 5-7 meet).
  double shoulder_to_elbow = 0.0;
  double elbow_to_wrist = 0.0;
  /// The flange frame in the frame of link 7 moved to the wrist centre (at zero angles: parallel
  /// to the base frame, origin at the wrist centre). For the iiwa 14: 0.126 m along z.
  world::Pose wrist_to_flange = world::Pose::Identity();
  /// +1 when joint i turns about the canonical axis (z, y, z, y, z, y, z), -1 when about its
  /// negative. The iiwa: {+1, +1, +1, -1, +1, +1, +1}.
  std::array<int, 7> axis_sign = {1, 1, 1, 1, 1, 1, 1};
};

/// Position limits of each joint, radians, lower < upper.
struct SrsLimits {
  Joints7 lower;
  Joints7 upper;

  bool contains(const Joints7& q) const {
    return (q.array() >= lower.array()).all() && (q.array() <= upper.array()).all();
  }
};

/// What a robot description file (robots/NAME/NAME.json, format costar-robot-description/1)
/// says about an S-R-S arm.
struct SrsArmDescription {
  std::string name;
  std::string base_link;
  std::string tool_frame;
  std::array<std::string, 7> joint_names;
  SrsGeometry geometry;
  SrsLimits limits;
  Joints7 max_velocity;  ///< rad/s
  Joints7 max_effort;    ///< N m
  Joints7 home;          ///< rad
};

/// Reads a robot description file and checks that the arm is an S-R-S arm this solver handles
/// (7 joints, link frames along z without rotation, axes z y z y z y z up to sign).
/// @throws std::runtime_error naming the file, the field and the problem.
SrsArmDescription readSrsArmDescription(const std::filesystem::path& file);

/// Forward and analytic inverse kinematics. Immutable after construction: one instance may be
/// shared by threads (the `acceptable` callback of inverseNearest() is the caller's).
class SrsKinematics {
 public:
  static constexpr int kMaxSolutions = 8;
  /// Predicate on a candidate solution, e.g. "free of collisions".
  using Acceptable = std::function<bool(const Joints7&)>;

  /// @throws std::invalid_argument when a length is not positive and finite, an axis sign is
  /// not +/-1, or wrist_to_flange is not a rigid transform.
  explicit SrsKinematics(SrsGeometry geometry);

  const SrsGeometry& geometry() const { return geometry_; }

  /// Pose of the flange in the base frame.
  world::Pose forward(const Joints7& q) const;

  /// The arm angle psi of a configuration, in (-pi, pi]: the inverse of the psi argument of
  /// inverse(). 0 when the elbow lies in the reference plane (joint 3 = 0).
  double armAngle(const Joints7& q) const;

  /// Every solution for the flange pose `flange` at arm angle `psi`, written to
  /// `solutions[0 .. count)`; returns count, 0 to 8. Does not allocate. Angles in (-pi, pi];
  /// joint limits are not applied (see inverseNearest()).
  /// - Branches that coincide are returned once: elbow straight (joint 4 = 0) gives 4
  ///   solutions; joint 2 or joint 6 at 0 (the axes of joints 1 and 3, or 5 and 7, aligned) merge
  ///   two more. At those shoulder and wrist singularities only the sum of the two aligned
  ///   joints is determined: the first of them takes its value in `preferred` (zeros by default)
  ///   and the second the rest.
  /// - Unreachable poses (the wrist centre farther from the shoulder than the upper arm and
  ///   forearm reach, or nearer than their difference) and non-finite poses: 0 solutions.
  ///   Within 1e-10 m of the boundary the pose is solved on it.
  /// Precondition: `flange.linear()` is a rotation matrix.
  int inverse(const world::Pose& flange, double psi, std::array<Joints7, kMaxSolutions>& solutions,
              const Joints7& preferred = Joints7::Zero()) const;
  /// As above, returned as a vector (allocates).
  std::vector<Joints7> inverse(const world::Pose& flange, double psi) const;

  /// A solution for `flange` within `limits` for which `acceptable` (when given) returns true,
  /// near `seed`:
  /// 1. On the seed's branch (signs of joints 2, 4, 6) at the seed's arm angle, when that
  ///    solution is within limits and acceptable. The seed's arm angle for this pose is the one
  ///    at which the shoulder and wrist rotations are nearest the seed's (in closed form); for a
  ///    seed that solves the pose it is the seed's own. The elbow stays where it was, and a small
  ///    pose change gives a small joint change (away from singularities).
  /// 2. Otherwise, on each of the 8 branches, the arm angle nearest the seed's at which every
  ///    joint is within limits (found in closed form), then further arm angles within the
  ///    feasible ranges in steps of 2 degrees until `acceptable` agrees; of those, the solution
  ///    nearest the seed (Euclidean distance in joint space).
  /// Returns nullopt when the pose is unreachable, has no solution within limits, or none that is
  /// acceptable. Each joint is the 2*pi-equivalent within limits closest to the seed's. Does not
  /// allocate (beyond what `acceptable` does). Precondition: `flange.linear()` is a rotation.
  /// @throws std::invalid_argument when `seed` has a non-finite entry.
  std::optional<Joints7> inverseNearest(const world::Pose& flange, const Joints7& seed, const SrsLimits& limits,
                                        const Acceptable& acceptable = {}) const;

  /// Most solutions solutionsWithin() returns.
  static constexpr int kMaxNearSolutions = 16;
  /// Solutions for `flange` within `limits`, near `seed`, for a caller that picks among them
  /// (e.g. the first free of collisions): the seed's branch at the seed's arm angle; on each of
  /// the 8 branches the feasible arm angle nearest the seed's (as inverseNearest() step 2);
  /// then the seed's branch at arm angles 10, 20, 40 and 80 degrees either side of the seed's,
  /// while there is room. Written to `solutions[0 .. count)`, returns count (0 to 16), without
  /// duplicates, unsorted; each joint the 2*pi-equivalent within limits nearest the seed's. Does
  /// not allocate. @throws std::invalid_argument when `seed` has a non-finite entry.
  int solutionsWithin(const world::Pose& flange, const Joints7& seed, const SrsLimits& limits,
                      std::array<Joints7, kMaxNearSolutions>& solutions) const;

 private:
  Joints7 toReal(const Joints7& canonical) const;
  Joints7 toCanonical(const Joints7& real) const;

  SrsGeometry geometry_;
  world::Pose flange_to_wrist_;
};

/// SrsKinematics as the arm's Kinematics (arm/kinematics.h), for the arm component, SmartMove
/// and the planners: 7 joints, the joint limits of the robot description.
/// - inverse(): SrsKinematics::solutionsWithin() (within the position limits, near the seed).
/// - inverseNearest(): SrsKinematics::inverseNearest() (the feasible arm angles in closed
///   form; the caller's predicate sees each candidate).
/// Made by makeKinematics() for "kinematics": {"solver": "srs"} (arm/robot_description.h).
class SrsArmKinematics final : public Kinematics {
 public:
  /// @throws std::invalid_argument when `limits` are not valid limits of 7 joints, or the
  /// geometry is invalid (SrsKinematics).
  SrsArmKinematics(SrsGeometry geometry, JointLimits limits);

  const SrsKinematics& solver() const { return solver_; }

  world::Pose forward(const JointVector& q) const override;
  void inverse(const world::Pose& flange, const JointVector& seed, IkSolutions& solutions) const override;
  std::optional<JointVector> inverseNearest(const world::Pose& flange, const JointVector& seed,
                                            const Acceptable& acceptable) const override;
  using Kinematics::inverseNearest;

 private:
  SrsKinematics solver_;
  SrsLimits srs_limits_;
};

}  // namespace costar::arm
