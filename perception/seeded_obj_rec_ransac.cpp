#include "perception/seeded_obj_rec_ransac.h"

#include "perception/transform_votes.h"

#include <pcl/recognition/ransac_based/obj_rec_ransac.h>

#include <Eigen/SVD>
#include <algorithm>
#include <array>
#include <cmath>
#include <list>
#include <random>
#include <stdexcept>
#include <string>

namespace costar::perception {

namespace {

using pcl::recognition::ModelLibrary;
using pcl::recognition::ORROctree;
using pcl::recognition::ORROctreeZProjection;

/// The protected parts of PCL's ModelLibrary that adding a model uses, reached through the
/// library's own type (no copy of its code): the models, and the hash table of point pairs.
class LibraryAccess final : public ModelLibrary {
 public:
  static std::map<std::string, Model*>& models(ModelLibrary& library) { return library.*(&LibraryAccess::models_); }
  static bool addPair(ModelLibrary& library, Model* model, const ORROctree::Node::Data* a,
                      const ORROctree::Node::Data* b) {
    return (library.*(&LibraryAccess::addToHashTable))(model, a, b);
  }
};

/// PCL 1.13's ORROctreeZProjection::build() writes each leaf's pixel coordinates into its own
/// num_pixels_x_ / num_pixels_y_, so the clear() that the next build() starts with frees only
/// some of the rows, pixels and sets it allocated: about 2 KB lost per pose estimation, 0.2 MB
/// per trial of the assembly (found with heaptrack in a soak). release() frees everything
/// build() allocated, by the lists it keeps of them and the row count it computed, and leaves
/// the projection empty; recognition between two builds is untouched.
class ProjectionRelease final : public ORROctreeZProjection {
 public:
  static void release(ORROctreeZProjection& projection) {
    auto& pixels = projection.*(&ProjectionRelease::pixels_);
    auto& sets = projection.*(&ProjectionRelease::sets_);
    auto& full_pixels = projection.*(&ProjectionRelease::full_pixels_);
    auto& full_sets = projection.*(&ProjectionRelease::full_sets_);
    for (Pixel* pixel : full_pixels) {
      delete pixel;
    }
    for (Set* set : full_sets) {
      delete set;
    }
    full_pixels.clear();
    full_sets.clear();
    if (pixels != nullptr) {
      // The row count as build() computed it (the same float expression).
      const float extent_x = projection.*(&ProjectionRelease::extent_x_);
      const float pixel_size = projection.*(&ProjectionRelease::pixel_size_);
      const int rows = static_cast<int>(extent_x / pixel_size + 0.5f);
      for (int i = 0; i < rows; ++i) {
        delete[] pixels[i];
        delete[] sets[i];
      }
      delete[] pixels;
      delete[] sets;
      pixels = nullptr;
      sets = nullptr;
    }
    projection.*(&ProjectionRelease::num_pixels_x_) = 0;
    projection.*(&ProjectionRelease::num_pixels_y_) = 0;
  }
};

world::Pose poseFromArray12(const float* t) {
  world::Pose pose = world::Pose::Identity();
  Eigen::Matrix3d r;
  r << t[0], t[1], t[2], t[3], t[4], t[5], t[6], t[7], t[8];
  // Re-orthonormalize (the array is single precision).
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(r, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d rotation = svd.matrixU() * svd.matrixV().transpose();
  if (rotation.determinant() < 0) {
    Eigen::Matrix3d u = svd.matrixU();
    u.col(2) *= -1;
    rotation = u * svd.matrixV().transpose();
  }
  pose.linear() = rotation;
  pose.translation() = Eigen::Vector3d(t[9], t[10], t[11]);
  return pose;
}

void toPcl(const std::vector<Eigen::Vector3f>& points, const std::vector<Eigen::Vector3f>& normals,
           pcl::PointCloud<pcl::PointXYZ>& pcl_points, pcl::PointCloud<pcl::Normal>& pcl_normals) {
  pcl_points.reserve(points.size());
  pcl_normals.reserve(normals.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    pcl_points.push_back(pcl::PointXYZ(points[i].x(), points[i].y(), points[i].z()));
    pcl_normals.push_back(pcl::Normal(normals[i].x(), normals[i].y(), normals[i].z()));
  }
}

}  // namespace

/// PCL's ObjRecRANSAC for its parameters, octrees and pose arithmetic; the steps that PCL's
/// compiled library would print from are done here on the same structures.
class SeededObjRecRansac::Recognizer final : public pcl::recognition::ObjRecRANSAC {
 public:
  Recognizer(const std::vector<Eigen::Vector3f>& points, const std::vector<Eigen::Vector3f>& normals,
             const Parameters& parameters)
      : ObjRecRANSAC(parameters.pair_width, parameters.voxel_size) {
    // Our own ICP follows the candidates; PCL's samples its points with a time-seeded generator.
    icpHypothesesRefinementOff();
    visibility_ = parameters.visibility;
    relative_num_of_illegal_pts_ = parameters.penalty_fraction;
    // Per-cluster scenes are tight around the objects: keep hypotheses whose model centre lies
    // outside the seen part (see DEPENDENCIES.md).
    setSceneBoundsEnlargementFactor(parameters.scene_bounds_enlargement);
    hashModel(points, normals);
  }
  ~Recognizer() override { ProjectionRelease::release(scene_octree_proj_); }
  Recognizer(const Recognizer&) = delete;
  Recognizer& operator=(const Recognizer&) = delete;

