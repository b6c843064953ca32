#include "sim/depth_noise.h"

#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <limits>

namespace costar::sim {

double axialSigma(const DepthNoiseOptions& o, double z, double theta) {
  const double dz = z - o.axial_reference_depth;
  const double grazing = theta / (M_PI / 2 - theta);
  return o.axial_constant + o.axial_quadratic * dz * dz + 0.0001 / std::sqrt(z) * grazing * grazing;
}

double lateralSigma(const DepthNoiseOptions& o, double theta) {
  return o.lateral_constant + o.lateral_angular * theta / (M_PI / 2 - theta);
}

namespace {

/// xoshiro256+ (Blackman and Vigna), seeded with splitmix64: fast, good enough for noise.
class FastRandom {
 public:
  explicit FastRandom(std::uint64_t seed) {
    for (auto& word : state_) {
      seed += 0x9E3779B97F4A7C15ull;
      std::uint64_t z = seed;
      z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
      z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
      word = z ^ (z >> 31);
    }
  }
  /// Uniform in (0, 1].
  double uniform() { return (static_cast<double>(next() >> 11) + 1.0) * (1.0 / 9007199254740992.0); }
  std::uint64_t next() {
    const std::uint64_t result = state_[0] + state_[3];
    const std::uint64_t t = state_[1] << 17;
    state_[2] ^= state_[0];
    state_[3] ^= state_[1];
    state_[1] ^= state_[2];
    state_[0] ^= state_[3];
    state_[2] ^= t;
    state_[3] = (state_[3] << 45) | (state_[3] >> 19);
    return result;
  }

 private:
  std::uint64_t state_[4];
};

/// 2^16 standard normal variates (Box-Muller, fixed seed), drawn from with random indices:
/// a sensor-noise generator three times as fast as sampling each one.
class NormalTable {
 public:
  NormalTable() {
    FastRandom random(0x5EED);
    for (std::size_t i = 0; i < kSize; i += 2) {
      const double radius = std::sqrt(-2.0 * std::log(random.uniform()));
      const double angle = 2.0 * M_PI * random.uniform();
      values_[i] = static_cast<float>(radius * std::cos(angle));
      values_[i + 1] = static_cast<float>(radius * std::sin(angle));
    }
  }
  /// A standard normal picked by the low 16 bits of `bits`.
  float operator[](std::uint64_t bits) const { return values_[bits & (kSize - 1)]; }

 private:
  static constexpr std::size_t kSize = 1u << 16;
  std::array<float, kSize> values_;
};

const NormalTable& normals() {
  static const NormalTable table;
  return table;
}

int roundToInt(double x) { return static_cast<int>(std::floor(x + 0.5)); }

}  // namespace

void noisyPointCloud(const std::vector<float>& depth, const camera::Intrinsics& in, const DepthNoiseOptions& o,
                     std::uint64_t seed, std::vector<Eigen::Vector3f>& points) {
  const int w = in.width;
  const int h = in.height;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  points.assign(static_cast<std::size_t>(w) * h, Eigen::Vector3f(nan, nan, nan));

  // Rays through each pixel (z = 1): a point is depth * ray.
  std::vector<float> ray_x(static_cast<std::size_t>(w));
  std::vector<float> ray_y(static_cast<std::size_t>(h));
  for (int u = 0; u < w; ++u) {
    ray_x[u] = static_cast<float>((u - in.cx) / in.fx);
  }
  for (int v = 0; v < h; ++v) {
    ray_y[v] = static_cast<float>((v - in.cy) / in.fy);
  }
  const auto at = [&](int u, int v) { return depth[static_cast<std::size_t>(v) * w + u]; };
  const auto valid = [&](int u, int v) {
    if (u < 0 || v < 0 || u >= w || v >= h) {
      return false;
    }
    const float z = at(u, v);
    return z > 0.0f && std::isfinite(z);
  };
  const auto point = [&](int u, int v) {
    const float z = at(u, v);
    return Eigen::Vector3f(ray_x[u] * z, ray_y[v] * z, z);
  };

  FastRandom random(seed);
  const NormalTable& normal = normals();
  const float cos_max = static_cast<float>(std::cos(o.max_incidence_deg * M_PI / 180.0));
  const double focal_baseline = in.fx * o.baseline;

  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      if (!valid(u, v)) {
        continue;
      }
      const float z_clean = at(u, v);
      Eigen::Vector3f& out = points[static_cast<std::size_t>(v) * w + u];
      if (!o.enabled) {
        out = point(u, v);
        continue;
      }
      if (z_clean < o.min_range || z_clean > o.max_range) {
        continue;
      }
      // Surface normal from the neighbours (central differences where possible); the
      // incidence angle between it and the viewing ray.
      const int u0 = valid(u - 1, v) ? u - 1 : u;
      const int u1 = valid(u + 1, v) ? u + 1 : u;
      const int v0 = valid(u, v - 1) ? v - 1 : v;
      const int v1 = valid(u, v + 1) ? v + 1 : v;
      double theta = 0.0;
      if (u0 != u1 && v0 != v1) {
        const Eigen::Vector3f normal = (point(u1, v) - point(u0, v)).cross(point(u, v1) - point(u, v0));
        const Eigen::Vector3f ray(ray_x[u], ray_y[v], 1.0f);
        const float scale = normal.norm() * ray.norm();
        if (scale > 0.0f) {
          const float cosine = std::min(1.0f, std::abs(normal.dot(ray)) / scale);
          if (cosine < cos_max) {
            continue;  // grazing: the projected pattern is not seen
          }
          theta = std::acos(cosine);
        }
      }
      // Lateral noise: the reading comes from a jittered pixel.
      const std::uint64_t bits = random.next();  // 16 bits for each of the three normals
      const double sigma_l = lateralSigma(o, theta);
      const int su = roundToInt(u + sigma_l * normal[bits]);
      const int sv = roundToInt(v + sigma_l * normal[bits >> 16]);
      if (!valid(su, sv)) {
        continue;  // the jitter fell off the surface: no reading
      }
      double z = at(su, sv);
      z += axialSigma(o, z, theta) * normal[bits >> 32];
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
      out = Eigen::Vector3f(static_cast<float>(ray_x[u] * z), static_cast<float>(ray_y[v] * z), static_cast<float>(z));
    }
  }
}

}  // namespace costar::sim
