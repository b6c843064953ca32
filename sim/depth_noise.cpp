#include "sim/depth_noise.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <thread>

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

struct Scratch {
  std::vector<float> ray_x;
  std::vector<float> ray_y;
  std::vector<std::uint8_t> surface;
  std::vector<float> incidence;
  std::vector<std::uint32_t> reading_rows;
  std::vector<std::uint64_t> draws;
};

int roundToInt(double x) { return static_cast<int>(std::floor(x + 0.5)); }

/// Runs `rows(v_begin, v_end)` over [0, height) on `threads` threads (the calling one included).
template <typename Rows>
void parallelRows(int height, int threads, const Rows& rows) {
  if (threads <= 1 || height < 2) {
    rows(0, height);
    return;
  }
  std::vector<std::thread> helpers;
  for (int t = 1; t < threads; ++t) {
    helpers.emplace_back(rows, height * t / threads, height * (t + 1) / threads);
  }
  rows(0, height / threads);
  for (auto& helper : helpers) {
    helper.join();
  }
}

}  // namespace

// Three passes, so that the expensive ones run on several threads while the noise stays a
// function of the seed alone: (1) per pixel, whether it gets a reading and its incidence angle
// (parallel); (2) the random bits, drawn in pixel order for the pixels that read (serial, cheap);
// (3) the jittered, noisy, quantized reading (parallel). The result is the same for any number
// of threads, and the same as drawing while scanning the image once.
void noisyPointCloud(const std::vector<float>& depth, const camera::Intrinsics& in, const DepthNoiseOptions& o,
                     std::uint64_t seed, std::vector<Eigen::Vector3f>& points, int threads) {
  const int w = in.width;
  const int h = in.height;
  const std::size_t pixels = static_cast<std::size_t>(w) * h;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  points.resize(pixels);  // every pixel is written below
  threads = std::clamp(threads, 1, 8);

  // Scratch kept per calling thread: a camera's frames come one after another, and fresh
  // megabytes for each would be cleared and page-faulted in again every frame.
  thread_local Scratch scratch;
  // Rays through each pixel (z = 1): a point is depth * ray.
  std::vector<float>& ray_x = scratch.ray_x;
  std::vector<float>& ray_y = scratch.ray_y;
  ray_x.resize(static_cast<std::size_t>(w));
  ray_y.resize(static_cast<std::size_t>(h));
  for (int u = 0; u < w; ++u) {
    ray_x[u] = static_cast<float>((u - in.cx) / in.fx);
  }
  for (int v = 0; v < h; ++v) {
    ray_y[v] = static_cast<float>((v - in.cy) / in.fy);
  }
  const float* const z_at = depth.data();
  // 1 where the clean image has a surface.
  std::vector<std::uint8_t>& surface = scratch.surface;
  surface.resize(pixels);
  for (std::size_t i = 0; i < pixels; ++i) {
    const float z = z_at[i];
    surface[i] = z > 0.0f && std::isfinite(z) ? 1 : 0;
  }
  const std::uint8_t* const ok = surface.data();
  const auto valid = [&](int u, int v) {
    return static_cast<unsigned>(u) < static_cast<unsigned>(w) && static_cast<unsigned>(v) < static_cast<unsigned>(h) &&
           ok[static_cast<std::size_t>(v) * w + u] != 0;
  };
  const auto point = [&](int u, int v) {
    const float z = z_at[static_cast<std::size_t>(v) * w + u];
    return Eigen::Vector3f(ray_x[u] * z, ray_y[v] * z, z);
  };

  if (!o.enabled) {
    for (int v = 0; v < h; ++v) {
      for (int u = 0; u < w; ++u) {
        points[static_cast<std::size_t>(v) * w + u] = valid(u, v) ? point(u, v) : Eigen::Vector3f(nan, nan, nan);
      }
    }
    return;
  }

  // Pass 1: the incidence angle of each pixel that reads (NaN: no reading), and how many read
  // in each row.
  const float cos_max = static_cast<float>(std::cos(o.max_incidence_deg * M_PI / 180.0));
  std::vector<float>& incidence = scratch.incidence;
  incidence.resize(pixels);
  std::vector<std::uint32_t>& reading_rows = scratch.reading_rows;
  reading_rows.assign(static_cast<std::size_t>(h) + 1, 0);
  parallelRows(h, threads, [&](int v_begin, int v_end) {
    for (int v = v_begin; v < v_end; ++v) {
      std::uint32_t reading = 0;
      for (int u = 0; u < w; ++u) {
        const std::size_t i = static_cast<std::size_t>(v) * w + u;
        float& theta_out = incidence[i];
        theta_out = nan;
        if (ok[i] == 0) {
          continue;
        }
        const float z_clean = z_at[i];
        if (z_clean < o.min_range || z_clean > o.max_range) {
          continue;
        }
        // Surface normal from the neighbours (central differences where possible); the
        // incidence angle between it and the viewing ray.
        const int u0 = valid(u - 1, v) ? u - 1 : u;
        const int u1 = valid(u + 1, v) ? u + 1 : u;
        const int v0 = valid(u, v - 1) ? v - 1 : v;
        const int v1 = valid(u, v + 1) ? v + 1 : v;
        float theta = 0.0f;
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
        theta_out = theta;
        ++reading;
      }
      reading_rows[static_cast<std::size_t>(v) + 1] = reading;
    }
  });

  // Pass 2: one 64-bit draw per reading pixel, in pixel order (16 bits for each of three
  // normals).
  for (int v = 0; v < h; ++v) {
    reading_rows[static_cast<std::size_t>(v) + 1] += reading_rows[static_cast<std::size_t>(v)];
  }
  std::vector<std::uint64_t>& draws = scratch.draws;
  draws.resize(reading_rows.back());
  FastRandom random(seed);
  for (auto& bits : draws) {
    bits = random.next();
  }

  // Pass 3: lateral jitter, axial noise, disparity quantization.
  const NormalTable& normal = normals();
  const double focal_baseline = in.fx * o.baseline;
  parallelRows(h, threads, [&](int v_begin, int v_end) {
    for (int v = v_begin; v < v_end; ++v) {
      std::size_t next_draw = reading_rows[static_cast<std::size_t>(v)];
      for (int u = 0; u < w; ++u) {
        const std::size_t i = static_cast<std::size_t>(v) * w + u;
        Eigen::Vector3f& out = points[i];
        out = Eigen::Vector3f(nan, nan, nan);
        const float theta_f = incidence[i];
        if (std::isnan(theta_f)) {
          continue;
        }
        const double theta = theta_f;
        // Lateral noise: the reading comes from a jittered pixel.
        const std::uint64_t bits = draws[next_draw++];
        const double sigma_l = lateralSigma(o, theta);
        const int su = roundToInt(u + sigma_l * normal[bits]);
        const int sv = roundToInt(v + sigma_l * normal[bits >> 16]);
        if (!valid(su, sv)) {
          continue;  // the jitter fell off the surface: no reading
        }
        double z = z_at[static_cast<std::size_t>(sv) * w + su];
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
        out =
            Eigen::Vector3f(static_cast<float>(ray_x[u] * z), static_cast<float>(ray_y[v] * z), static_cast<float>(z));
      }
    }
  });
}

}  // namespace costar::sim
