#include "perception/clustering.h"

#include <pcl/point_types.h>
#include <pcl/search/kdtree.h>
#include <pcl/segmentation/extract_clusters.h>

#include <algorithm>

namespace costar::perception {

std::vector<std::vector<int>> euclideanClusters(const std::vector<Eigen::Vector3f>& points, double tolerance,
                                                int min_size) {
  std::vector<std::vector<int>> clusters;
  if (points.empty()) {
    return clusters;
  }
  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud(new pcl::PointCloud<pcl::PointXYZ>);
  cloud->reserve(points.size());
  for (const auto& p : points) {
    cloud->push_back(pcl::PointXYZ(p.x(), p.y(), p.z()));
  }
  pcl::search::KdTree<pcl::PointXYZ>::Ptr tree(new pcl::search::KdTree<pcl::PointXYZ>);
  tree->setInputCloud(cloud);
  pcl::EuclideanClusterExtraction<pcl::PointXYZ> extraction;
  extraction.setClusterTolerance(tolerance);
  extraction.setMinClusterSize(std::max(1, min_size));
  extraction.setMaxClusterSize(static_cast<int>(points.size()));
  extraction.setSearchMethod(tree);
  extraction.setInputCloud(cloud);
  std::vector<pcl::PointIndices> found;
  extraction.extract(found);
  for (auto& indices : found) {
    std::vector<int> cluster(indices.indices.begin(), indices.indices.end());
    std::sort(cluster.begin(), cluster.end());
    clusters.push_back(std::move(cluster));
  }
  std::sort(clusters.begin(), clusters.end(),
            [](const std::vector<int>& a, const std::vector<int>& b) { return a.front() < b.front(); });
  return clusters;
}

std::vector<std::vector<int>> organizedClusters(const std::vector<Eigen::Vector3f>& points,
                                                const std::vector<int>& pixels, int width, int height, double tolerance,
                                                int window, int min_size) {
  const std::size_t count = points.size();
  std::vector<int> at(static_cast<std::size_t>(width) * height, -1);
  for (std::size_t i = 0; i < count; ++i) {
    at[static_cast<std::size_t>(pixels[i])] = static_cast<int>(i);
  }
  std::vector<int> parent(count);
  for (std::size_t i = 0; i < count; ++i) {
    parent[i] = static_cast<int>(i);
  }
  const auto root = [&parent](int i) {
    while (parent[static_cast<std::size_t>(i)] != i) {
      parent[static_cast<std::size_t>(i)] = parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(i)])];
      i = parent[static_cast<std::size_t>(i)];
    }
    return i;
  };
  const float squared = static_cast<float>(tolerance * tolerance);
  for (std::size_t i = 0; i < count; ++i) {
    const int u0 = pixels[i] % width;
    const int v0 = pixels[i] / width;
    // Forward half of the window: each pair is looked at once.
    for (int dv = 0; dv <= window; ++dv) {
      const int v = v0 + dv;
      if (v >= height) {
        break;
      }
      for (int du = -window; du <= window; ++du) {
        if (dv == 0 && du <= 0) {
          continue;
        }
        const int u = u0 + du;
        if (u < 0 || u >= width) {
          continue;
        }
        const int j = at[static_cast<std::size_t>(v) * width + u];
        if (j < 0 || (points[i] - points[static_cast<std::size_t>(j)]).squaredNorm() > squared) {
          continue;
        }
        const int a = root(static_cast<int>(i));
        const int b = root(j);
        if (a != b) {
          parent[static_cast<std::size_t>(std::max(a, b))] = std::min(a, b);
        }
      }
    }
  }
  std::vector<int> group_of(count, -1);
  std::vector<std::vector<int>> groups;
  for (std::size_t i = 0; i < count; ++i) {
    const int r = root(static_cast<int>(i));
    if (group_of[static_cast<std::size_t>(r)] < 0) {
      group_of[static_cast<std::size_t>(r)] = static_cast<int>(groups.size());
      groups.emplace_back();
    }
    groups[static_cast<std::size_t>(group_of[static_cast<std::size_t>(r)])].push_back(static_cast<int>(i));
  }
  std::vector<std::vector<int>> clusters;
  for (auto& group : groups) {
    if (static_cast<int>(group.size()) >= min_size) {
      clusters.push_back(std::move(group));
    }
  }
  return clusters;
}

}  // namespace costar::perception
