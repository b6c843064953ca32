#include "perception/features.h"

#include <pcl/features/fpfh_omp.h>
#include <pcl/point_types.h>
#include <pcl/search/kdtree.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <unordered_map>

namespace costar::perception {

Eigen::Matrix<float, kColorFeatures, 1> colorFeatures(const Rgb& color) {
  const float r = color[0] / 255.0f;
  const float g = color[1] / 255.0f;
  const float b = color[2] / 255.0f;
  const float sum = std::max(r + g + b, 1e-3f);
  const float high = std::max({r, g, b});
  const float low = std::min({r, g, b});
  const float saturation = high > 1e-3f ? (high - low) / high : 0.0f;
  // Hue angle from the opponent colour axes (no branch cuts).
  const float alpha = r - 0.5f * (g + b);
  const float beta = 0.8660254f * (g - b);
  const float length = std::hypot(alpha, beta);
  const float hue_x = length > 1e-4f ? alpha / length : 0.0f;
  const float hue_y = length > 1e-4f ? beta / length : 0.0f;
  Eigen::Matrix<float, kColorFeatures, 1> out;
  out << r / sum, g / sum, high, saturation, saturation * hue_x, saturation * hue_y;
  return out;
}

VoxelFeatures computeFeatures(const Cloud& points, const FeatureOptions& options) {
  if (points.normals.size() != points.size() || points.colors.size() != points.size()) {
    throw std::invalid_argument("computeFeatures: the points need normals and colours");
  }
  VoxelFeatures out;
  out.voxel_of_point.assign(points.size(), -1);
  // Voxels, in order of their first point.
  std::unordered_map<std::int64_t, int> index;
  index.reserve(points.size());
  std::vector<Eigen::Vector3f> sum_points;
  std::vector<Eigen::Vector3f> sum_normals;
  std::vector<Eigen::Vector3f> sum_colors;
  std::vector<int> counts;
  const double inverse = 1.0 / options.voxel_size;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3i cell = (points.points[i].cast<double>() * inverse).array().floor().cast<int>();
    const std::int64_t key = (static_cast<std::int64_t>(cell.x() & 0x1FFFFF) << 42) |
                             (static_cast<std::int64_t>(cell.y() & 0x1FFFFF) << 21) |
                             static_cast<std::int64_t>(cell.z() & 0x1FFFFF);
    auto [it, inserted] = index.emplace(key, static_cast<int>(counts.size()));
    if (inserted) {
      sum_points.emplace_back(Eigen::Vector3f::Zero());
      sum_normals.emplace_back(Eigen::Vector3f::Zero());
      sum_colors.emplace_back(Eigen::Vector3f::Zero());
      counts.push_back(0);
    }
    const int v = it->second;
    out.voxel_of_point[i] = v;
    sum_points[static_cast<std::size_t>(v)] += points.points[i];
    sum_normals[static_cast<std::size_t>(v)] += points.normals[i];
    sum_colors[static_cast<std::size_t>(v)] +=
        Eigen::Vector3f(points.colors[i][0], points.colors[i][1], points.colors[i][2]);
    ++counts[static_cast<std::size_t>(v)];
  }
  const std::size_t voxels = counts.size();
  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud(new pcl::PointCloud<pcl::PointXYZ>);
  pcl::PointCloud<pcl::Normal>::Ptr normals(new pcl::PointCloud<pcl::Normal>);
  cloud->reserve(voxels);
  normals->reserve(voxels);
  for (std::size_t v = 0; v < voxels; ++v) {
    const float n = static_cast<float>(counts[v]);
    const Eigen::Vector3f p = sum_points[v] / n;
    Eigen::Vector3f normal = sum_normals[v];
    normal = normal.norm() > 1e-6f ? Eigen::Vector3f(normal.normalized()) : Eigen::Vector3f(-p.normalized());
    const Eigen::Vector3f c = sum_colors[v] / n;
    out.voxels.points.push_back(p);
    out.voxels.normals.push_back(normal);
    out.voxels.colors.push_back({static_cast<std::uint8_t>(std::lround(c.x())),
                                 static_cast<std::uint8_t>(std::lround(c.y())),
                                 static_cast<std::uint8_t>(std::lround(c.z()))});
    cloud->push_back(pcl::PointXYZ(p.x(), p.y(), p.z()));
    normals->push_back(pcl::Normal(normal.x(), normal.y(), normal.z()));
  }
  out.features.setZero(static_cast<Eigen::Index>(voxels), kFeatureCount);
  if (voxels == 0) {
    return out;
  }
  pcl::FPFHEstimationOMP<pcl::PointXYZ, pcl::Normal, pcl::FPFHSignature33> fpfh(
      static_cast<unsigned>(std::clamp(options.threads, 1, 16)));
  pcl::search::KdTree<pcl::PointXYZ>::Ptr tree(new pcl::search::KdTree<pcl::PointXYZ>);
  fpfh.setInputCloud(cloud);
  fpfh.setInputNormals(normals);
  fpfh.setSearchMethod(tree);
  fpfh.setRadiusSearch(options.fpfh_radius);
  pcl::PointCloud<pcl::FPFHSignature33> histograms;
  fpfh.compute(histograms);
  for (std::size_t v = 0; v < voxels; ++v) {
    const auto& h = histograms[v].histogram;
    for (int b = 0; b < kFpfhBins; ++b) {
      const float value = h[b];
      out.features(static_cast<Eigen::Index>(v), b) = std::isfinite(value) ? value / 100.0f : 0.0f;
    }
    out.features.block<1, kColorFeatures>(static_cast<Eigen::Index>(v), kFpfhBins) =
        colorFeatures(out.voxels.colors[v]).transpose();
  }
  return out;
}

}  // namespace costar::perception
