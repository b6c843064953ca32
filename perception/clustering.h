#pragma once
// Euclidean clustering (PCL): splits points into connected groups, e.g. one training example
// per object on a clear table, or the instances the pose estimator looks at one at a time.

#include <vector>

#include <Eigen/Core>

namespace costar::perception {

/// Groups `points` so that two points closer than `tolerance` (m) share a group; returns the
/// groups with at least `min_size` points as lists of indices, each sorted ascending, the
/// groups ordered by their first index (deterministic).
std::vector<std::vector<int>> euclideanClusters(const std::vector<Eigen::Vector3f>& points, double tolerance,
                                                int min_size = 1);

/// Connected groups of points from an organized image (fast, for the pipeline): two points
/// are connected when their pixels lie within `window` pixels of each other and their 3D
/// distance is below `tolerance` (m). `pixels[i]` is point i's index v * width + u. Returns
/// the groups of at least `min_size` points like euclideanClusters().
std::vector<std::vector<int>> organizedClusters(const std::vector<Eigen::Vector3f>& points,
                                                const std::vector<int>& pixels, int width, int height, double tolerance,
                                                int window = 2, int min_size = 1);

}  // namespace costar::perception