  std::vector<Candidate> candidates(const std::vector<Eigen::Vector3f>& points,
                                    const std::vector<Eigen::Vector3f>& normals, double success_probability,
                                    float relative_object_size, std::uint32_t seed) {
    std::vector<Candidate> out;
    PointCloudIn scene;
    PointCloudN scene_normals;
    toPcl(points, normals, scene, scene_normals);
    relative_obj_size_ = relative_object_size;
    clearTestData();
    scene_octree_.build(scene, voxel_size_, &scene_normals);
    ProjectionRelease::release(scene_octree_proj_);
    scene_octree_proj_.build(scene_octree_, abs_zdist_thresh_, abs_zdist_thresh_);
    std::vector<ORROctree::Node*>& leaves = scene_octree_.getFullLeaves();
    if (leaves.size() < 2) {
      return out;
    }
    const int iterations =
        std::min(computeNumberOfIterations(std::min(success_probability, 0.999)), static_cast<int>(leaves.size()));
    std::mt19937 random(seed);
    samplePairs(iterations, leaves, random);
    std::list<pcl::recognition::HypothesisBase> hypotheses;
    hypothesesFromPairs(hypotheses);
    HypothesisOctree grouped;
    group(hypotheses, grouped);
    for (const auto* leaf : grouped.getFullLeaves()) {
      const pcl::recognition::Hypothesis& hypothesis = leaf->getData();
      out.push_back({poseFromArray12(hypothesis.rigid_transform_), hypothesis.match_confidence_});
    }
    clearTestData();
    return out;
  }

  std::size_t modelLeaves() const { return model_->getOctree().getFullLeaves().size(); }

 private:
  /// The model in ObjRecRANSAC's model library: its octree, and every pair of its leaves
  /// pair_width apart in the library's hash table (by their normals' angles), co-planar pairs
  /// left out, as ModelLibrary::addModel does.
  void hashModel(const std::vector<Eigen::Vector3f>& points, const std::vector<Eigen::Vector3f>& normals) {
    PointCloudIn model_points;
    PointCloudN model_normals;
    toPcl(points, normals, model_points, model_normals);
    // No points for PCL's own ICP (off): the model samples none with its time-seeded generator.
    auto model = std::make_unique<ModelLibrary::Model>(model_points, model_normals, voxel_size_, "model", 0.0f);
    const ORROctree& octree = model->getOctree();
    if (octree.getFullLeaves().empty()) {
      throw std::invalid_argument("the model has no points in ObjRecRANSAC's octree");
    }
    ModelLibrary::Model* added = model.release();
    LibraryAccess::models(model_library_)["model"] = added;  // the library deletes it
    model_ = added;
    std::list<ORROctree::Node*> partners;
    for (const ORROctree::Node* leaf : octree.getFullLeaves()) {
      partners.clear();
      octree.getFullLeavesIntersectedBySphere(leaf->getData()->getPoint(), pair_width_, partners);
      for (const ORROctree::Node* partner : partners) {
        LibraryAccess::addPair(model_library_, added, leaf->getData(), partner->getData());
      }
    }
  }

