#pragma once
// A serial robot arm read from its URDF: the kinematic chain (Orocos KDL, built by
// kdl_parser), joint limits and the collision shapes of every link. This is the general path
// for any arm; the UR5 additionally has a closed-form inverse (arm/ur5_kinematics.h).

#include <Eigen/Core>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "world/pose.h"

namespace costar::planning {

/// A collision primitive in its link's frame.
struct CollisionShape {
  enum class Kind { kBox, kCylinder, kSphere };
  Kind kind = Kind::kBox;
  /// Box: full side lengths; cylinder: (radius, length along z, 0); sphere: (radius, 0, 0).
  Eigen::Vector3d size = Eigen::Vector3d::Zero();
  world::Pose origin = world::Pose::Identity();
};

struct LinkGeometry {
  std::string link;
  std::vector<CollisionShape> shapes;
};

/// An arm's URDF with a tool's URDF mounted on the arm's link `flange_link`: the tool's link
/// "mount" stands for the flange (its shapes are added to the flange link, its joints start
/// there); the tool's other links and joints are added as they are. `label` names the files in
/// messages. @throws std::runtime_error when either is not URDF or lacks those links.
std::string mountUrdf(const std::string& arm, const std::string& tool, const std::string& flange_link,
                      const std::string& label);

class RobotModel {
 public:
  /// Reads the chain from `base_link` to `tip_link` of a URDF file.
  /// @throws std::runtime_error naming the file and the problem.
  static RobotModel fromUrdf(const std::filesystem::path& urdf, const std::string& base_link,
                             const std::string& tip_link);
  /// The same for an arm with a tool mounted on its flange (mountUrdf()): e.g. the arm's URDF
  /// and its gripper's, the tip the gripper's tool centre point.
  static RobotModel fromUrdf(const std::filesystem::path& arm, const std::filesystem::path& tool,
                             const std::string& flange_link, const std::string& base_link, const std::string& tip_link);
  /// From URDF text; `path` names it in messages.
  static RobotModel fromUrdfText(const std::string& urdf, const std::filesystem::path& path,
                                 const std::string& base_link, const std::string& tip_link);
  RobotModel(RobotModel&&) noexcept;
  RobotModel& operator=(RobotModel&&) noexcept;
  ~RobotModel();

  std::size_t dof() const;
  const std::vector<std::string>& jointNames() const;
  const Eigen::VectorXd& lowerLimits() const;
  const Eigen::VectorXd& upperLimits() const;
  const Eigen::VectorXd& velocityLimits() const;

  /// Pose of the tip link in the base link's frame. @pre q.size() == dof()
  world::Pose forward(const Eigen::VectorXd& q) const;
  /// Every link with collision shapes, in chain order.
  const std::vector<LinkGeometry>& links() const;
  /// Poses (in the base frame) of links(), same order. @pre q.size() == dof()
  void linkPoses(const Eigen::VectorXd& q, std::vector<world::Pose>& poses) const;
  /// Index in links() of the link whose parent link is the previous entry, for adjacency.
  bool adjacent(std::size_t a, std::size_t b) const;

  /// Numeric inverse kinematics (KDL's Levenberg–Marquardt solver) from `seed`, then from
  /// `restarts` random seeds drawn with `random_seed`; solutions within the joint limits only.
  std::optional<Eigen::VectorXd> inverse(const world::Pose& tip_in_base, const Eigen::VectorXd& seed, int restarts,
                                         std::uint64_t random_seed) const;

 private:
  struct Impl;
  explicit RobotModel(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace costar::planning
