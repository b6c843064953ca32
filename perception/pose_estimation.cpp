#include "perception/pose_estimation.h"

#include "perception/clustering.h"

#include <fcntl.h>
#include <pcl/recognition/ransac_based/obj_rec_ransac.h>
#include <unistd.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <limits>
#include <list>
#include <mutex>
#include <random>
#include <set>
#include <stdexcept>
#include <tuple>

namespace costar::perception {

// --- stdout ----------------------------------------------------------------------------------

namespace {
std::mutex silence_mutex;
int silence_depth = 0;
int saved_stdout = -1;
}  // namespace

StdoutSilence::StdoutSilence() {
  std::lock_guard lock(silence_mutex);
  if (silence_depth++ == 0) {
    std::cout.flush();
    std::fflush(stdout);
    saved_stdout = ::dup(1);
    const int null_fd = ::open("/dev/null", O_WRONLY);
    if (null_fd >= 0) {
      ::dup2(null_fd, 1);
      ::close(null_fd);
    }
  }
}

StdoutSilence::~StdoutSilence() {
  std::lock_guard lock(silence_mutex);
  if (--silence_depth == 0) {
    std::cout.flush();
    std::fflush(stdout);
    if (saved_stdout >= 0) {
      ::dup2(saved_stdout, 1);
      ::close(saved_stdout);
      saved_stdout = -1;
    }
  }
}

// --- ObjRecRANSAC, seeded --------------------------------------------------------------------

namespace {

using pcl::recognition::ORROctree;

world::Pose poseFromArray12(const float* t);

/// PCL's ObjRecRANSAC with its protected thresholds exposed and a recognize() whose sampling
/// comes from a seeded generator (PCL seeds with time(nullptr), twice per sample).
/// PCL 1.13's ORROctreeZProjection::build() writes each leaf's pixel coordinates into its own
/// num_pixels_x_ / num_pixels_y_, so the clear() that the next build() starts with frees only
/// some of the rows, pixels and sets it allocated: about 2 KB lost per pose estimation, 0.2 MB
/// per trial of the assembly (found with heaptrack in a soak). release() frees everything
/// build() allocated, by the lists it keeps of them and the row count it computed, and leaves
/// the projection empty; recognition between two builds is untouched.
class ProjectionRelease final : public pcl::recognition::ORROctreeZProjection {
 public:
  static void release(pcl::recognition::ORROctreeZProjection& projection) {
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

class SeededObjRecRansac final : public pcl::recognition::ObjRecRANSAC {
 public:
  SeededObjRecRansac(float pair_width, float voxel_size) : ObjRecRANSAC(pair_width, voxel_size) {}
  ~SeededObjRecRansac() override { ProjectionRelease::release(scene_octree_proj_); }
  SeededObjRecRansac(const SeededObjRecRansac&) = delete;
  SeededObjRecRansac& operator=(const SeededObjRecRansac&) = delete;

  void setVisibility(float value) { visibility_ = value; }
  void setRelativeObjectSize(float value) { relative_obj_size_ = value; }
  void setRelativeNumberOfIllegalPoints(float value) { relative_num_of_illegal_pts_ = value; }

  /// One accepted hypothesis per occupied cell of ObjRecRANSAC's rigid transform space.
  struct Candidate {
    world::Pose pose;
    float match = 0.0f;
  };

  /// ObjRecRANSAC::recognize() (PCL 1.13) up to and including the grouping of hypotheses in its
  /// rigid transform space, with deterministic sampling. Returns the best hypothesis of every
  /// occupied rotation space that passes ObjRecRANSAC's visibility and penalty tests. The
  /// final conflict graph is left out: it ranks hypotheses by the scene pixels they explain,
  /// and a scene cut down to one class's points has no table to contradict a hypothesis that
  /// slides off the object; the caller verifies the candidates against the whole depth image.
  std::vector<Candidate> candidates(const PointCloudIn& scene, const PointCloudN& normals, double success_probability,
                                    float relative_object_size, std::uint32_t seed) {
    std::vector<Candidate> out;
    relative_obj_size_ = relative_object_size;
    clearTestData();
    scene_octree_.build(scene, voxel_size_, &normals);
    ProjectionRelease::release(scene_octree_proj_);
    scene_octree_proj_.build(scene_octree_, abs_zdist_thresh_, abs_zdist_thresh_);
    scene_octree_points_ = PointCloudIn::Ptr(new PointCloudIn());
    scene_octree_.getFullLeavesPoints(*scene_octree_points_);
    std::vector<ORROctree::Node*>& leaves = scene_octree_.getFullLeaves();
    if (leaves.size() < 2) {
      return out;
    }
    const int iterations =
        std::min(computeNumberOfIterations(std::min(success_probability, 0.999)), static_cast<int>(leaves.size()));
    std::mt19937 random(seed);
    samplePairs(iterations, leaves, random);
    std::list<pcl::recognition::HypothesisBase> pre_hypotheses;
    const int count = generateHypotheses(sampled_oriented_point_pairs_, pre_hypotheses);
    HypothesisOctree grouped;
    groupHypotheses(pre_hypotheses, count, transform_space_, grouped);
    pre_hypotheses.clear();
    for (const auto* leaf : grouped.getFullLeaves()) {
      const pcl::recognition::Hypothesis& hypothesis = leaf->getData();
      out.push_back({poseFromArray12(hypothesis.rigid_transform_), hypothesis.match_confidence_});
    }
    clearTestData();
    return out;
  }

  /// Full leaves of the model's octree (at the voxel size), once addModel() has run.
  std::size_t modelLeaves(const std::string& name) const {
    const auto* model = getModel(name);
    return model == nullptr ? 0 : model->getOctree().getFullLeaves().size();
  }

 private:
  /// ORROctree::getRandomFullLeafOnSphere with our generator.
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

  /// ObjRecRANSAC::sampleOrientedPointPairs with our generator.
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

Eigen::Matrix3d rotationFromVector(const Eigen::Vector3d& omega) {
  const double angle = omega.norm();
  if (angle < 1e-12) {
    return Eigen::Matrix3d::Identity();
  }
  return Eigen::AngleAxisd(angle, omega / angle).toRotationMatrix();
}

Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

double seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

}  // namespace

// --- ICP -------------------------------------------------------------------------------------

IcpResult refinePose(const ObjectModel& model, const std::vector<Eigen::Vector3f>& scene, const world::Pose& initial,
                     int iterations, double initial_distance, double final_distance, double point_to_point_weight) {
  IcpResult result;
  // Work with the inverse: camera -> object frame, where the grid lives.
  Eigen::Isometry3d to_object = initial.inverse();
  const int total = std::max(1, iterations);
  for (int iteration = 0; iteration < total; ++iteration) {
    const double fraction = total == 1 ? 1.0 : static_cast<double>(iteration) / (total - 1);
    const double gate = initial_distance + (final_distance - initial_distance) * std::min(1.0, 1.5 * fraction);
    const double gate_squared = gate * gate;
    Eigen::Matrix<double, 6, 6> a = Eigen::Matrix<double, 6, 6>::Zero();
    Eigen::Matrix<double, 6, 1> b = Eigen::Matrix<double, 6, 1>::Zero();
    const Eigen::Isometry3f transform = to_object.cast<float>();
    double squared_sum = 0.0;
    int inliers = 0;
    for (const Eigen::Vector3f& p : scene) {
      const Eigen::Vector3f q = transform * p;
      const int nearest = model.grid.lookup(q);
      if (nearest < 0) {
        continue;
      }
      const Eigen::Vector3f& m = model.surface.points[static_cast<std::size_t>(nearest)];
      const Eigen::Vector3f d = q - m;
      if (d.squaredNorm() > gate_squared) {
        continue;
      }
      const Eigen::Vector3d n = model.surface.normals[static_cast<std::size_t>(nearest)].cast<double>();
      const Eigen::Vector3d qd = q.cast<double>();
      const double r = n.dot(d.cast<double>());
      // Huber weight; the knee follows the gate (wide early: far points pull as a whole).
      const double knee = std::max(0.0015, gate / 4.0);
      const double weight = std::abs(r) < knee ? 1.0 : knee / std::abs(r);
      Eigen::Matrix<double, 6, 1> j;
      j << qd.cross(n), n;
      a.noalias() += weight * j * j.transpose();
      b.noalias() += weight * j * r;
      // An optional weak point-to-point term: past an edge, the nearest sample of a face says
      // nothing along the face, and this term still pulls (an elongated object sliding along
      // its axis); inside faces it adds the sample spacing's jitter, so only coarse runs use it.
      if (point_to_point_weight > 0) {
        Eigen::Matrix<double, 3, 6> jp;
        jp << -skew(qd), Eigen::Matrix3d::Identity();
        const Eigen::Vector3d dd = d.cast<double>();
        const double point_weight = point_to_point_weight * (dd.norm() < knee ? 1.0 : knee / dd.norm());
        a.noalias() += point_weight * jp.transpose() * jp;
        b.noalias() += point_weight * jp.transpose() * dd;
      }
      squared_sum += r * r;
      ++inliers;
    }
    result.inliers = inliers;
    result.rms = inliers > 0 ? std::sqrt(squared_sum / inliers) : 0.0;
    result.iterations = iteration + 1;
    if (inliers < 6) {
      break;
    }
    // Damped normal equations: directions the visible surface does not constrain stay put.
    a.diagonal().array() += 1e-9 + 1e-6 * a.trace() / 6.0;
    const Eigen::Matrix<double, 6, 1> x = a.ldlt().solve(-b);
    Eigen::Isometry3d step = Eigen::Isometry3d::Identity();
    step.linear() = rotationFromVector(x.head<3>());
    step.translation() = x.tail<3>();
    to_object = step * to_object;
    // Converged once the gate has shrunk to its final value.
    if (x.head<3>().norm() < 2e-5 && x.tail<3>().norm() < 2e-6 && 1.5 * fraction >= 1.0) {
      break;
    }
  }
  result.pose = to_object.inverse();
  result.pose.linear() = Eigen::Quaterniond(result.pose.linear()).normalized().toRotationMatrix();
  return result;
}

// --- scoring ---------------------------------------------------------------------------------

DepthAgreement compareWithDepth(const ObjectModel& model, const world::Pose& pose, const camera::RgbdFrame& frame,
                                double tolerance, int stride, const std::vector<std::uint8_t>* claimed) {
  DepthAgreement agreement;
  const camera::Intrinsics& in = frame.intrinsics;
  const Eigen::Isometry3f transform = pose.cast<float>();
  const Eigen::Matrix3f rotation = transform.linear();
  const float tol = static_cast<float>(tolerance);
  const std::size_t step = static_cast<std::size_t>(std::max(1, stride));
  for (std::size_t i = 0; i < model.surface.size(); i += step) {
    const Eigen::Vector3f p = transform * model.surface.points[i];
    const Eigen::Vector3f n = rotation * model.surface.normals[i];
    // Facing the camera at less than about 80 degrees of incidence.
    if (n.dot(p) > -0.17f * p.norm() || p.z() <= 0.0f) {
      continue;
    }
    const int u = static_cast<int>(std::lround(in.fx * p.x() / p.z() + in.cx));
    const int v = static_cast<int>(std::lround(in.fy * p.y() / p.z() + in.cy));
    if (u < 0 || v < 0 || u >= in.width || v >= in.height) {
      continue;
    }
    ++agreement.facing;
    const float depth = frame.points[static_cast<std::size_t>(v) * in.width + u].z();
    if (!(depth == depth)) {
      continue;  // no reading: cannot judge
    }
    if (std::abs(depth - p.z()) <= tol) {
      if (claimed == nullptr || (*claimed)[static_cast<std::size_t>(v) * in.width + u] == 0) {
        ++agreement.confirmed;
      } else {
        ++agreement.contradicted;  // another detection's surface: the two would overlap
      }
    } else if (depth > p.z() + tol) {
      ++agreement.contradicted;  // the camera sees through where the model has surface
    }
    // depth < p.z() - tol: something in front (occlusion, or the object's own far side).
  }
  return agreement;
}

double overlapFraction(const ObjectModel& a, const world::Pose& pose_a, const ObjectModel& b, const world::Pose& pose_b,
                       double margin) {
  if (a.interior.empty()) {
    return 0.0;
  }
  // Far apart: no overlap.
  if ((pose_a.translation() - pose_b.translation()).norm() > a.radius + b.radius) {
    return 0.0;
  }
  const Eigen::Isometry3f a_to_b = (pose_b.inverse() * pose_a).cast<float>();
  int inside = 0;
  for (const Eigen::Vector3f& interior : a.interior) {
    const Eigen::Vector3d p = (a_to_b * interior).cast<double>();
    for (const world::Box& box : b.object_class.boxes) {
      if (((p - box.center).cwiseAbs() - box.half_size).maxCoeff() < -margin) {
        ++inside;
        break;
      }
    }
  }
  return static_cast<double>(inside) / static_cast<double>(a.interior.size());
}

// --- the estimator ---------------------------------------------------------------------------

struct ClassPoseEstimator::Impl {
  std::unique_ptr<SeededObjRecRansac> recognizer;
  /// Full leaves of ObjRecRANSAC's model octree: the scale of "one instance" in a scene.
  double model_leaves = 0.0;
};

ClassPoseEstimator::ClassPoseEstimator(const ObjectModel& model, PoseEstimationOptions options)
    : model_(model), options_(options), impl_(std::make_unique<Impl>()) {
  const ClassParameters& p = model.parameters;
  impl_->recognizer =
      std::make_unique<SeededObjRecRansac>(static_cast<float>(p.pair_width), static_cast<float>(p.voxel_size));
  SeededObjRecRansac& recognizer = *impl_->recognizer;
  // Our own ICP follows; PCL's internal one samples its points with a time-seeded generator.
  recognizer.icpHypothesesRefinementOff();
  recognizer.setVisibility(static_cast<float>(p.visibility));
  recognizer.setRelativeNumberOfIllegalPoints(static_cast<float>(p.penalty_fraction));
  // Per-cluster scenes are tight around the objects: keep hypotheses whose model centre lies
  // outside the seen part (see DEPENDENCIES.md).
  recognizer.setSceneBoundsEnlargementFactor(1.0f);
  // The model: the surface samples thinned to one per recognition_spacing cell and face.
  pcl::PointCloud<pcl::PointXYZ> points;
  pcl::PointCloud<pcl::Normal> normals;
  std::set<std::tuple<int, int, int, int, int, int>> taken;
  for (std::size_t i = 0; i < model.surface.size(); ++i) {
    const Eigen::Vector3f& q = model.surface.points[i];
    const Eigen::Vector3f& n = model.surface.normals[i];
    const Eigen::Vector3i cell = (q.cast<double>() / p.recognition_spacing).array().floor().cast<int>();
    const Eigen::Vector3i direction = n.array().round().cast<int>();
    if (!taken.insert({cell.x(), cell.y(), cell.z(), direction.x(), direction.y(), direction.z()}).second) {
      continue;
    }
    points.push_back(pcl::PointXYZ(q.x(), q.y(), q.z()));
    normals.push_back(pcl::Normal(n.x(), n.y(), n.z()));
  }
  {
    StdoutSilence silence;
    if (!recognizer.addModel(points, normals, model.name())) {
      throw std::runtime_error("ObjRecRANSAC refused the model of class '" + model.name() + "'");
    }
  }
  impl_->model_leaves = static_cast<double>(recognizer.modelLeaves(model.name()));
}

ClassPoseEstimator::~ClassPoseEstimator() = default;

std::vector<std::vector<int>> ClassPoseEstimator::clusters(const Cloud& points,
                                                           const camera::Intrinsics& intrinsics) const {
  return organizedClusters(points.points, points.pixels, intrinsics.width, intrinsics.height,
                           options_.cluster_tolerance, 2, options_.min_cluster_points);
}

namespace {

/// Points of `cloud` within `reach` of `centre`, except those `taken` marks (when given), at
/// most `max_count` (evenly thinned).
std::vector<Eigen::Vector3f> pointsNear(const Cloud& cloud, const Eigen::Vector3f& centre, double reach,
                                        std::size_t max_count, const std::vector<bool>* taken = nullptr) {
  std::vector<Eigen::Vector3f> near;
  const float reach_squared = static_cast<float>(reach * reach);
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3f& p = cloud.points[i];
    if ((p - centre).squaredNorm() < reach_squared && (taken == nullptr || !(*taken)[i])) {
      near.push_back(p);
    }
  }
  if (near.size() > max_count) {
    std::vector<Eigen::Vector3f> thinned;
    thinned.reserve(max_count);
    const double step = static_cast<double>(near.size()) / static_cast<double>(max_count);
    for (std::size_t i = 0; i < max_count; ++i) {
      thinned.push_back(near[static_cast<std::size_t>(static_cast<double>(i) * step)]);
    }
    near.swap(thinned);
  }
  return near;
}

double rank(const Detection& detection) { return detection.confidence * detection.visible_fraction; }

template <typename ModelOf>
std::vector<Detection> mergeBy(std::vector<Detection> detections, const ModelOf& model_of) {
  std::stable_sort(detections.begin(), detections.end(),
                   [](const Detection& a, const Detection& b) { return rank(a) > rank(b); });
  std::vector<Detection> kept;
  for (auto& detection : detections) {
    const ObjectModel& model = model_of(detection.object_class);
    const bool taken = std::any_of(kept.begin(), kept.end(), [&](const Detection& other) {
      return overlapFraction(model, detection.pose_in_camera, model_of(other.object_class), other.pose_in_camera) > 0.2;
    });
    if (!taken) {
      kept.push_back(std::move(detection));
    }
  }
  return kept;
}

}  // namespace

std::vector<Detection> mergeDetections(std::vector<Detection> detections, const std::vector<ObjectModel>& models) {
  return mergeBy(std::move(detections), [&models](const std::string& name) -> const ObjectModel& {
    for (const auto& model : models) {
      if (model.name() == name) {
        return model;
      }
    }
    throw std::invalid_argument("mergeDetections: no model of class '" + name + "'");
  });
}

bool ClassPoseEstimator::aboveSupport(const world::Pose& pose) const {
  if (!support_plane_) {
    return true;
  }
  const Eigen::Isometry3f transform = pose.cast<float>();
  for (const Eigen::Vector3f& interior : model_.interior) {
    if (support_plane_->height(transform * interior) < -0.004) {
      return false;
    }
  }
  return true;
}

std::vector<world::Pose> ClassPoseEstimator::principalAxisSeeds(const Cloud& cloud,
                                                                const std::vector<int>& indices) const {
  std::vector<world::Pose> seeds;
  if (indices.size() < 10) {
    return seeds;
  }
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const int i : indices) {
    mean += cloud.points[static_cast<std::size_t>(i)].cast<double>();
  }
  mean /= static_cast<double>(indices.size());
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (const int i : indices) {
    const Eigen::Vector3d d = cloud.points[static_cast<std::size_t>(i)].cast<double>() - mean;
    covariance += d * d.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(covariance);
  // Columns: largest, middle, smallest spread; the smallest points away from the camera.
  Eigen::Matrix3d axes;
  axes.col(0) = solver.eigenvectors().col(2);
  axes.col(1) = solver.eigenvectors().col(1);
  axes.col(2) = solver.eigenvectors().col(0);
  if (axes.col(2).dot(mean) < 0) {
    axes.col(2) = -axes.col(2);
  }
  const Eigen::Vector3d half = model_.object_class.bounds().sizes() / 2.0;
  const Eigen::Vector3d centre = model_.object_class.bounds().center();
  // Object axis a goes to axes.col(k) with sign s: all 48 signed permutations, proper ones only.
  const std::array<std::array<int, 3>, 6> permutations = {
      {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}}};
  for (const auto& permutation : permutations) {
    for (int signs = 0; signs < 8; ++signs) {
      Eigen::Matrix3d rotation;  // columns: the object's x, y, z in the camera frame
      for (int a = 0; a < 3; ++a) {
        const double sign = (signs >> a) & 1 ? -1.0 : 1.0;
        rotation.col(a) = sign * axes.col(permutation[static_cast<std::size_t>(a)]);
      }
      if (rotation.determinant() < 0) {
        continue;
      }
      // The object axis along the points' normal: the object lies behind the seen face.
      const int normal_axis =
          static_cast<int>(std::find(permutation.begin(), permutation.end(), 2) - permutation.begin());
      world::Pose seed = world::Pose::Identity();
      seed.linear() = rotation;
      seed.translation() = mean + axes.col(2) * half[normal_axis] - rotation * centre;
      seeds.push_back(seed);
    }
  }
  return seeds;
}

double lowHeight(const Cloud& points, const std::vector<int>& indices, const TablePlane& support) {
  if (indices.empty()) {
    return 0.0;
  }
  std::vector<double> heights;
  heights.reserve(indices.size());
  for (const int i : indices) {
    heights.push_back(support.height(points.points[static_cast<std::size_t>(i)]));
  }
  const auto low = heights.begin() + static_cast<std::ptrdiff_t>(heights.size() / 20);
  std::nth_element(heights.begin(), low, heights.end());
  return *low;
}

bool ClassPoseEstimator::raised(const world::Pose& pose) const {
  if (!support_plane_) {
    return false;
  }
  const Eigen::Isometry3f transform = pose.cast<float>();
  return std::all_of(model_.interior.begin(), model_.interior.end(), [&](const Eigen::Vector3f& interior) {
    return support_plane_->height(transform * interior) > kRaisedSupport;
  });
}

namespace {

/// restingSeeds (`middle`) and restingSeedsAtEnds (`ends`) from one pass over the points.
struct RestingStarts {
  std::vector<world::Pose> middle;
  std::vector<world::Pose> ends;
};

RestingStarts restingStarts(const Cloud& cloud, const std::vector<int>& indices, const TablePlane& support,
                            const world::ObjectClass& object_class) {
  RestingStarts starts;
  if (indices.size() < 10) {
    return starts;
  }
  const Eigen::Vector3d normal = support.normal.normalized();  // out of the table, toward the camera
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const int i : indices) {
    mean += cloud.points[static_cast<std::size_t>(i)].cast<double>();
  }
  mean /= static_cast<double>(indices.size());
  // The points' spread in the plane: its main axis is a first guess of the object's x.
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (const int i : indices) {
    Eigen::Vector3d d = cloud.points[static_cast<std::size_t>(i)].cast<double>() - mean;
    d -= d.dot(normal) * normal;
    covariance += d * d.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(covariance);
  Eigen::Vector3d axis = solver.eigenvectors().col(2);
  axis -= axis.dot(normal) * normal;
  if (axis.norm() < 1e-9) {
    return starts;
  }
  axis.normalize();
  const Eigen::Vector3d side = normal.cross(axis);
  // Under the points, on the plane: the seen faces are the top and the side facing the camera,
  // so the middle lies a little further away, horizontally.
  const Eigen::AlignedBox3d bounds = object_class.bounds();
  const auto onPlane = [&](const Eigen::Vector3d& point) {
    Eigen::Vector3d on_plane = point - support.height(point.cast<float>()) * normal;
    const Eigen::Vector3d away = on_plane - on_plane.dot(normal) * normal;  // the camera is at the origin
    if (away.norm() > 1e-9) {
      on_plane += away.normalized() * (0.25 * std::min(bounds.sizes().x(), bounds.sizes().y()));
    }
    return on_plane;
  };
  // Points spread along their main axis over more than one and a half objects are more than one
  // (touching parts of a class): their mean lies between them; the ends' starts stand half an
  // object in from the points' extremes (their 2nd and 98th percentiles).
  std::vector<Eigen::Vector3d> ends;
  {
    const double span = bounds.sizes().head<2>().maxCoeff();
    std::vector<double> along;
    along.reserve(indices.size());
    for (const int i : indices) {
      along.push_back((cloud.points[static_cast<std::size_t>(i)].cast<double>() - mean).dot(axis));
    }
    const auto first = along.begin() + static_cast<std::ptrdiff_t>(along.size() / 50);
    const auto last = along.begin() + static_cast<std::ptrdiff_t>(along.size() - 1 - along.size() / 50);
    std::nth_element(along.begin(), first, along.end());
    const double from = *first;
    std::nth_element(along.begin(), last, along.end());
    const double to = *last;
    if (to - from > 1.5 * span) {
      ends = {onPlane(mean + (from + 0.5 * span) * axis), onPlane(mean + (to - 0.5 * span) * axis)};
    }
  }
  // What it rests on: the table, and, when even its lowest points are well above the table (a
  // link on a node), a level under those points as well (their 5th percentile height).
  std::vector<double> levels{0.0};
  if (const double low = lowHeight(cloud, indices, support); low > kRaisedSupport) {
    levels.push_back(low);
  }
  constexpr double kStep = 15.0 * M_PI / 180.0;
  const auto addStarts = [&](const Eigen::Vector3d& on_plane, std::vector<world::Pose>& seeds) {
    for (const double level : levels) {
      for (int k = 0; k < 12; ++k) {  // 0 .. 165 degrees: a turn of 180 more is the same box
        const double yaw = k * kStep;
        Eigen::Matrix3d rotation;  // columns: the object's x, y, z in the camera frame
        rotation.col(0) = std::cos(yaw) * axis + std::sin(yaw) * side;
        rotation.col(2) = normal;
        rotation.col(1) = rotation.col(2).cross(rotation.col(0));
        world::Pose seed = world::Pose::Identity();
        seed.linear() = rotation;
        // The object's bottom face on the level, its footprint's middle above on_plane.
        const Eigen::Vector3d footprint_middle(bounds.center().x(), bounds.center().y(), bounds.min().z());
        seed.translation() = on_plane + level * normal - rotation * footprint_middle;
        seeds.push_back(seed);
      }
    }
  };
  addStarts(onPlane(mean), starts.middle);
  for (const Eigen::Vector3d& end : ends) {
    addStarts(end, starts.ends);
  }
  return starts;
}

}  // namespace

std::vector<world::Pose> restingSeeds(const Cloud& cloud, const std::vector<int>& indices, const TablePlane& support,
                                      const world::ObjectClass& object_class) {
  return restingStarts(cloud, indices, support, object_class).middle;
}

std::vector<world::Pose> restingSeedsAtEnds(const Cloud& cloud, const std::vector<int>& indices,
                                            const TablePlane& support, const world::ObjectClass& object_class) {
  return restingStarts(cloud, indices, support, object_class).ends;
}

std::vector<int> ClassPoseEstimator::unexplainedPoints(const Cloud& cloud, const std::vector<int>& cluster,
                                                       const std::vector<Detection>& detections) const {
  std::vector<Eigen::Isometry3f> to_object;
  for (const auto& detection : detections) {
    to_object.push_back(detection.pose_in_camera.inverse().cast<float>());
  }
  const float limit = static_cast<float>(options_.depth_tolerance * options_.depth_tolerance);
  std::vector<int> out;
  for (const int i : cluster) {
    const Eigen::Vector3f& p = cloud.points[static_cast<std::size_t>(i)];
    const bool near_surface = std::any_of(to_object.begin(), to_object.end(), [&](const Eigen::Isometry3f& t) {
      const Eigen::Vector3f q = t * p;
      const int nearest = model_.grid.lookup(q);
      return nearest >= 0 && (model_.surface.points[static_cast<std::size_t>(nearest)] - q).squaredNorm() < limit;
    });
    if (!near_surface) {
      out.push_back(i);
    }
  }
  return out;
}

namespace {

/// An axis of a model's box at least this many times its shortest is long: point-to-plane ICP
/// cannot tell where along it the object lies (slideAlongLongAxes).
constexpr double kLongAxis = 1.5;

bool isLongAxis(const Eigen::Vector3d& size, int axis) { return size[axis] >= kLongAxis * size.minCoeff(); }

bool isElongated(const Eigen::Vector3d& size) { return size.maxCoeff() >= kLongAxis * size.minCoeff(); }

/// A coarse pose of an elongated part that the depth image agrees with this much less than a
/// detection needs is slid along its length before it is rejected (verify).
constexpr double kSlideBeforeRejecting = 0.3;

}  // namespace

void ClassPoseEstimator::levelResting(std::vector<Detection>& detections, const camera::RgbdFrame& frame) const {
  if (!support_plane_) {
    return;
  }
  constexpr double kLevelFrom = 1.0 * M_PI / 180.0;
  constexpr double kLevelUpTo = 20.0 * M_PI / 180.0;
  constexpr double kAgreementSlack = 0.005;
  const Eigen::Vector3d up = support_plane_->normal.normalized();
  for (Detection& detection : detections) {
    const Eigen::Matrix3d rotation = detection.pose_in_camera.linear();
    int axis = 0;
    for (int k = 1; k < 3; ++k) {
      if (std::abs(rotation.col(k).dot(up)) > std::abs(rotation.col(axis).dot(up))) {
        axis = k;
      }
    }
    const Eigen::Vector3d face =
        rotation.col(axis).dot(up) > 0.0 ? rotation.col(axis) : Eigen::Vector3d(-rotation.col(axis));
    const double tilt = std::acos(std::clamp(face.dot(up), -1.0, 1.0));
    if (tilt < kLevelFrom || tilt > kLevelUpTo) {
      continue;
    }
    world::Pose levelled = detection.pose_in_camera;
    levelled.linear() = Eigen::Quaterniond::FromTwoVectors(face, up).toRotationMatrix() * rotation;
    const DepthAgreement agreement = compareWithDepth(model_, levelled, frame, options_.depth_tolerance);
    if (agreement.agreement() >= detection.confidence - kAgreementSlack &&
        agreement.visibleFraction() >= options_.min_visible_fraction && aboveSupport(levelled)) {
      detection.pose_in_camera = levelled;
      detection.confidence = agreement.agreement();
      detection.visible_fraction = agreement.visibleFraction();
    }
  }
}

std::optional<world::Pose> ClassPoseEstimator::slideAlongLongAxes(const world::Pose& pose,
                                                                  const camera::RgbdFrame& frame,
                                                                  const std::vector<std::uint8_t>* claimed) const {
  // Point-to-plane ICP cannot tell where along its faces an elongated object lies when an
  // end hides behind a neighbour: try shifts along each long axis and keep the one the depth
  // image agrees with best (surface seen where the model has it, minus three times the
  // surface seen through).
  const Eigen::Vector3d size = model_.object_class.bounds().sizes();
  const auto score = [&](const world::Pose& candidate) {
    const DepthAgreement agreement =
        compareWithDepth(model_, candidate, frame, options_.depth_tolerance, claimed == nullptr ? 2 : 1, claimed);
    return agreement.confirmed - 3 * agreement.contradicted;
  };
  // Against claimed surface, farther: a part slid into its neighbour can lie a third of its
  // length off.
  const int steps = claimed == nullptr ? 12 : 20;
  std::optional<world::Pose> best;
  int best_score = score(pose);
  for (int axis = 0; axis < 3; ++axis) {
    if (!isLongAxis(size, axis)) {
      continue;
    }
    for (int step = -steps; step <= steps; ++step) {
      if (step == 0) {
        continue;
      }
      Eigen::Vector3d shift = Eigen::Vector3d::Zero();
      shift[axis] = 0.002 * step;
      const world::Pose candidate = pose * Eigen::Translation3d(shift);
      const int value = score(candidate);
      if (value > best_score) {
        best_score = value;
        best = candidate;
      }
    }
  }
  return best;
}

void ClassPoseEstimator::markExplained(const Cloud& cloud, const Detection& detection, std::vector<bool>& taken) const {
  const Eigen::Isometry3f to_object = detection.pose_in_camera.inverse().cast<float>();
  const Eigen::Vector3f centre = detection.pose_in_camera.translation().cast<float>();
  const float reach = static_cast<float>(model_.radius + 0.01);
  const float limit = static_cast<float>(options_.depth_tolerance * options_.depth_tolerance);
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3f& p = cloud.points[i];
    if (taken[i] || (p - centre).squaredNorm() > reach * reach) {
      continue;
    }
    const Eigen::Vector3f q = to_object * p;
    const int nearest = model_.grid.lookup(q);
    taken[i] = nearest >= 0 && (model_.surface.points[static_cast<std::size_t>(nearest)] - q).squaredNorm() < limit;
  }
}

double ClassPoseEstimator::meanSupport(const std::vector<Detection>& detections) {
  if (detections.empty()) {
    return 0.0;
  }
  double sum = 0.0;
  for (const auto& detection : detections) {
    sum += detection.support;
  }
  return sum / static_cast<double>(detections.size());
}

std::optional<Detection> ClassPoseEstimator::verify(const Cloud& cloud, const world::Pose& start, double raw_score,
                                                    const camera::RgbdFrame& frame, const std::vector<bool>& taken,
                                                    const std::vector<Detection>& accepted, int* checked) const {
  const auto overlapsAccepted = [&](const world::Pose& pose) {
    return std::any_of(accepted.begin(), accepted.end(), [&](const Detection& other) {
      return overlapFraction(model_, pose, model_, other.pose_in_camera) > 0.2;
    });
  };
  if (overlapsAccepted(start)) {
    return std::nullopt;  // explained already
  }
  // Points already explained by an accepted neighbour do not pull this one.
  const std::vector<Eigen::Vector3f> coarse_points =
      pointsNear(cloud, start.translation().cast<float>(), model_.radius + options_.icp_initial_distance, 150, &taken);
  if (coarse_points.size() < 10) {
    return std::nullopt;
  }
  if (checked != nullptr) {
    ++*checked;
  }
  // A raw pose that already fits needs a small correction only (a narrow ICP cannot drift
  // onto a touching neighbour); otherwise, or if that fails, a wide one.
  const auto passes = [this](const DepthAgreement& quick) {
    return quick.agreement() >= options_.min_confidence - 0.1 &&
           quick.visibleFraction() >= options_.min_visible_fraction * 0.8;
  };
  IcpResult coarse;
  DepthAgreement quick;
  bool ok = false;
  if (raw_score >= 0.25) {
    coarse = refinePose(model_, coarse_points, start, 8, 0.01, options_.icp_final_distance + 0.001);
    quick = compareWithDepth(model_, coarse.pose, frame, options_.depth_tolerance, 5);
    ok = passes(quick);
  }
  if (!ok) {
    coarse = refinePose(model_, coarse_points, start, 10, options_.icp_initial_distance,
                        options_.icp_coarse_final_distance, 0.2);
    quick = compareWithDepth(model_, coarse.pose, frame, options_.depth_tolerance, 5);
    ok = passes(quick);
  }
  // An elongated part lying on another part, whose points are partly that part's class's (a
  // link across a node, its end over the node labelled node), is pulled along its length by
  // them: slid back to where the depth image has it, it may pass. (On the table, sliding a start
  // that fails can put it where a partly hidden part is not: not done there.)
  if (!ok && isElongated(model_.object_class.bounds().sizes()) && raised(coarse.pose) &&
      quick.agreement() >= options_.min_confidence - kSlideBeforeRejecting &&
      quick.visibleFraction() >= options_.min_visible_fraction * 0.8) {
    if (const std::optional<world::Pose> slid = slideAlongLongAxes(coarse.pose, frame)) {
      const DepthAgreement again = compareWithDepth(model_, *slid, frame, options_.depth_tolerance, 5);
      if (passes(again)) {
        coarse.pose = *slid;
        quick = again;
        ok = true;
      }
    }
  }
  if (!ok || !aboveSupport(coarse.pose) || overlapsAccepted(coarse.pose)) {
    return std::nullopt;
  }
  const std::vector<Eigen::Vector3f> fine_points =
      pointsNear(cloud, coarse.pose.translation().cast<float>(), model_.radius + 0.01, 1500, &taken);
  IcpResult refined = refinePose(model_, fine_points, coarse.pose, options_.icp_iterations,
                                 options_.icp_coarse_final_distance, options_.icp_final_distance);
  if (const std::optional<world::Pose> slid = slideAlongLongAxes(refined.pose, frame)) {
    refined = refinePose(model_, fine_points, *slid, options_.icp_iterations / 2 + 1,
                         options_.icp_final_distance + 0.002, options_.icp_final_distance);
  }
  const DepthAgreement agreement = compareWithDepth(model_, refined.pose, frame, options_.depth_tolerance);
  Detection detection;
  detection.object_class = model_.name();
  detection.pose_in_camera = refined.pose;
  detection.confidence = agreement.agreement();
  detection.visible_fraction = agreement.visibleFraction();
  detection.fit_rms = refined.rms;
  detection.support = refined.inliers;
  if (detection.confidence < options_.min_confidence || detection.visible_fraction < options_.min_visible_fraction ||
      !aboveSupport(refined.pose)) {
    return std::nullopt;
  }
  return detection;
}

std::vector<std::pair<double, std::size_t>> ClassPoseEstimator::rankStarts(const std::vector<world::Pose>& starts,
                                                                           const camera::RgbdFrame& frame,
                                                                           std::size_t last_resort) const {
  std::vector<std::pair<double, std::size_t>> order;
  order.reserve(starts.size());
  for (std::size_t c = 0; c < starts.size(); ++c) {
    const DepthAgreement raw = compareWithDepth(model_, starts[c], frame, 2 * options_.depth_tolerance, 7);
    order.emplace_back(raw.agreement() * raw.visibleFraction(), c);
  }
  std::stable_sort(order.begin(), order.end(), [last_resort](const auto& a, const auto& b) {
    const bool a_last = a.second >= last_resort;
    const bool b_last = b.second >= last_resort;
    return a_last != b_last ? b_last : a.first > b.first;
  });
  return order;
}

bool ClassPoseEstimator::explained(std::size_t unexplained, const std::vector<Detection>& accepted) const {
  return static_cast<double>(unexplained) <
         std::max<double>(options_.min_cluster_points, options_.unexplained_fraction * meanSupport(accepted));
}

void ClassPoseEstimator::splitStraddling(const Cloud& cloud, const std::vector<int>& cluster,
                                         const camera::RgbdFrame& frame, std::vector<Detection>& accepted,
                                         int* checked) const {
  // Two touching parts of the class lying end to end: a detection straddling them (half of
  // each) fits the depth image well enough to be accepted, and every later start on either
  // part overlaps it, so the cluster stays unexplained on both sides. Try each detection
  // replaced by detections started upright on the table under the points it and no other
  // explains (with the points nobody explains), in the middle and, when they span more than
  // one object, at both ends; keep them when they explain more of the cluster.
  if (!support_plane_ || accepted.empty()) {
    return;
  }
  const std::size_t unexplained = unexplainedPoints(cloud, cluster, accepted).size();
  if (explained(unexplained, accepted)) {
    return;
  }
  std::vector<Detection> best = accepted;
  std::size_t best_unexplained = unexplained;
  for (std::size_t a = 0; a < accepted.size(); ++a) {
    std::vector<Detection> others = accepted;
    others.erase(others.begin() + static_cast<std::ptrdiff_t>(a));
    std::vector<bool> others_taken(cloud.size(), false);
    for (const Detection& other : others) {
      markExplained(cloud, other, others_taken);
    }
    const RestingStarts resting =
        restingStarts(cloud, unexplainedPoints(cloud, cluster, others), *support_plane_, model_.object_class);
    // The ends on their own (a start in the middle would find the straddling pose again), then
    // the middle (one part, when the replaced detection lay partly on a neighbour).
    for (const std::vector<world::Pose>* starts : {&resting.ends, &resting.middle}) {
      if (starts->empty()) {
        continue;
      }
      std::vector<Detection> trial = others;
      std::vector<bool> taken = others_taken;
      for (const auto& [raw_score, c] : rankStarts(*starts, frame, starts->size())) {
        std::optional<Detection> detection = verify(cloud, (*starts)[c], raw_score, frame, taken, trial, checked);
        if (detection) {
          trial.push_back(*detection);
          markExplained(cloud, *detection, taken);
        }
      }
      const std::size_t left = unexplainedPoints(cloud, cluster, trial).size();
      if (trial.size() >= accepted.size() && left < best_unexplained) {
        best = std::move(trial);
        best_unexplained = left;
      }
    }
  }
  accepted = std::move(best);
}

std::vector<Detection> ClassPoseEstimator::estimateCluster(const Cloud& cloud, const std::vector<int>& cluster,
                                                           const camera::RgbdFrame& frame, std::uint32_t task,
                                                           Timing* timing) {
  Timing local;
  std::vector<Detection> accepted;
  if (cloud.normals.size() != cloud.size() || cluster.size() < 3) {
    return accepted;
  }
  const ClassParameters& parameters = model_.parameters;
  std::vector<int> remaining = cluster;
  std::vector<bool> taken(cloud.size(), false);  // points explained by accepted detections
  for (int attempt = 0; attempt < std::max(1, options_.max_attempts); ++attempt) {
    // ObjRecRANSAC on the remaining points of the cluster.
    auto start = std::chrono::steady_clock::now();
    pcl::PointCloud<pcl::PointXYZ> points;
    pcl::PointCloud<pcl::Normal> normals;
    points.reserve(remaining.size());
    normals.reserve(remaining.size());
    std::vector<std::int64_t> keys;
    keys.reserve(remaining.size());
    for (const int i : remaining) {
      const Eigen::Vector3f& q = cloud.points[static_cast<std::size_t>(i)];
      const Eigen::Vector3f& n = cloud.normals[static_cast<std::size_t>(i)];
      points.push_back(pcl::PointXYZ(q.x(), q.y(), q.z()));
      normals.push_back(pcl::Normal(n.x(), n.y(), n.z()));
      const Eigen::Vector3i k = (q.cast<double>() / parameters.voxel_size).array().floor().cast<int>();
      keys.push_back((static_cast<std::int64_t>(k.x() & 0xFFFFF) << 40) |
                     (static_cast<std::int64_t>(k.y() & 0xFFFFF) << 20) | static_cast<std::int64_t>(k.z() & 0xFFFFF));
    }
    std::sort(keys.begin(), keys.end());
    const auto scene_leaves = static_cast<double>(std::unique(keys.begin(), keys.end()) - keys.begin());
    // A camera sees about a third of an object's surface.
    // Retries sample harder (a smaller relative object size means more point pairs).
    const double relative =
        attempt > 0
            ? parameters.relative_object_size
            : std::clamp(0.35 * impl_->model_leaves / std::max(1.0, scene_leaves), parameters.relative_object_size,
                         std::max(parameters.relative_object_size, options_.max_relative_object_size));
    auto candidates =
        impl_->recognizer->candidates(points, normals, options_.success_probability, static_cast<float>(relative),
                                      options_.seed + 7919u * task + 104729u * static_cast<std::uint32_t>(attempt));
    // Points left next to an instance already found: that instance's orientation, placed at
    // their centroid pushed back by half the object's size along the viewing ray, is a good
    // start too (touching parts of a class often lie aligned, which ObjRecRANSAC's sampling
    // handles poorly).
    if (attempt > 0 && !accepted.empty()) {
      Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
      for (const int i : remaining) {
        centroid += cloud.points[static_cast<std::size_t>(i)].cast<double>();
      }
      centroid /= static_cast<double>(remaining.size());
      centroid += centroid.normalized() * (0.5 * model_.object_class.bounds().sizes().minCoeff());
      for (const auto& neighbour : accepted) {
        world::Pose seed = neighbour.pose_in_camera;
        seed.translation() = centroid;
        candidates.push_back({seed, 0.0f});
      }
    }
    // When ObjRecRANSAC has nothing (all its point pairs were coplanar: only one face in
    // view, e.g. a link's top with its sides at grazing angles), start from the points'
    // principal axes: every proper rotation taking the object frame's axes to them, the
    // object pushed back along the smallest one (away from the camera) by half its size.
    if (attempt > 0 && candidates.empty()) {
      for (const world::Pose& seed : principalAxisSeeds(cloud, remaining)) {
        candidates.push_back({seed, 0.0f});
      }
    }
    // The points' axes mislead when two faces are in view (a node's top and front), and
    // ObjRecRANSAC's hypotheses can all be wrong there too: on a retry, the object standing
    // upright on the table, turned in steps, starts near the truth as well. Points of touching
    // parts of the class: upright at both ends of the points too, tried after every other
    // candidate (a start between them fits neither).
    std::size_t last_resort = candidates.size();
    if (attempt > 0 && support_plane_) {
      const RestingStarts starts = restingStarts(cloud, remaining, *support_plane_, model_.object_class);
      for (const world::Pose& seed : starts.middle) {
        candidates.push_back({seed, 0.0f});
      }
      last_resort = candidates.size();
      for (const world::Pose& seed : starts.ends) {
        candidates.push_back({seed, 0.0f});
      }
    }
    local.recognition += seconds(start);
    ++local.runs;
    local.candidates += static_cast<int>(candidates.size());

    // Verification. Candidates are ordered by a quick render-and-compare of their raw pose;
    // each is refined by a coarse ICP and checked again, and one that passes is refined and
    // checked in full. The run stops once the cluster's points are explained.
    start = std::chrono::steady_clock::now();
    std::vector<world::Pose> starts;
    starts.reserve(candidates.size());
    for (const auto& candidate : candidates) {
      starts.push_back(candidate.pose);
    }
    const auto order = rankStarts(starts, frame, last_resort);
    for (const auto& [raw_score, c] : order) {
      std::optional<Detection> detection =
          verify(cloud, candidates[c].pose, raw_score, frame, taken, accepted, &local.checked);
      if (!detection) {
        continue;
      }
      detection->recognition_score = candidates[c].match;
      accepted.push_back(*detection);
      markExplained(cloud, *detection, taken);
      if (explained(unexplainedPoints(cloud, cluster, accepted).size(), accepted)) {
        break;  // the cluster is explained
      }
    }
    local.refinement += seconds(start);

    // Points of the cluster that no detection explains: another run on them, if enough.
    const std::vector<int> unexplained = unexplainedPoints(cloud, cluster, accepted);
    const double instance_points = accepted.empty() ? static_cast<double>(cluster.size()) : meanSupport(accepted);
    if (static_cast<int>(unexplained.size()) < options_.min_cluster_points ||
        static_cast<double>(unexplained.size()) < options_.unexplained_fraction * instance_points) {
      break;
    }
    remaining = accepted.empty() ? cluster : unexplained;
  }
  auto start = std::chrono::steady_clock::now();
  splitStraddling(cloud, cluster, frame, accepted, &local.checked);
  local.refinement += seconds(start);
  if (timing != nullptr) {
    timing->recognition += local.recognition;
    timing->refinement += local.refinement;
    timing->runs += local.runs;
    timing->candidates += local.candidates;
    timing->checked += local.checked;
  }
  return accepted;
}

void ClassPoseEstimator::refineTouching(const Cloud& cloud, std::vector<Detection>& detections,
                                        const camera::RgbdFrame& frame) const {
  const double reach = model_.radius + 0.01;
  const auto distance = [this](const Detection& detection, const Eigen::Isometry3f& to_object,
                               const Eigen::Vector3f& p) {
    const Eigen::Vector3f q = to_object * p;
    const int nearest = model_.grid.lookup(q);
    return nearest < 0 ? std::numeric_limits<float>::max()
                       : (model_.surface.points[static_cast<std::size_t>(nearest)] - q).norm();
  };
  const Eigen::Vector3d size = model_.object_class.bounds().sizes();
  Eigen::Index longest = 0;
  size.maxCoeff(&longest);
  const bool elongated = isLongAxis(size, static_cast<int>(longest));
  std::vector<std::uint8_t> claimed(
      elongated ? static_cast<std::size_t>(frame.intrinsics.width) * static_cast<std::size_t>(frame.intrinsics.height)
                : 0,
      0);
  for (int round = 0; round < 2; ++round) {
    std::vector<Detection> updated = detections;
    std::vector<Eigen::Isometry3f> to_object;
    for (const auto& detection : detections) {
      to_object.push_back(detection.pose_in_camera.inverse().cast<float>());
    }
    for (std::size_t i = 0; i < detections.size(); ++i) {
      std::vector<std::size_t> neighbours;
      for (std::size_t j = 0; j < detections.size(); ++j) {
        if (j != i && (detections[i].pose_in_camera.translation() - detections[j].pose_in_camera.translation()).norm() <
                          2 * model_.radius + 0.01) {
          neighbours.push_back(j);
        }
      }
      if (neighbours.empty()) {
        continue;
      }
      // One pass over the points near it: its own (none nearer a neighbour's surface, within
      // reach) for the refinement, and, for an elongated part, those a neighbour's surface
      // explains (claimed) or not, within the slide's range.
      std::vector<Eigen::Vector3f> own;
      std::vector<int> claimed_pixels;
      std::vector<Eigen::Vector3f> unclaimed;
      const Eigen::Vector3f centre = detections[i].pose_in_camera.translation().cast<float>();
      const auto own_reach2 = static_cast<float>(reach * reach);
      const auto slide_reach = static_cast<float>(reach + 0.04);  // the slide's range
      const float scan_reach2 = elongated ? slide_reach * slide_reach : own_reach2;
      for (std::size_t k = 0; k < cloud.size(); ++k) {
        const Eigen::Vector3f& p = cloud.points[k];
        const float squared = (p - centre).squaredNorm();
        if (squared > scan_reach2) {
          continue;
        }
        float theirs = std::numeric_limits<float>::max();  // the nearest neighbour surface
        for (const std::size_t j : neighbours) {
          theirs = std::min(theirs, distance(detections[j], to_object[j], p));
        }
        if (squared <= own_reach2 && !(theirs < distance(detections[i], to_object[i], p))) {
          own.push_back(p);
        }
        if (elongated) {
          if (theirs <= static_cast<float>(0.5 * options_.depth_tolerance)) {
            claimed_pixels.push_back(cloud.pixels[k]);
          } else {
            unclaimed.push_back(p);
          }
        }
      }
      IcpResult refined = refinePose(model_, own, detections[i].pose_in_camera, 15, options_.icp_final_distance + 0.002,
                                     options_.icp_final_distance);
      if (refined.inliers < 10) {
        continue;
      }
      // An elongated part against a neighbour's side (a T of two links) can slide into it:
      // the neighbour's top at the same height confirms the slid part as well as its own far
      // end did. Slide it again with the neighbours' surface counted against it (the two
      // would overlap), and refine on the points they do not explain.
      if (elongated) {
        for (const int pixel : claimed_pixels) {
          claimed[static_cast<std::size_t>(pixel)] = 1;
        }
        const std::optional<world::Pose> slid = slideAlongLongAxes(refined.pose, frame, &claimed);
        for (const int pixel : claimed_pixels) {
          claimed[static_cast<std::size_t>(pixel)] = 0;
        }
        if (slid) {
          const IcpResult again = refinePose(model_, unclaimed, *slid, options_.icp_iterations / 2 + 1,
                                             options_.icp_final_distance + 0.002, options_.icp_final_distance);
          if (again.inliers >= 10) {
            refined = again;
          }
        }
      }
      const DepthAgreement agreement = compareWithDepth(model_, refined.pose, frame, options_.depth_tolerance);
      updated[i].pose_in_camera = refined.pose;
      updated[i].confidence = agreement.agreement();
      updated[i].visible_fraction = agreement.visibleFraction();
      updated[i].fit_rms = refined.rms;
      updated[i].support = refined.inliers;
    }
    detections = std::move(updated);
  }
}

std::vector<Detection> ClassPoseEstimator::estimate(const Cloud& cloud, const camera::RgbdFrame& frame,
                                                    Timing* timing) {
  std::vector<Detection> all;
  if (cloud.normals.size() != cloud.size() || cloud.pixels.size() != cloud.size()) {
    throw std::invalid_argument("ClassPoseEstimator::estimate: the points need normals and pixel indices");
  }
  const auto groups = clusters(cloud, frame.intrinsics);
  for (std::size_t c = 0; c < groups.size(); ++c) {
    auto found = estimateCluster(cloud, groups[c], frame, static_cast<std::uint32_t>(c), timing);
    all.insert(all.end(), found.begin(), found.end());
  }
  refineTouching(cloud, all, frame);
  return mergeBy(std::move(all), [this](const std::string&) -> const ObjectModel& { return model_; });
}

}  // namespace costar::perception
