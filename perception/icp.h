#pragma once
// Point-to-plane ICP of scene points onto an object model's surface (stage 4 of the pipeline:
// each ObjRecRANSAC hypothesis is refined so before it is checked against the depth image).
// Poses are object frame -> camera optical frame.

#include <Eigen/Core>
#include <vector>

#include "perception/object_model.h"
#include "world/pose.h"

namespace costar::perception {

/// Result of refining a pose.
struct IcpResult {
  world::Pose pose = world::Pose::Identity();
  int inliers = 0;
  double rms = 0.0;
  int iterations = 0;
};

/// Point-to-plane ICP of `scene` (points in the camera frame) onto the model's surface,
/// starting from `initial` (object -> camera). Correspondences come from the model's grid of
/// nearest surface samples; the gate shrinks from `initial_distance` to `final_distance` (m)
/// and residuals are Huber-weighted; while it shrinks, an iteration uses an even subset of at
/// most 300 of the points, from the final gate on all of them. `point_to_point_weight` > 0 adds
/// that much of a point-to-point term (pulls an object that slid along a face back over its points).
IcpResult refinePose(const ObjectModel& model, const std::vector<Eigen::Vector3f>& scene, const world::Pose& initial,
                     int iterations, double initial_distance, double final_distance,
                     double point_to_point_weight = 0.0);

}  // namespace costar::perception