  /// A leaf of the scene octree at `radius` from `p` (ORROctree::getRandomFullLeafOnSphere with
  /// our generator).
  ORROctree::Node* randomLeafOnSphere(const float* p, float radius, std::mt19937& random) {
    std::vector<ORROctree::Node*> stack{scene_octree_.getRoot()};
    std::array<int, 8> order{};
    while (!stack.empty()) {
      ORROctree::Node* node = stack.back();
      stack.pop_back();
      if (std::fabs(radius - pcl::recognition::aux::distance3<float>(p, node->getCenter())) > node->getRadius()) {
        continue;
      }
      if (node->hasChildren()) {
        for (int i = 0; i < 8; ++i) {
          order[static_cast<std::size_t>(i)] = i;
        }
        std::shuffle(order.begin(), order.end(), random);
        for (const int child : order) {
          stack.push_back(node->getChild(child));
        }
      } else if (node->hasData()) {
        return node;
      }
    }
    return nullptr;
  }

  /// Oriented point pairs of the scene, pair_width apart, co-planar ones left out
  /// (ObjRecRANSAC::sampleOrientedPointPairs with our generator).
  void samplePairs(int iterations, const std::vector<ORROctree::Node*>& leaves, std::mt19937& random) {
    std::vector<int> ids(leaves.size());
    for (std::size_t i = 0; i < ids.size(); ++i) {
      ids[i] = static_cast<int>(i);
    }
    for (int i = 0; i < iterations && !ids.empty(); ++i) {
      std::uniform_int_distribution<std::size_t> pick(0, ids.size() - 1);
      const std::size_t at = pick(random);
      ORROctree::Node* first = leaves[static_cast<std::size_t>(ids[at])];
      ids[at] = ids.back();
      ids.pop_back();
      const float* p1 = first->getData()->getPoint();
      const float* n1 = first->getData()->getNormal();
      ORROctree::Node* second = randomLeafOnSphere(p1, pair_width_, random);
      if (second == nullptr) {
        continue;
      }
      const float* p2 = second->getData()->getPoint();
      const float* n2 = second->getData()->getNormal();
      if (ignore_coplanar_opps_ && pcl::recognition::aux::pointsAreCoplanar(p1, n1, p2, n2, max_coplanarity_angle_)) {
        continue;
      }
      sampled_oriented_point_pairs_.emplace_back(p1, n1, p2, n2);
    }
  }

  /// One hypothesis per model pair whose signature falls in the hash table's cells around each
  /// scene pair's: the rigid transform taking the model pair onto the scene pair.
  void hypothesesFromPairs(std::list<pcl::recognition::HypothesisBase>& out) const {
    ModelLibrary::HashTableCell* cells[27];  // a cell and its neighbours
    float key[3];
    for (const OrientedPointPair& pair : sampled_oriented_point_pairs_) {
      compute_oriented_point_pair_signature(pair.p1_, pair.n1_, pair.p2_, pair.n2_, key);
      const int count = model_library_.getHashTable().getNeighbors(key, cells);
      for (int i = 0; i < count; ++i) {
        for (const auto& [model, model_pairs] : *cells[i]) {
          for (const auto& [first, second] : model_pairs) {
            pcl::recognition::HypothesisBase hypothesis(model);
            computeRigidTransform(first->getPoint(), first->getNormal(), second->getPoint(), second->getNormal(),
                                  pair.p1_, pair.n1_, pair.p2_, pair.n2_, hypothesis.rigid_transform_);
            out.push_back(hypothesis);
          }
        }
      }
    }
  }

