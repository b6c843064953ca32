#pragma once
// The depth check of stage 4 (render and compare): how well a model under a pose agrees with
// the organized depth image it was found in, and how much of one model's volume another claims.
// Poses are object frame -> camera optical frame.

#include <cstdint>
#include <vector>

#include "camera/rgbd.h"
#include "perception/object_model.h"
#include "world/pose.h"

namespace costar::perception {

/// Render-and-compare: of the model surface samples that face the camera under `pose`
/// (object -> optical frame) and project into `frame`, how many the organized depth confirms
/// (within `tolerance`), contradicts (the camera sees farther), or cannot judge (something is
/// in front: occluded, or no reading).
struct DepthAgreement {
  int facing = 0;
  int confirmed = 0;
  int contradicted = 0;
  double agreement() const {
    return confirmed + contradicted == 0 ? 0.0 : double(confirmed) / (confirmed + contradicted);
  }
  double visibleFraction() const { return facing == 0 ? 0.0 : double(confirmed) / facing; }
};
/// `stride` > 1 checks every stride-th sample only (a quick score). A sample confirmed on a
/// `claimed` pixel (one per pixel of `frame`, non-zero: another detection's surface) counts
/// as contradicted instead: the two objects would overlap.
DepthAgreement compareWithDepth(const ObjectModel& model, const world::Pose& pose, const camera::RgbdFrame& frame,
                                double tolerance, int stride = 1, const std::vector<std::uint8_t>* claimed = nullptr);

/// Fraction of `a`'s interior samples (under pose_a) that lie inside `b`'s boxes (under pose_b)
/// shrunk by `margin` (m): how much of a's volume b claims too.
double overlapFraction(const ObjectModel& a, const world::Pose& pose_a, const ObjectModel& b, const world::Pose& pose_b,
                       double margin = 0.001);

/// A model under a pose (object -> optical frame).
struct PlacedModel {
  const ObjectModel* model = nullptr;
  world::Pose pose = world::Pose::Identity();
};
/// Fraction of `a`'s interior samples (under pose_a) that lie inside the boxes of any of
/// `others` shrunk by `margin` (m): how much of a's volume they claim together (a box fitted into
/// the gap between four touching nodes' tops lies a fifth or less in each of them, and almost
/// wholly in them together).
double overlapFraction(const ObjectModel& a, const world::Pose& pose_a, const std::vector<PlacedModel>& others,
                       double margin = 0.001);

}  // namespace costar::perception
