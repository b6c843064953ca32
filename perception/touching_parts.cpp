#include <algorithm>
#include <limits>

#include "perception/pose_estimation.h"

namespace costar::perception {

// Parts of a class touching each other: a detection straddling two of them end to end is
// replaced by detections at both ends (splitStraddling); touching detections are refined on
// the points nearer their own surface, and an elongated one slides along its length with its
// neighbours' surface counted against it (refineTouching, slideAlongLongAxes).

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
      // The refined pose must pass what verify() asked of the detection; else it stays where it
      // was (a link refined among its neighbours' points was pulled 2.6-6.2 cm below the table
      // with confidence 0.50, iiwa-3f-sim seed 202 scene 9).
      const DepthAgreement agreement = compareWithDepth(model_, refined.pose, frame, options_.depth_tolerance);
      if (agreement.agreement() < options_.min_confidence ||
          agreement.visibleFraction() < options_.min_visible_fraction || !aboveSupport(refined.pose)) {
        continue;
      }
      updated[i].pose_in_camera = refined.pose;
      updated[i].confidence = agreement.agreement();
      updated[i].visible_fraction = agreement.visibleFraction();
      updated[i].fit_rms = refined.rms;
      updated[i].support = refined.inliers;
    }
    detections = std::move(updated);
  }
}

}  // namespace costar::perception
