#include "planning/collision_world.h"

#include <fcl/fcl.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>

namespace costar::planning {

namespace {

std::shared_ptr<fcl::CollisionGeometryd> geometryOf(const CollisionShape& shape, double padding) {
  switch (shape.kind) {
    case CollisionShape::Kind::kBox:
      return std::make_shared<fcl::Boxd>(shape.size + Eigen::Vector3d::Constant(2 * padding));
    case CollisionShape::Kind::kCylinder:
      return std::make_shared<fcl::Cylinderd>(shape.size.x() + padding, shape.size.y() + 2 * padding);
    case CollisionShape::Kind::kSphere:
      return std::make_shared<fcl::Sphered>(shape.size.x() + padding);
  }
  return nullptr;
}

bool touches(const fcl::CollisionObjectd& a, const fcl::CollisionObjectd& b) {
  // Bounding boxes first (kept current by computeAABB): most pairs are far apart, and the
  // narrow phase on two primitives (GJK/MPR) costs ~50x more.
  if (!a.getAABB().overlap(b.getAABB())) {
    return false;
  }
  fcl::CollisionRequestd request;
  fcl::CollisionResultd result;
  return fcl::collide(&a, &b, request, result) > 0;
}

}  // namespace

AllowedContacts AllowedContacts::between(const std::vector<std::string>& robot_links,
                                         const std::vector<std::string>& obstacles) {
  AllowedContacts allowed;
  for (const std::string& link : robot_links) {
    for (const std::string& obstacle : obstacles) {
      allowed.allow(link, obstacle);
    }
  }
  return allowed;
}

void AllowedContacts::allow(const std::string& robot_link, const std::string& obstacle) {
  if (!contains(robot_link, obstacle)) {
    pairs_.emplace_back(robot_link, obstacle);
  }
}

bool AllowedContacts::contains(std::string_view robot_link, std::string_view obstacle) const {
  return std::any_of(pairs_.begin(), pairs_.end(),
                     [&](const auto& pair) { return pair.first == robot_link && pair.second == obstacle; });
}

namespace {

/// A link's collision objects (FCL), from its shapes.
struct LinkObjects {
  std::vector<CollisionShape> shapes;
  std::vector<std::shared_ptr<fcl::CollisionGeometryd>> geometries;
  std::vector<world::Pose> origins;
  std::vector<std::unique_ptr<fcl::CollisionObjectd>> objects;

