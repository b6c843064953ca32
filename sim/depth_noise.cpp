#include "sim/depth_noise.h"

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <random>

namespace costar::sim {

double axialSigma(const DepthNoiseOptions& o, double z, double theta) {
  const double dz = z - o.axial_reference_depth;
  const double grazing = theta / (M_PI / 2 - theta);
  return o.axial_constant + o.axial_quadratic * dz * dz + 0.0001 / std::sqrt(z) * grazing * grazing;
}

double lateralSigma(const DepthNoiseOptions& o, double theta) {
  return o.lateral_constant + o.lateral_angular * theta / (M_PI / 2 - theta);
}

void noisyPointCloud(const std::vector<float>& depth, const camera::Intrinsics& in, const DepthNoiseOptions& o,
                     std::uint64_t seed, std::vector<Eigen::Vector3f>& points) {
  const int w = in.width;
  const int h = in.height;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  points.assign(static_cast<std::size_t>(w) * h, Eigen::Vector3f(nan, nan, nan));

  const auto valid = [&](int u, int v) {
    if (u < 0 || v < 0 || u >= w || v >= h) {
      return false;
    }
    const float z = depth[static_cast<std::size_t>(v) * w + u];
    return std::isfinite(z) && z > 0.0f;
  };
  const auto deproject = [&](double u, double v, double z) {
    return Eigen::Vector3d((u - in.cx) * z / in.fx, (v - in.cy) * z / in.fy, z);
  };
  const auto clean = [&](int u, int v) { return deproject(u, v, depth[static_cast<std::size_t>(v) * w + u]); };

  std::mt19937_64 random(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  const double max_theta = o.max_incidence_deg * M_PI / 180.0;
  const double focal_baseline = in.fx * o.baseline;

  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      if (!valid(u, v)) {
        continue;
      }
      const double z_clean = depth[static_cast<std::size_t>(v) * w + u];
      if (!o.enabled) {
        points[static_cast<std::size_t>(v) * w + u] = clean(u, v).cast<float>();
        continue;
      }
      if (z_clean < o.min_range || z_clean > o.max_range) {
        continue;
      }
      // Surface normal from the neighbours (central differences where possible).
      const int u0 = valid(u - 1, v) ? u - 1 : u;
      const int u1 = valid(u + 1, v) ? u + 1 : u;
      const int v0 = valid(u, v - 1) ? v - 1 : v;
      const int v1 = valid(u, v + 1) ? v + 1 : v;
      double theta = 0.0;
      if (u0 != u1 && v0 != v1) {
        const Eigen::Vector3d normal_vector = (clean(u1, v) - clean(u0, v)).cross(clean(u, v1) - clean(u, v0));
        const Eigen::Vector3d ray = clean(u, v).normalized();
        if (normal_vector.norm() > 0) {
          theta = std::acos(std::min(1.0, std::abs(normal_vector.normalized().dot(ray))));
        }
      }
      if (theta > max_theta) {
        continue;  // grazing: the projected pattern is not seen
      }
      // Lateral noise: the reading comes from a jittered pixel.
      const double sigma_l = lateralSigma(o, theta);
      const int su = static_cast<int>(std::lround(u + sigma_l * normal(random)));
      const int sv = static_cast<int>(std::lround(v + sigma_l * normal(random)));
      if (!valid(su, sv)) {
        continue;  // the jitter fell off the surface: no reading
      }
      double z = depth[static_cast<std::size_t>(sv) * w + su];
      z += axialSigma(o, z, theta) * normal(random);
      if (o.quantize_disparity && z > 0) {
        const double disparity = std::round(focal_baseline / z / o.disparity_step) * o.disparity_step;
        if (disparity <= 0) {
          continue;
        }
        z = focal_baseline / disparity;
      }
      if (z < o.min_range || z > o.max_range) {
        continue;
      }
      points[static_cast<std::size_t>(v) * w + u] = deproject(u, v, z).cast<float>();
    }
  }
}

}  // namespace costar::sim
