#pragma once
// Local shape and colour features for the SVM segmentation (stage 3): the points above the
// table are grouped into small voxels; each voxel gets an FPFH histogram (PCL; Rusu et al.
// 2009: 33 bins of the angles between its normal and its neighbours' within a radius) and six
// colour values (chromaticity, value, saturation, hue as a vector scaled by saturation).

#include <Eigen/Core>
#include <vector>

#include "perception/cloud.h"

namespace costar::perception {

struct FeatureOptions {
  /// Edge of the classification voxels (m).
  double voxel_size = 0.008;
  /// Neighbourhood radius of the FPFH histograms (m).
  double fpfh_radius = 0.02;
  /// Threads computing the histograms (PCL's OpenMP estimator; the same histograms for any).
  int threads = 1;
};

/// FPFH bins, colour values, and their total.
inline constexpr int kFpfhBins = 33;
inline constexpr int kColorFeatures = 6;
inline constexpr int kFeatureCount = kFpfhBins + kColorFeatures;

struct VoxelFeatures {
  /// One point per occupied voxel: the centroid, mean normal (unit), mean colour.
  Cloud voxels;
  /// For each input point, the index of its voxel.
  std::vector<int> voxel_of_point;
  /// One row per voxel, kFeatureCount columns: FPFH bins / 100, then colour.
  Eigen::MatrixXf features;
};

/// Groups `points` (which must have normals and colours) into voxels and computes their
/// features. Deterministic: voxels are ordered by their first point.
/// @throws std::invalid_argument if normals or colours are missing.
VoxelFeatures computeFeatures(const Cloud& points, const FeatureOptions& options = {});

/// The six colour features of an RGB colour.
Eigen::Matrix<float, kColorFeatures, 1> colorFeatures(const Rgb& color);

}  // namespace costar::perception
