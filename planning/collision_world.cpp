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

struct CollisionWorld::Impl {
  struct LinkObjects {
    std::vector<CollisionShape> shapes;
    std::vector<std::unique_ptr<fcl::CollisionObjectd>> objects;
    std::vector<world::Pose> origins;

    void set(const std::vector<CollisionShape>& new_shapes, double padding) {
      shapes = new_shapes;
      objects.clear();
      origins.clear();
      for (const CollisionShape& shape : shapes) {
        objects.push_back(std::make_unique<fcl::CollisionObjectd>(geometryOf(shape, padding)));
        origins.push_back(shape.origin);
      }
    }
  };
  std::vector<LinkObjects> links;  // parallel to robot.links()
  std::map<std::string, std::unique_ptr<fcl::CollisionObjectd>> obstacles;
  std::vector<std::pair<std::size_t, std::size_t>> self_pairs;  // link pairs to check
  std::set<std::pair<std::string, std::string>> allowed;
  world::Pose base = world::Pose::Identity();
  mutable std::vector<world::Pose> poses;

  void place(const RobotModel& robot, const Eigen::VectorXd& q) const {
    robot.linkPoses(q, poses);
    for (std::size_t i = 0; i < links.size(); ++i) {
      for (std::size_t k = 0; k < links[i].objects.size(); ++k) {
        const world::Pose pose = base * poses[i] * links[i].origins[k];
        links[i].objects[k]->setTransform(pose.linear(), pose.translation());
        links[i].objects[k]->computeAABB();
      }
    }
  }

  bool linksTouch(std::size_t a, std::size_t b) const {
    for (const auto& x : links[a].objects) {
      for (const auto& y : links[b].objects) {
        if (touches(*x, *y)) {
          return true;
        }
      }
    }
    return false;
  }
};

CollisionWorld::CollisionWorld(const RobotModel& robot, const world::Pose& base_in_world, CollisionOptions options,
                               const std::vector<Eigen::VectorXd>& reference)
    : robot_(robot), options_(options), impl_(std::make_unique<Impl>()) {
  impl_->base = base_in_world;
  for (const LinkGeometry& link : robot.links()) {
    Impl::LinkObjects objects;
    objects.set(link.shapes, options_.padding);
    impl_->links.push_back(std::move(objects));
  }
  // Self-collision pairs: not adjacent, and not touching at any reference configuration.
  std::vector<Eigen::VectorXd> references = reference;
  references.push_back(Eigen::VectorXd::Zero(static_cast<Eigen::Index>(robot.dof())));
  for (std::size_t a = 0; a < impl_->links.size(); ++a) {
    for (std::size_t b = a + 1; b < impl_->links.size(); ++b) {
      if (robot.adjacent(a, b)) {
        continue;
      }
      bool touching = false;
      for (const auto& q : references) {
        impl_->place(robot, q);
        touching = touching || impl_->linksTouch(a, b);
      }
      if (!touching) {
        impl_->self_pairs.emplace_back(a, b);
      }
    }
  }
}

CollisionWorld::~CollisionWorld() = default;

void CollisionWorld::setBox(const std::string& name, const world::Pose& pose, const Eigen::Vector3d& size) {
  auto object = std::make_unique<fcl::CollisionObjectd>(std::make_shared<fcl::Boxd>(size));
  object->setTransform(pose.linear(), pose.translation());
  object->computeAABB();
  impl_->obstacles[name] = std::move(object);
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
  impl_->links[linkIndex(robot_, link)].set(shapes, options_.padding);
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

std::optional<Contact> CollisionWorld::check(const Eigen::VectorXd& q, const AllowedContacts& allowed) const {
  ++checks_;
  if (workspace_ && !workspace_->contains((impl_->base * robot_.forward(q)).translation())) {
    return Contact{"tcp", "the workspace boundary"};
  }
  impl_->place(robot_, q);
  const auto& links = robot_.links();
  for (std::size_t i = 0; i < impl_->links.size(); ++i) {
    for (const auto& [name, obstacle] : impl_->obstacles) {
      for (const auto& object : impl_->links[i].objects) {
        if (object->getAABB().overlap(obstacle->getAABB()) && !impl_->allowed.contains({links[i].link, name}) &&
            !allowed.contains(links[i].link, name) && touches(*object, *obstacle)) {
          return Contact{links[i].link, name};
        }
      }
    }
  }
  for (const auto& [a, b] : impl_->self_pairs) {
    if (impl_->linksTouch(a, b)) {
      return Contact{links[a].link, links[b].link};
    }
  }
  return std::nullopt;
}

std::optional<Contact> CollisionWorld::checkSegment(const Eigen::VectorXd& from, const Eigen::VectorXd& to,
                                                    const AllowedContacts& allowed) const {
  const double longest = (to - from).cwiseAbs().maxCoeff();
  const int steps = std::max(1, static_cast<int>(std::ceil(longest / options_.resolution)));
  for (int s = 0; s <= steps; ++s) {
    const Eigen::VectorXd q = from + (to - from) * (static_cast<double>(s) / steps);
    if (auto contact = check(q, allowed)) {
      return contact;
    }
  }
  return std::nullopt;
}

}  // namespace costar::planning
