#pragma once
// Stage 3 of the pipeline: SVM segmentation. Every voxel of the points above the table gets
// a label from the SVM (0 = background, else an object class's svm_label) on its FPFH and
// colour features; a majority vote among neighbouring voxels smooths the labels; each point
// takes its voxel's label. Touching parts of different classes end up in different classes'
// point sets.

#include <vector>

#include "perception/cloud.h"
#include "perception/features.h"
#include "perception/svm_classifier.h"

namespace costar::perception {

struct SegmentationOptions {
  FeatureOptions features;
  /// Each voxel takes the most common label among the voxels within this distance (m; 0: no
  /// smoothing). Ties keep the voxel's own label.
  double smoothing_radius = 0.012;
  /// Background-labelled points connected (neighbouring pixels closer than grow_step) to a
  /// class's points, within grow_reach of where the growth entered the background, join that
  /// class (nearest first; 0: no growth). A part's face the SVM confuses with background (a
  /// grey link's flat top, a part seen at a grazing angle) then still reaches pose estimation,
  /// whose depth-image check refuses what does not fit the class's model.
  double grow_step = 0.008;
  double grow_reach = 0.10;
};

struct SegmentationResult {
  /// Per input point: the SVM label of its voxel.
  std::vector<int> labels;
  int voxel_count = 0;
  /// Seconds spent computing features and classifying (with smoothing).
  double feature_seconds = 0.0;
  double classification_seconds = 0.0;
};

/// Labels `points` (with normals and colours). @throws std::invalid_argument when the
/// classifier's feature count is not kFeatureCount.
SegmentationResult segmentPoints(const Cloud& points, const SvmClassifier& classifier,
                                 const SegmentationOptions& options = {});

/// Grows class labels (non-zero) into connected background (0) points of an organized cloud
/// (`pixels` index an image `width` pixels wide): a breadth-first search from every class point
/// through 4-neighbouring pixels whose points are closer than `step`, up to `reach` from the
/// class point it started at. Returns the new labels.
std::vector<int> growLabels(const Cloud& points, int width, int height, std::vector<int> labels, double step,
                            double reach);

/// Majority vote of `labels` (one per point of `points`) among points within `radius` (m).
std::vector<int> smoothLabels(const std::vector<Eigen::Vector3f>& points, const std::vector<int>& labels,
                              double radius);

}  // namespace costar::perception
