#pragma once
// Collision checking of a robot arm (RobotModel) against itself and named obstacles (the
// table, known parts), with FCL. Used to check every motion along its whole path before it
// runs, and by the planner.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "planning/robot_model.h"
#include "world/pose.h"

namespace costar::planning {

/// What touches what, for a reason a user can read.
struct Contact {
  std::string robot_link;
  std::string other;  // an obstacle's name, or another robot link
  std::string str() const { return robot_link + " would touch " + other; }
};

/// Contacts one query allows, on top of the world's own (allow()): a gripper's links may touch
/// the part it is grasping while that grasp is planned. Passed to each query, never stored in
/// the world, so that a query cannot leave an allowance behind for the next one.
class AllowedContacts {
 public:
  AllowedContacts() = default;
  /// Every link of `robot_links` may touch every obstacle of `obstacles`.
  static AllowedContacts between(const std::vector<std::string>& robot_links,
                                 const std::vector<std::string>& obstacles);
  void allow(const std::string& robot_link, const std::string& obstacle);
  bool contains(std::string_view robot_link, std::string_view obstacle) const;
  bool empty() const { return pairs_.empty(); }

 private:
  std::vector<std::pair<std::string, std::string>> pairs_;
};

struct CollisionOptions {
  /// Robot shapes are inflated by this much (m) so that tracking errors keep a margin.
  double padding = 0.01;
  /// Largest joint step (rad) between the configurations checked along a segment.
  double resolution = 0.01;
};

class CollisionWorld {
 public:
  /// `base_in_world`: where the robot's base frame is. The robot model must outlive this.
  /// Self-collision pairs that touch at `reference` configurations (e.g. home) or are
  /// adjacent in the chain are not checked, like MoveIt's set-up assistant does.
  CollisionWorld(const RobotModel& robot, const world::Pose& base_in_world, CollisionOptions options = {},
                 const std::vector<Eigen::VectorXd>& reference = {});
  ~CollisionWorld();
  CollisionWorld(const CollisionWorld&) = delete;
  CollisionWorld& operator=(const CollisionWorld&) = delete;

  /// Adds or replaces a box obstacle (full side lengths) at a pose in the world.
  void setBox(const std::string& name, const world::Pose& pose, const Eigen::Vector3d& size);
  void remove(const std::string& name);
  /// Removes every obstacle whose name starts with `prefix`.
  void removeAll(const std::string& prefix = "");
  std::vector<std::string> obstacleNames() const;

  /// Keeps the robot's tip (the tool centre point) inside `box` (world frame): a configuration
  /// with the tip outside is reported as "tcp would leave the workspace".
  void setWorkspace(const Eigen::AlignedBox3d& box) { workspace_ = box; }

  /// Replaces the collision shapes of a robot link (in its frame, padded like the others): for
  /// parts that move, such as a gripper's fingers at their opening. Self-collision pairs stay
  /// those chosen at construction. @throws std::invalid_argument for a link without shapes.
  void setLinkShapes(const std::string& link, const std::vector<CollisionShape>& shapes);
  /// The link's shapes now (as read from the robot model, or as last set).
  /// @throws std::invalid_argument for a link without shapes.
  const std::vector<CollisionShape>& linkShapes(const std::string& link) const;

  /// Lets `robot_link` touch `obstacle` in every query, e.g. the robot's base and the table it
  /// stands on (what one query allows: AllowedContacts).
  void allow(const std::string& robot_link, const std::string& obstacle);
  void disallow(const std::string& robot_link, const std::string& obstacle);
  void disallowAll();

  /// The first contact of the robot at `q` that neither the world nor `allowed` allows, or
  /// nullopt when it is free.
  std::optional<Contact> check(const Eigen::VectorXd& q, const AllowedContacts& allowed = {}) const;
  /// Checks the straight joint-space segment from `from` to `to` at `options.resolution`.
  std::optional<Contact> checkSegment(const Eigen::VectorXd& from, const Eigen::VectorXd& to,
                                      const AllowedContacts& allowed = {}) const;

  const RobotModel& robot() const { return robot_; }
  const CollisionOptions& options() const { return options_; }
  /// Number of configurations checked so far (for benchmarks).
  std::uint64_t checks() const { return checks_; }

 private:
  struct Impl;
  const RobotModel& robot_;
  CollisionOptions options_;
  std::unique_ptr<Impl> impl_;
  mutable std::uint64_t checks_ = 0;
  std::optional<Eigen::AlignedBox3d> workspace_;
};

}  // namespace costar::planning
