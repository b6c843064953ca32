#include "planning/robot_model.h"

#include <urdf_parser/urdf_parser.h>

#include <kdl/chain.hpp>
#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/chainiksolverpos_lma.hpp>
#include <kdl/tree.hpp>
#include <kdl_parser/kdl_parser.hpp>
#include <pugixml.hpp>

#include <array>
#include <atomic>
#include <fstream>
#include <map>
#include <mutex>
#include <random>
#include <sstream>
#include <stdexcept>

namespace costar::planning {

namespace {

world::Pose toPose(const KDL::Frame& frame) {
  world::Pose pose = world::Pose::Identity();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      pose.linear()(r, c) = frame.M(r, c);
    }
    pose.translation()[r] = frame.p[r];
  }
  return pose;
}

KDL::Frame toFrame(const world::Pose& pose) {
  const auto& r = pose.linear();
  const auto& t = pose.translation();
  return KDL::Frame(KDL::Rotation(r(0, 0), r(0, 1), r(0, 2), r(1, 0), r(1, 1), r(1, 2), r(2, 0), r(2, 1), r(2, 2)),
                    KDL::Vector(t.x(), t.y(), t.z()));
}

world::Pose toPose(const urdf::Pose& origin) {
  world::Pose pose = world::Pose::Identity();
  pose.translation() = Eigen::Vector3d(origin.position.x, origin.position.y, origin.position.z);
  pose.linear() = Eigen::Quaterniond(origin.rotation.w, origin.rotation.x, origin.rotation.y, origin.rotation.z)
                      .normalized()
                      .toRotationMatrix();
  return pose;
}

}  // namespace

/// KDL 1.5's joints cache their last pose in mutable members (kdl/joint.hpp: `q_previous`,
/// `joint_pose`), so one chain evaluated on two threads at once races: a thread can take the
/// other's joint pose (collision queries on two threads reported contacts one thread did not).
/// Each thread evaluates the forward kinematics on a copy of its own, a few per thread kept.
class ThreadChains {
 public:
  struct Copy {
    explicit Copy(const KDL::Chain& original) : chain(original), fk(chain) {}
    KDL::Chain chain;
    KDL::ChainFkSolverPos_recursive fk;  // refers to `chain`, so the copy does not move
  };

  explicit ThreadChains(const KDL::Chain& chain) : chain_(chain), id_(next_id_.fetch_add(1)) {}

  /// This thread's solver for the chain.
  KDL::ChainFkSolverPos_recursive& fk() const {
    struct Slot {
      std::uint64_t id = 0;
      std::unique_ptr<Copy> copy;
    };
    thread_local std::array<Slot, 8> slots;  // ids start at 1: 0 is a free slot
    thread_local std::size_t next = 0;
    for (Slot& slot : slots) {
      if (slot.id == id_) {
        return slot.copy->fk;
      }
    }
    Slot& slot = slots[next];  // the oldest is replaced
    next = (next + 1) % slots.size();
    slot.copy = std::make_unique<Copy>(chain_);
    slot.id = id_;
    return slot.copy->fk;
  }

 private:
  const KDL::Chain& chain_;
  std::uint64_t id_;  // unique for the process's life, unlike an address
  static inline std::atomic<std::uint64_t> next_id_ = 1;
};

struct RobotModel::Impl {
  KDL::Chain chain;  // never evaluated, only copied: its joints' caches are never written
  std::unique_ptr<ThreadChains> fk;
  KDL::Chain ik_chain;  // the inverse solver's own
  std::unique_ptr<KDL::ChainIkSolverPos_LMA> ik;
  std::mutex ik_mutex;  // the solver keeps its work in itself: one thread at a time
  std::vector<std::string> joint_names;
  Eigen::VectorXd lower, upper, velocity;
  std::vector<LinkGeometry> links;
  std::vector<int> link_segment;  // KDL segment index whose tip is the link (-1: the base)
  std::vector<int> link_parent;   // index in links of the parent link with geometry, or -1
};

