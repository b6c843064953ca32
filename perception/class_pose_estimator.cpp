#include <algorithm>
#include <chrono>
#include <cmath>
#include <set>
#include <stdexcept>
#include <tuple>

#include "perception/clustering.h"
#include "perception/pose_estimation.h"
#include "perception/seeded_obj_rec_ransac.h"

namespace costar::perception {

namespace {

double seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

}  // namespace

struct ClassPoseEstimator::Impl {
  std::unique_ptr<SeededObjRecRansac> recognizer;
  /// Full leaves of ObjRecRANSAC's model octree: the scale of "one instance" in a scene.
  double model_leaves = 0.0;
};

ClassPoseEstimator::ClassPoseEstimator(const ObjectModel& model, PoseEstimationOptions options)
    : model_(model), options_(options), impl_(std::make_unique<Impl>()) {
  const ClassParameters& p = model.parameters;
  // The model: the surface samples thinned to one per recognition_spacing cell and face.
  std::vector<Eigen::Vector3f> points;
  std::vector<Eigen::Vector3f> normals;
  std::set<std::tuple<int, int, int, int, int, int>> taken;
  for (std::size_t i = 0; i < model.surface.size(); ++i) {
    const Eigen::Vector3f& q = model.surface.points[i];
    const Eigen::Vector3f& n = model.surface.normals[i];
    const Eigen::Vector3i cell = (q.cast<double>() / p.recognition_spacing).array().floor().cast<int>();
    const Eigen::Vector3i direction = n.array().round().cast<int>();
    if (!taken.insert({cell.x(), cell.y(), cell.z(), direction.x(), direction.y(), direction.z()}).second) {
      continue;
    }
    points.push_back(q);
    normals.push_back(n);
  }
  SeededObjRecRansac::Parameters parameters;
  parameters.pair_width = static_cast<float>(p.pair_width);
  parameters.voxel_size = static_cast<float>(p.voxel_size);
  parameters.visibility = static_cast<float>(p.visibility);
  parameters.penalty_fraction = static_cast<float>(p.penalty_fraction);
  try {
    impl_->recognizer = std::make_unique<SeededObjRecRansac>(points, normals, parameters);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error("ObjRecRANSAC refused the model of class '" + model.name() + "': " + e.what());
  }
  impl_->model_leaves = static_cast<double>(impl_->recognizer->modelLeaves());
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

}  // namespace

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

bool ClassPoseEstimator::raised(const world::Pose& pose) const {
  if (!support_plane_) {
    return false;
  }
  const Eigen::Isometry3f transform = pose.cast<float>();
  return std::all_of(model_.interior.begin(), model_.interior.end(), [&](const Eigen::Vector3f& interior) {
    return support_plane_->height(transform * interior) > kRaisedSupport;
  });
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

bool isElongated(const Eigen::Vector3d& size) { return size.maxCoeff() >= kLongAxis * size.minCoeff(); }

/// A coarse pose of an elongated part that the depth image agrees with this much less than a
/// detection needs is slid along its length before it is rejected (verify).
constexpr double kSlideBeforeRejecting = 0.3;

}  // namespace

bool ClassPoseEstimator::isLongAxis(const Eigen::Vector3d& size, int axis) {
  return size[axis] >= kLongAxis * size.minCoeff();
}

void ClassPoseEstimator::levelResting(std::vector<Detection>& detections, const camera::RgbdFrame& frame) const {
  if (!support_plane_) {
    return;
  }
  constexpr double kLevelFrom = 1.0 * M_PI / 180.0;
  constexpr double kLevelUpTo = kLeaning;
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
  std::vector<PlacedModel> placed;
  placed.reserve(accepted.size());
  for (const Detection& other : accepted) {
    placed.push_back({&model_, other.pose_in_camera});
  }
  const auto overlapsAccepted = [&](const world::Pose& pose) {
    return overlapFraction(model_, pose, placed) > kOverlapTaken;
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
    std::vector<Eigen::Vector3f> points;
    std::vector<Eigen::Vector3f> normals;
    points.reserve(remaining.size());
    normals.reserve(remaining.size());
    std::vector<std::int64_t> keys;
    keys.reserve(remaining.size());
    for (const int i : remaining) {
      const Eigen::Vector3f& q = cloud.points[static_cast<std::size_t>(i)];
      const Eigen::Vector3f& n = cloud.normals[static_cast<std::size_t>(i)];
      points.push_back(q);
      normals.push_back(n);
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
      for (const world::Pose& seed : principalAxisSeeds(cloud, remaining, model_.object_class)) {
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
  return mergeDetections(std::move(all), model_);
}

}  // namespace costar::perception