  /// The hypotheses voted into the rigid transform space (the scene's bounds, enlarged); of each
  /// occupied rotation space, the transform with the most votes (its neighbours' counting), if
  /// it passes the visibility and penalty tests, goes into `grouped` at the space's centre.
  void group(const std::list<pcl::recognition::HypothesisBase>& hypotheses, HypothesisOctree& grouped) {
    float b[6];
    scene_octree_.getBounds(b);
    const float enlarge = scene_bounds_enlargement_factor_ * std::max(std::max(b[1] - b[0], b[3] - b[2]), b[5] - b[4]);
    b[0] -= enlarge;
    b[1] += enlarge;
    b[2] -= enlarge;
    b[3] += enlarge;
    b[4] -= enlarge;
    b[5] += enlarge;
    HypothesisCreator creator;
    grouped.build(b, position_discretization_, &creator);
    // PCL's RigidTransformSpace without its nodes (transform_votes.h); every hypothesis is of
    // the one model. A position outside the space is dropped (PCL prints a warning for it).
    TransformVotes& space = votes_;
    space.build(b, position_discretization_, rotation_discretization_);
    float centre[3];
    for (const pcl::recognition::HypothesisBase& hypothesis : hypotheses) {
      pcl::recognition::aux::transform(hypothesis.rigid_transform_, hypothesis.obj_model_->getOctreeCenterOfMass(),
                                       centre);
      space.add(centre, hypothesis.rigid_transform_);
    }
    const float leaves = static_cast<float>(model_->getOctree().getFullLeaves().size());
    const float match_threshold = leaves * visibility_;
    const int penalty_threshold = static_cast<int>(leaves * relative_num_of_illegal_pts_ + 0.5f);
    for (const TransformVotes::Winner& winner : space.winners()) {
      pcl::recognition::Hypothesis hypothesis(model_);
      std::copy(winner.rigid_transform.begin(), winner.rigid_transform.end(), hypothesis.rigid_transform_);
      int match = 0;
      int penalty = 0;
      test(hypothesis, match, penalty);
      if (match >= match_threshold && penalty <= penalty_threshold && hypothesis.match_confidence_ > 0.0f) {
        grouped.createLeaf(winner.centre[0], winner.centre[1], winner.centre[2])->setData(hypothesis);
      }
    }
  }

  /// How many of the model's leaves the hypothesis puts where the scene's projection has a
  /// surface (match) and in front of it (penalty); match_confidence_ is the match's fraction.
  void test(pcl::recognition::Hypothesis& hypothesis, int& match, int& penalty) const {
    const std::vector<ORROctree::Node*>& leaves = hypothesis.obj_model_->getOctree().getFullLeaves();
    float point[3];
    for (const ORROctree::Node* leaf : leaves) {
      pcl::recognition::aux::transform(hypothesis.rigid_transform_, leaf->getData()->getPoint(), point);
      const ORROctreeZProjection::Pixel* pixel = scene_octree_proj_.getPixel(point);
      if (pixel == nullptr) {
        continue;
      }
      if (point[2] < pixel->z1()) {
        ++penalty;
      } else if (point[2] <= pixel->z2()) {
        ++match;
      }
    }
    hypothesis.match_confidence_ = static_cast<float>(match) / static_cast<float>(leaves.size());
  }

  const ModelLibrary::Model* model_ = nullptr;
  /// Kept from run to run: it remembers its rotation octree's neighbour lookups.
  TransformVotes votes_;
};

SeededObjRecRansac::SeededObjRecRansac(const std::vector<Eigen::Vector3f>& points,
                                       const std::vector<Eigen::Vector3f>& normals, Parameters parameters) {
  if (points.empty() || normals.size() != points.size()) {
    throw std::invalid_argument("ObjRecRANSAC's model needs points, each with a normal (" +
                                std::to_string(points.size()) + " points, " + std::to_string(normals.size()) +
                                " normals)");
  }
  recognizer_ = std::make_unique<Recognizer>(points, normals, parameters);
}

SeededObjRecRansac::~SeededObjRecRansac() = default;

std::vector<SeededObjRecRansac::Candidate> SeededObjRecRansac::candidates(const std::vector<Eigen::Vector3f>& points,
                                                                          const std::vector<Eigen::Vector3f>& normals,
                                                                          double success_probability,
                                                                          float relative_object_size,
                                                                          std::uint32_t seed) {
  return recognizer_->candidates(points, normals, success_probability, relative_object_size, seed);
}

std::size_t SeededObjRecRansac::modelLeaves() const { return recognizer_->modelLeaves(); }

}  // namespace costar::perception