RobotModel::RobotModel(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
RobotModel::RobotModel(RobotModel&&) noexcept = default;
RobotModel& RobotModel::operator=(RobotModel&&) noexcept = default;
RobotModel::~RobotModel() = default;

namespace {

std::string readUrdf(const std::filesystem::path& path) {
  std::ifstream stream(path);
  if (!stream) {
    throw std::runtime_error("cannot open URDF '" + path.string() + "'");
  }
  std::stringstream text;
  text << stream.rdbuf();
  return text.str();
}

}  // namespace

RobotModel RobotModel::fromUrdf(const std::filesystem::path& path, const std::string& base_link,
                                const std::string& tip_link) {
  return fromUrdfText(readUrdf(path), path, base_link, tip_link);
}

RobotModel RobotModel::fromUrdf(const std::filesystem::path& arm, const std::filesystem::path& tool,
                                const std::string& flange_link, const std::string& base_link,
                                const std::string& tip_link) {
  const std::string label = arm.string() + "' + '" + tool.string();
  return fromUrdfText(mountUrdf(readUrdf(arm), readUrdf(tool), flange_link, label), label, base_link, tip_link);
}

std::string mountUrdf(const std::string& arm, const std::string& tool, const std::string& flange_link,
                      const std::string& label) {
  pugi::xml_document arm_doc;
  pugi::xml_document tool_doc;
  if (!arm_doc.load_string(arm.c_str()) || !tool_doc.load_string(tool.c_str())) {
    throw std::runtime_error("URDF '" + label + "' cannot be parsed");
  }
  pugi::xml_node robot = arm_doc.child("robot");
  const pugi::xml_node tool_robot = tool_doc.child("robot");
  pugi::xml_node flange = robot.find_child_by_attribute("link", "name", flange_link.c_str());
  const pugi::xml_node mount = tool_robot.find_child_by_attribute("link", "name", "mount");
  if (!robot || !tool_robot || !flange || !mount) {
    throw std::runtime_error("URDF '" + label + "': the arm needs a link '" + flange_link +
                             "' (its flange) and the tool a link 'mount'");
  }
  for (const pugi::xml_node child : mount.children()) {
    flange.append_copy(child);
  }
  for (const pugi::xml_node child : tool_robot.children()) {
    if (child == mount || child.type() != pugi::node_element) {
      continue;
    }
    pugi::xml_node copy = robot.append_copy(child);
    if (std::string(copy.name()) == "joint") {
      pugi::xml_attribute parent = copy.child("parent").attribute("link");
      if (std::string(parent.value()) == "mount") {
        parent.set_value(flange_link.c_str());
      }
    }
  }
  std::ostringstream out;
  arm_doc.save(out, "  ");
  return out.str();
}

RobotModel RobotModel::fromUrdfText(const std::string& urdf_text, const std::filesystem::path& path,
                                    const std::string& base_link, const std::string& tip_link) {
  std::stringstream text;
  text << urdf_text;
  const urdf::ModelInterfaceSharedPtr model = urdf::parseURDF(text.str());
  if (!model) {
    throw std::runtime_error("URDF '" + path.string() + "' cannot be parsed");
  }
  KDL::Tree tree;
  if (!kdl_parser::treeFromString(text.str(), tree)) {
    throw std::runtime_error("kdl_parser cannot build a tree from '" + path.string() + "'");
  }
  auto impl = std::make_unique<Impl>();
  if (!tree.getChain(base_link, tip_link, impl->chain)) {
    throw std::runtime_error("URDF '" + path.string() + "' has no chain from '" + base_link + "' to '" + tip_link +
                             "'");
  }
  const unsigned joints = impl->chain.getNrOfJoints();
  impl->lower.resize(joints);
  impl->upper.resize(joints);
  impl->velocity.resize(joints);
  // Links along the chain, base first, with their collision shapes and joint limits.
  std::vector<std::pair<std::string, int>> chain_links{{base_link, -1}};
  for (unsigned i = 0; i < impl->chain.getNrOfSegments(); ++i) {
    const KDL::Segment& segment = impl->chain.getSegment(i);
    chain_links.emplace_back(segment.getName(), static_cast<int>(i));
    if (segment.getJoint().getType() != KDL::Joint::None) {
      const auto joint = model->getJoint(segment.getJoint().getName());
      const std::size_t index = impl->joint_names.size();
      impl->joint_names.push_back(segment.getJoint().getName());
      if (!joint || !joint->limits) {
        throw std::runtime_error("URDF '" + path.string() + "': joint '" + segment.getJoint().getName() +
                                 "' has no limits");
      }
      impl->lower[index] = joint->limits->lower;
      impl->upper[index] = joint->limits->upper;
      impl->velocity[index] = joint->limits->velocity;
    }
  }
  int previous = -1;
  for (const auto& [link_name, segment] : chain_links) {
    const auto link = model->getLink(link_name);
    if (!link) {
      continue;
    }
    LinkGeometry geometry{link_name, {}};
    for (const auto& collision : link->collision_array) {
      if (!collision || !collision->geometry) {
        continue;
      }
      CollisionShape shape;
      shape.origin = toPose(collision->origin);
      switch (collision->geometry->type) {
        case urdf::Geometry::BOX: {
          const auto* box = static_cast<const urdf::Box*>(collision->geometry.get());
          shape.kind = CollisionShape::Kind::kBox;
          shape.size = Eigen::Vector3d(box->dim.x, box->dim.y, box->dim.z);
          break;
        }
        case urdf::Geometry::CYLINDER: {
          const auto* cylinder = static_cast<const urdf::Cylinder*>(collision->geometry.get());
          shape.kind = CollisionShape::Kind::kCylinder;
          shape.size = Eigen::Vector3d(cylinder->radius, cylinder->length, 0);
          break;
        }
        case urdf::Geometry::SPHERE: {
          const auto* sphere = static_cast<const urdf::Sphere*>(collision->geometry.get());
          shape.kind = CollisionShape::Kind::kSphere;
          shape.size = Eigen::Vector3d(sphere->radius, 0, 0);
          break;
        }
        default:
          throw std::runtime_error("URDF '" + path.string() + "': link '" + link_name +
                                   "' has a collision mesh; only boxes, cylinders and spheres are supported");
      }
      geometry.shapes.push_back(shape);
    }
    if (!geometry.shapes.empty()) {
      impl->links.push_back(std::move(geometry));
      impl->link_segment.push_back(segment);
      impl->link_parent.push_back(previous);
      previous = static_cast<int>(impl->links.size()) - 1;
    }
  }
  impl->fk = std::make_unique<ThreadChains>(impl->chain);
  impl->ik_chain = impl->chain;
  impl->ik = std::make_unique<KDL::ChainIkSolverPos_LMA>(impl->ik_chain, 1e-6, 500);
  return RobotModel(std::move(impl));
}

std::size_t RobotModel::dof() const { return impl_->joint_names.size(); }
const std::vector<std::string>& RobotModel::jointNames() const { return impl_->joint_names; }
const Eigen::VectorXd& RobotModel::lowerLimits() const { return impl_->lower; }
const Eigen::VectorXd& RobotModel::upperLimits() const { return impl_->upper; }
const Eigen::VectorXd& RobotModel::velocityLimits() const { return impl_->velocity; }
const std::vector<LinkGeometry>& RobotModel::links() const { return impl_->links; }

world::Pose RobotModel::forward(const Eigen::VectorXd& q) const {
  // Local joint and frame values and this thread's chain: several threads may ask at once.
  KDL::JntArray joints;
  joints.data = q;
  KDL::Frame frame;
  impl_->fk->fk().JntToCart(joints, frame);
  return toPose(frame);
}

void RobotModel::linkPoses(const Eigen::VectorXd& q, std::vector<world::Pose>& poses) const {
  KDL::JntArray joints;
  joints.data = q;
  KDL::Frame frame;
  KDL::ChainFkSolverPos_recursive& fk = impl_->fk->fk();
  poses.resize(impl_->links.size());
  for (std::size_t i = 0; i < impl_->links.size(); ++i) {
    const int segment = impl_->link_segment[i];
    if (segment < 0) {
      poses[i] = world::Pose::Identity();
    } else {
      fk.JntToCart(joints, frame, segment + 1);
      poses[i] = toPose(frame);
    }
  }
}

bool RobotModel::adjacent(std::size_t a, std::size_t b) const {
  return impl_->link_parent[a] == static_cast<int>(b) || impl_->link_parent[b] == static_cast<int>(a);
}

std::optional<Eigen::VectorXd> RobotModel::inverse(const world::Pose& target, const Eigen::VectorXd& seed, int restarts,
                                                   std::uint64_t random_seed) const {
  const KDL::Frame goal = toFrame(target);
  std::mt19937_64 random(random_seed);
  KDL::JntArray start(static_cast<unsigned>(dof()));
  KDL::JntArray result(static_cast<unsigned>(dof()));
  const std::lock_guard lock(impl_->ik_mutex);
  for (int attempt = 0; attempt <= restarts; ++attempt) {
    if (attempt == 0) {
      start.data = seed;
    } else {
      for (std::size_t j = 0; j < dof(); ++j) {
        std::uniform_real_distribution<double> angle(std::max(impl_->lower[j], -M_PI), std::min(impl_->upper[j], M_PI));
        start(j) = angle(random);
      }
    }
    if (impl_->ik->CartToJnt(start, goal, result) >= 0) {
      const Eigen::VectorXd q = result.data;
      if ((q.array() >= impl_->lower.array()).all() && (q.array() <= impl_->upper.array()).all()) {
        return q;
      }
    }
  }
  return std::nullopt;
}

}  // namespace costar::planning