  LinkObjects() = default;
  LinkObjects(const std::vector<CollisionShape>& link_shapes, double padding) : shapes(link_shapes) {
    for (const CollisionShape& shape : shapes) {
      geometries.push_back(geometryOf(shape, padding));
      origins.push_back(shape.origin);
    }
    makeObjects();
  }
  /// A copy with objects of its own, on the same geometries (placing it moves nothing else);
  /// without the shapes, which only the world's own keep.
  LinkObjects copy() const {
    LinkObjects other;
    other.geometries = geometries;
    other.origins = origins;
    other.makeObjects();
    return other;
  }
  void makeObjects() {
    objects.clear();
    for (const auto& geometry : geometries) {
      objects.push_back(std::make_unique<fcl::CollisionObjectd>(geometry));
    }
  }
};

/// Puts every link's objects where the robot has them at `q`.
void place(const RobotModel& robot, const world::Pose& base, const Eigen::VectorXd& q, std::vector<LinkObjects>& links,
           std::vector<world::Pose>& poses) {
  robot.linkPoses(q, poses);
  for (std::size_t i = 0; i < links.size(); ++i) {
    for (std::size_t k = 0; k < links[i].objects.size(); ++k) {
      const world::Pose pose = base * poses[i] * links[i].origins[k];
      links[i].objects[k]->setTransform(pose.linear(), pose.translation());
      links[i].objects[k]->computeAABB();
    }
  }
}

bool linksTouch(const LinkObjects& a, const LinkObjects& b) {
  for (const auto& x : a.objects) {
    for (const auto& y : b.objects) {
      if (touches(*x, *y)) {
        return true;
      }
    }
  }
  return false;
}

std::unique_ptr<fcl::CollisionObjectd> boxObject(const world::Pose& pose, const Eigen::Vector3d& size) {
  auto object = std::make_unique<fcl::CollisionObjectd>(std::make_shared<fcl::Boxd>(size));
  object->setTransform(pose.linear(), pose.translation());
  object->computeAABB();
  return object;
}

}  // namespace

struct CollisionWorld::Impl {
  std::vector<LinkObjects> links;  // parallel to robot.links()
  std::map<std::string, std::unique_ptr<fcl::CollisionObjectd>> obstacles;
  std::vector<std::pair<std::size_t, std::size_t>> self_pairs;  // link pairs to check
  std::set<std::pair<std::string, std::string>> allowed;
  world::Pose base = world::Pose::Identity();
};

/// A query's own placed copies of the links (the scene's shapes where it gives them), the
/// obstacles it sees in name order (the world's less those it removes, its own), and what it
/// allows.
struct CollisionWorld::Query::State {
  const CollisionWorld* world = nullptr;
  std::vector<LinkObjects> links;
  std::vector<std::string> own_names;  // the scene's obstacles' (the world's are its map's keys)
  std::vector<std::unique_ptr<fcl::CollisionObjectd>> own_obstacles;
  std::vector<std::pair<std::string_view, const fcl::CollisionObjectd*>> obstacles;  // in name order
  AllowedContacts allowed;
  bool workspace = true;
  std::vector<world::Pose> poses;
};

CollisionWorld::CollisionWorld(const RobotModel& robot, const world::Pose& base_in_world, CollisionOptions options,
                               const std::vector<Eigen::VectorXd>& reference)
    : robot_(robot), options_(options), impl_(std::make_unique<Impl>()) {
  impl_->base = base_in_world;
  for (const LinkGeometry& link : robot.links()) {
    impl_->links.emplace_back(link.shapes, options_.padding);
  }
  // Self-collision pairs: not adjacent, and not touching at any reference configuration.
  std::vector<Eigen::VectorXd> references = reference;
  references.push_back(Eigen::VectorXd::Zero(static_cast<Eigen::Index>(robot.dof())));
  std::vector<world::Pose> poses;
  for (std::size_t a = 0; a < impl_->links.size(); ++a) {
    for (std::size_t b = a + 1; b < impl_->links.size(); ++b) {
      if (robot.adjacent(a, b)) {
        continue;
      }
      bool touching = false;
      for (const auto& q : references) {
        place(robot, impl_->base, q, impl_->links, poses);
        touching = touching || linksTouch(impl_->links[a], impl_->links[b]);
      }
      if (!touching) {
        impl_->self_pairs.emplace_back(a, b);
      }
    }
  }
}

CollisionWorld::~CollisionWorld() = default;

void CollisionWorld::setBox(const std::string& name, const world::Pose& pose, const Eigen::Vector3d& size) {
  impl_->obstacles[name] = boxObject(pose, size);
}

void CollisionWorld::remove(const std::string& name) { impl_->obstacles.erase(name); }

void CollisionWorld::removeAll(const std::string& prefix) {
  std::erase_if(impl_->obstacles, [&prefix](const auto& entry) { return entry.first.starts_with(prefix); });
}

std::vector<std::string> CollisionWorld::obstacleNames() const {
  std::vector<std::string> names;
  for (const auto& [name, object] : impl_->obstacles) {
    names.push_back(name);
  }
  return names;
}

namespace {

std::size_t linkIndex(const RobotModel& robot, const std::string& link) {
  const auto& links = robot.links();
  for (std::size_t i = 0; i < links.size(); ++i) {
    if (links[i].link == link) {
      return i;
    }
  }
  throw std::invalid_argument("the robot has no link '" + link + "' with collision shapes");
}

}  // namespace

void CollisionWorld::setLinkShapes(const std::string& link, const std::vector<CollisionShape>& shapes) {
  const std::size_t index = linkIndex(robot_, link);
  impl_->links[index] = LinkObjects(shapes, options_.padding);
}

const std::vector<CollisionShape>& CollisionWorld::linkShapes(const std::string& link) const {
  return impl_->links[linkIndex(robot_, link)].shapes;
}

void CollisionWorld::allow(const std::string& robot_link, const std::string& obstacle) {
  impl_->allowed.emplace(robot_link, obstacle);
}

void CollisionWorld::disallow(const std::string& robot_link, const std::string& obstacle) {
  impl_->allowed.erase({robot_link, obstacle});
}

void CollisionWorld::disallowAll() { impl_->allowed.clear(); }

CollisionWorld::Query CollisionWorld::query(const QueryScene& scene) const {
  auto state = std::make_unique<Query::State>();
  state->world = this;
  state->allowed = scene.allowed;
  state->workspace = scene.workspace;
  state->links.reserve(impl_->links.size());
  for (const LinkObjects& link : impl_->links) {
    state->links.push_back(link.copy());
  }
  for (const auto& [link, shapes] : scene.link_shapes) {
    state->links[linkIndex(robot_, link)] = LinkObjects(shapes, options_.padding);
  }
  // The obstacles in name order, as the world keeps them: the first contact found, and so the
  // reason a query gives, does not depend on where an obstacle came from.
  const auto listed = [&scene](std::string_view name) {
    return std::find(scene.removed.begin(), scene.removed.end(), name) != scene.removed.end() ||
           std::any_of(scene.obstacles.begin(), scene.obstacles.end(),
                       [name](const BoxObstacle& box) { return box.name == name; });
  };
  state->obstacles.reserve(impl_->obstacles.size() + scene.obstacles.size());
  for (const auto& [name, object] : impl_->obstacles) {
    if (!listed(name)) {
      state->obstacles.emplace_back(name, object.get());
    }
  }
  if (!scene.obstacles.empty()) {
    state->own_names.reserve(scene.obstacles.size());
    for (const BoxObstacle& box : scene.obstacles) {
      state->own_names.push_back(box.name);
      state->own_obstacles.push_back(boxObject(box.pose, box.size));
      state->obstacles.emplace_back(state->own_names.back(), state->own_obstacles.back().get());
    }
    std::stable_sort(state->obstacles.begin(), state->obstacles.end(),
                     [](const auto& a, const auto& b) { return a.first < b.first; });
  }
  return Query(std::move(state));
}

CollisionWorld::Query::Query(std::unique_ptr<State> state) : state_(std::move(state)) {}
CollisionWorld::Query::~Query() = default;
CollisionWorld::Query::Query(Query&&) noexcept = default;

std::optional<Contact> CollisionWorld::Query::check(const Eigen::VectorXd& q) {
  const CollisionWorld& world = *state_->world;
  world.checks_.fetch_add(1, std::memory_order_relaxed);
  if (state_->workspace && world.workspace_ &&
      !world.workspace_->contains((world.impl_->base * world.robot_.forward(q)).translation())) {
    return Contact{"tcp", "the workspace boundary"};
  }
  place(world.robot_, world.impl_->base, q, state_->links, state_->poses);
  const auto& links = world.robot_.links();
  for (std::size_t i = 0; i < state_->links.size(); ++i) {
    for (const auto& [name, obstacle] : state_->obstacles) {
      for (const auto& object : state_->links[i].objects) {
        if (object->getAABB().overlap(obstacle->getAABB()) &&
            !world.impl_->allowed.contains({links[i].link, std::string(name)}) &&
            !state_->allowed.contains(links[i].link, name) && touches(*object, *obstacle)) {
          return Contact{links[i].link, std::string(name)};
        }
      }
    }
  }
  for (const auto& [a, b] : world.impl_->self_pairs) {
    if (linksTouch(state_->links[a], state_->links[b])) {
      return Contact{links[a].link, links[b].link};
    }
  }
  return std::nullopt;
}

std::optional<Contact> CollisionWorld::Query::checkSegment(const Eigen::VectorXd& from, const Eigen::VectorXd& to) {
  const double longest = (to - from).cwiseAbs().maxCoeff();
  const int steps = std::max(1, static_cast<int>(std::ceil(longest / state_->world->options_.resolution)));
  for (int s = 0; s <= steps; ++s) {
    const Eigen::VectorXd q = from + (to - from) * (static_cast<double>(s) / steps);
    if (auto contact = check(q)) {
      return contact;
    }
  }
  return std::nullopt;
}

std::optional<Contact> CollisionWorld::check(const Eigen::VectorXd& q, const QueryScene& scene) const {
  return query(scene).check(q);
}

std::optional<Contact> CollisionWorld::checkSegment(const Eigen::VectorXd& from, const Eigen::VectorXd& to,
                                                    const QueryScene& scene) const {
  return query(scene).checkSegment(from, to);
}

}  // namespace costar::planning
