#include "perception/segmentation.h"

#include <array>
#include <deque>

#include <chrono>
#include <cmath>
#include <map>
#include <stdexcept>
#include <unordered_map>

namespace costar::perception {

std::vector<int> smoothLabels(const std::vector<Eigen::Vector3f>& points, const std::vector<int>& labels,
                              double radius) {
  if (radius <= 0 || points.empty()) {
    return labels;
  }
  // Buckets of `radius`: neighbours lie in the 27 around a point's own.
  const auto cell = [radius](const Eigen::Vector3f& p) {
    return Eigen::Vector3i((p.cast<double>() / radius).array().floor().cast<int>());
  };
  const auto key = [](const Eigen::Vector3i& c) {
    return (static_cast<std::int64_t>(c.x() & 0x1FFFFF) << 42) | (static_cast<std::int64_t>(c.y() & 0x1FFFFF) << 21) |
           static_cast<std::int64_t>(c.z() & 0x1FFFFF);
  };
  std::unordered_map<std::int64_t, std::vector<int>> buckets;
  for (std::size_t i = 0; i < points.size(); ++i) {
    buckets[key(cell(points[i]))].push_back(static_cast<int>(i));
  }
  const float squared = static_cast<float>(radius * radius);
  std::vector<int> out(labels.size());
  std::map<int, int> votes;
  for (std::size_t i = 0; i < points.size(); ++i) {
    votes.clear();
    const Eigen::Vector3i c = cell(points[i]);
    for (int dz = -1; dz <= 1; ++dz) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const auto it = buckets.find(key(c + Eigen::Vector3i(dx, dy, dz)));
          if (it == buckets.end()) {
            continue;
          }
          for (const int j : it->second) {
            if ((points[static_cast<std::size_t>(j)] - points[i]).squaredNorm() <= squared) {
              ++votes[labels[static_cast<std::size_t>(j)]];
            }
          }
        }
      }
    }
    int best = labels[i];
    int best_votes = votes[best];
    for (const auto& [label, count] : votes) {
      if (count > best_votes) {
        best = label;
        best_votes = count;
      }
    }
    out[i] = best;
  }
  return out;
}

SegmentationResult segmentPoints(const Cloud& points, const SvmClassifier& classifier,
                                 const SegmentationOptions& options) {
  if (classifier.featureCount() != kFeatureCount) {
    throw std::invalid_argument("segmentPoints: the SVM expects " + std::to_string(classifier.featureCount()) +
                                " features, this build computes " + std::to_string(kFeatureCount) +
                                " (retrain with `costar perception train`)");
  }
  SegmentationResult result;
  auto start = std::chrono::steady_clock::now();
  const VoxelFeatures voxels = computeFeatures(points, options.features);
  result.voxel_count = static_cast<int>(voxels.voxels.size());
  result.feature_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  start = std::chrono::steady_clock::now();
  const std::vector<int> voxel_labels =
      smoothLabels(voxels.voxels.points, classifier.predict(voxels.features), options.smoothing_radius);
  result.labels.resize(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    result.labels[i] = voxel_labels[static_cast<std::size_t>(voxels.voxel_of_point[i])];
  }
  result.classification_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

std::vector<int> growLabels(const Cloud& points, int width, int height, std::vector<int> labels, double step,
                            double reach) {
  if (labels.size() != points.size()) {
    throw std::invalid_argument("growLabels: one label per point expected");
  }
  std::vector<int> at(static_cast<std::size_t>(width) * static_cast<std::size_t>(height), -1);
  for (std::size_t i = 0; i < points.size(); ++i) {
    at[static_cast<std::size_t>(points.pixels[i])] = static_cast<int>(i);
  }
  const float step2 = static_cast<float>(step * step);
  const float reach2 = static_cast<float>(reach * reach);
  std::vector<int> origin(points.size(), -1);
  std::deque<int> queue;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (labels[i] != 0) {
      origin[i] = static_cast<int>(i);
      queue.push_back(static_cast<int>(i));
    }
  }
  while (!queue.empty()) {
    const int p = queue.front();
    queue.pop_front();
    const int pixel = points.pixels[static_cast<std::size_t>(p)];
    const int u = pixel % width;
    const int v = pixel / width;
    const std::array<std::pair<int, int>, 4> around = {{{u - 1, v}, {u + 1, v}, {u, v - 1}, {u, v + 1}}};
    for (const auto& [nu, nv] : around) {
      if (nu < 0 || nv < 0 || nu >= width || nv >= height) {
        continue;
      }
      const int q = at[static_cast<std::size_t>(nv) * width + nu];
      if (q < 0 || origin[static_cast<std::size_t>(q)] >= 0 || labels[static_cast<std::size_t>(q)] != 0) {
        continue;
      }
      const Eigen::Vector3f& point = points.points[static_cast<std::size_t>(q)];
      if ((point - points.points[static_cast<std::size_t>(p)]).squaredNorm() > step2 ||
          (point - points.points[static_cast<std::size_t>(origin[static_cast<std::size_t>(p)])]).squaredNorm() >
              reach2) {
        continue;
      }
      labels[static_cast<std::size_t>(q)] = labels[static_cast<std::size_t>(p)];
      origin[static_cast<std::size_t>(q)] = origin[static_cast<std::size_t>(p)];
      queue.push_back(q);
    }
  }
  return labels;
}

}  // namespace costar::perception
