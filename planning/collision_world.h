#pragma once
// Collision checking of a robot arm (RobotModel) against itself and named obstacles (the
// table, known parts), with FCL. Used to check every motion along its whole path before it
// runs, and by the planner.
//
// The world holds what every query sees (the cell as it is: the table, the known parts, the
// fingers as the gripper reads them), changed only between queries by whoever keeps the cell's
// model. What one query sees besides (contacts it allows, a gripper's fingers at the opening a
// grasp is planned with, a keep-out box, the part held left out) is its QueryScene, an argument:
// nothing is toggled in the world around a query. Queries are const and keep their own placed
// copies of the robot's shapes, so several may run at once while the world does not change.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <atomic>
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

/// A box obstacle (full side lengths) at a pose in the world.
struct BoxObstacle {
  std::string name;
  world::Pose pose = world::Pose::Identity();
  Eigen::Vector3d size = Eigen::Vector3d::Zero();
};

/// What one query sees besides the world's own obstacles, link shapes and allowances.
struct QueryScene {
  QueryScene() = default;
  /// A scene that only allows contacts (implicit: most queries need nothing else).
  QueryScene(AllowedContacts contacts) : allowed(std::move(contacts)) {}  // NOLINT(google-explicit-constructor)

  /// Contacts the query may make.
  AllowedContacts allowed;
  /// Links whose shapes are others in this query (in the link's frame, padded like the others):
  /// a gripper's fingers at the opening a grasp is planned with. Self-collision pairs stay
  /// those chosen when the world was made.
  std::vector<std::pair<std::string, std::vector<CollisionShape>>> link_shapes;
  /// Obstacles only this query has (a keep-out box); one named like an obstacle of the world
  /// stands in its place.
  std::vector<BoxObstacle> obstacles;
  /// Obstacles of the world this query leaves out (the part held); names the world does not
  /// have are ignored.
  std::vector<std::string> removed;
  /// Whether the tool centre point is kept in the world's workspace (setWorkspace); false: a
  /// query about the links alone (free-drive's look-ahead of the arm's links past the tool).
  bool workspace = true;
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
  /// parts that move, such as a gripper's fingers as the cell reads them (a query that plans
  /// them elsewhere says so in its QueryScene). Self-collision pairs stay
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

  /// Collision checks of many configurations in one scene (a plan's): the world as `scene`
  /// changes it, prepared once. It holds its own placed copies of the robot's shapes: queries
  /// may run on several threads at once while the world does not change. The world must
  /// outlive it. @throws std::invalid_argument for a link of scene.link_shapes without shapes.
  class Query {
   public:
    ~Query();
    Query(Query&&) noexcept;
    Query(const Query&) = delete;
    Query& operator=(const Query&) = delete;
    Query& operator=(Query&&) = delete;

    /// The first contact of the robot at `q` that neither the world nor the scene allows, or
    /// nullopt when it is free.
    std::optional<Contact> check(const Eigen::VectorXd& q);
    /// Checks the straight joint-space segment from `from` to `to` at `options.resolution`.
    std::optional<Contact> checkSegment(const Eigen::VectorXd& from, const Eigen::VectorXd& to);

   private:
    friend class CollisionWorld;
    struct State;
    explicit Query(std::unique_ptr<State> state);
    std::unique_ptr<State> state_;
  };
  Query query(const QueryScene& scene = {}) const;

  /// One configuration, or one segment, in `scene` (a Query made for it).
  std::optional<Contact> check(const Eigen::VectorXd& q, const QueryScene& scene = {}) const;
  std::optional<Contact> checkSegment(const Eigen::VectorXd& from, const Eigen::VectorXd& to,
                                      const QueryScene& scene = {}) const;

  const RobotModel& robot() const { return robot_; }
  const CollisionOptions& options() const { return options_; }
  /// Number of configurations checked so far (for benchmarks).
  std::uint64_t checks() const { return checks_.load(std::memory_order_relaxed); }

 private:
  struct Impl;
  const RobotModel& robot_;
  CollisionOptions options_;
  std::unique_ptr<Impl> impl_;
  mutable std::atomic<std::uint64_t> checks_ = 0;
  std::optional<Eigen::AlignedBox3d> workspace_;
};

}  // namespace costar::planning
