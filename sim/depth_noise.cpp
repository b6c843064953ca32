#include "sim/depth_noise.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <thread>

namespace costar::sim {

namespace {

/// theta / (pi/2 - theta): the incidence term of both sigmas (the noise computes it once per
/// pixel and passes it to both).
template <typename T>
T incidenceRatio(T theta) {
  return theta / (static_cast<T>(M_PI / 2) - theta);
}

/// The model's two sigmas from the incidence ratio, with a copy of the options' coefficients
/// (a row's loop then keeps them in registers, which it does not for fields it reads through a
/// reference while storing to memory).
struct Sigmas {
  explicit Sigmas(const DepthNoiseOptions& o)
      : axial_constant(o.axial_constant),
        axial_quadratic(o.axial_quadratic),
        reference_depth(o.axial_reference_depth),
        lateral_constant(o.lateral_constant),
        lateral_angular(o.lateral_angular) {}
  double axial(double z, double ratio) const {
    const double dz = z - reference_depth;
    return axial_constant + axial_quadratic * dz * dz + 0.0001 / std::sqrt(z) * ratio * ratio;
  }
  double lateral(double ratio) const { return lateral_constant + lateral_angular * ratio; }

  double axial_constant;
  double axial_quadratic;
  double reference_depth;
  double lateral_constant;
  double lateral_angular;
};

}  // namespace

double axialSigma(const DepthNoiseOptions& o, double z, double theta) {
  return Sigmas(o).axial(z, incidenceRatio(theta));
}

double lateralSigma(const DepthNoiseOptions& o, double theta) { return Sigmas(o).lateral(incidenceRatio(theta)); }

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
  std::vector<float> incidence;  // per pixel: theta / (pi/2 - theta), NaN where nothing reads
  std::vector<std::uint32_t> reading_rows;
  std::vector<std::uint64_t> draws;
};

int roundToInt(double x) { return static_cast<int>(std::floor(x + 0.5)); }

/// acos(c) for c in [0, 1]: Abramowitz and Stegun 4.4.46 (|error| <= 2e-8 rad, below a float's
/// rounding of the angle), branch-free so that a row of them vectorizes; libm's acosf was a
/// quarter of the noise model's time.
inline float acosUnit(float c) {
  float p = -0.0012624911f;
  p = p * c + 0.0066700901f;
  p = p * c - 0.0170881256f;
  p = p * c + 0.0308918810f;
  p = p * c - 0.0501743046f;
  p = p * c + 0.0889789874f;
  p = p * c - 0.2145988016f;
  p = p * c + 1.5707963050f;
  return std::sqrt(1.0f - c) * p;
}

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
// function of the seed alone: (1) per pixel, whether it gets a reading and the ratio
// theta / (pi/2 - theta) of its incidence angle theta, which both sigmas use (parallel); (2) the
// random bits, drawn in pixel order for the pixels that read (serial, cheap); (3) the jittered,
// noisy, quantized reading (parallel). The result is the same for any number of threads, and
// the same as drawing while scanning the image once. Passes 1 and 3 work on whole rows with
// branch-free loops that GCC vectorizes (this file is built with -fno-math-errno
// -fno-trapping-math: sim/CMakeLists.txt).
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

  // Pass 1: the incidence ratio of each pixel that reads (NaN: no reading), and how many read
  // in each row.
  const float cos_max = static_cast<float>(std::cos(o.max_incidence_deg * M_PI / 180.0));
  std::vector<float>& incidence = scratch.incidence;
  incidence.resize(pixels);
  std::vector<std::uint32_t>& reading_rows = scratch.reading_rows;
  reading_rows.assign(static_cast<std::size_t>(h) + 1, 0);
  const auto near_limit = static_cast<float>(o.min_range);
  const auto far_limit = static_cast<float>(o.max_range);
  parallelRows(h, threads, [&](int v_begin, int v_end) {
    std::vector<float> grazing_row(static_cast<std::size_t>(w));
    for (int v = v_begin; v < v_end; ++v) {
      // First the cosine of each pixel's incidence angle (-1: no reading), then the angles of
      // the whole row at once.
      float* const cosines = incidence.data() + static_cast<std::size_t>(v) * w;
      // A pixel at the image's border, one neighbour at a time.
      const auto border_cosine = [&](int u) {
        const std::size_t i = static_cast<std::size_t>(v) * w + u;
        if (ok[i] == 0 || z_at[i] < near_limit || z_at[i] > far_limit) {
          return -1.0f;
        }
        const int u0 = valid(u - 1, v) ? u - 1 : u;
        const int u1 = valid(u + 1, v) ? u + 1 : u;
        const int v0 = valid(u, v - 1) ? v - 1 : v;
        const int v1 = valid(u, v + 1) ? v + 1 : v;
        if (u0 == u1 || v0 == v1) {
          return 1.0f;  // no normal: read as frontal
        }
        const Eigen::Vector3f normal = (point(u1, v) - point(u0, v)).cross(point(u, v1) - point(u, v0));
        const Eigen::Vector3f ray(ray_x[u], ray_y[v], 1.0f);
        const float squared_scale = normal.squaredNorm() * ray.squaredNorm();
        return squared_scale > 0.0f ? std::min(1.0f, std::abs(normal.dot(ray)) / std::sqrt(squared_scale)) : 1.0f;
      };
      if (v == 0 || v + 1 == h) {
        for (int u = 0; u < w; ++u) {
          cosines[u] = border_cosine(u);
        }
      } else {
        cosines[0] = border_cosine(0);
        cosines[w - 1] = border_cosine(w - 1);
        // Inside the image: the same as border_cosine, written with selects instead of
        // branches so that GCC vectorizes the row. A neighbour without a surface is replaced
        // by the pixel itself (a one-sided difference); none on either side: no normal.
        const float* const z = z_at + static_cast<std::size_t>(v) * w;
        const float* const z_up = z - w;
        const float* const z_down = z + w;
        const float ray_v = ray_y[v];
        const float ray_up = ray_y[v - 1];
        const float ray_down = ray_y[v + 1];
        constexpr float kInfinity = std::numeric_limits<float>::infinity();
        for (int u = 1; u + 1 < w; ++u) {
          // Every value read up front (a read only under a condition keeps GCC from vectorizing).
          const float zc = z[u];
          const float z_left = z[u - 1];
          const float z_right = z[u + 1];
          const float z_above = z_up[u];
          const float z_below = z_down[u];
          const float ray_left = ray_x[u - 1];
          const float ray_centre = ray_x[u];
          const float ray_right = ray_x[u + 1];
          const bool left = (z_left > 0.0f) & (z_left < kInfinity);
          const bool right = (z_right > 0.0f) & (z_right < kInfinity);
          const bool up = (z_above > 0.0f) & (z_above < kInfinity);
          const bool down = (z_below > 0.0f) & (z_below < kInfinity);
          // Along the row: from (x0, z0) to (x1, z1).
          const float z1 = right ? z_right : zc;
          const float x1 = (right ? ray_right : ray_centre) * z1;
          const float z0 = left ? z_left : zc;
          const float x0 = (left ? ray_left : ray_centre) * z0;
          const Eigen::Vector3f along_row(x1 - x0, ray_v * (z1 - z0), z1 - z0);
          // Along the column.
          const float z3 = down ? z_below : zc;
          const float y3 = (down ? ray_down : ray_v) * z3;
          const float z2 = up ? z_above : zc;
          const float y2 = (up ? ray_up : ray_v) * z2;
          const Eigen::Vector3f along_column(ray_centre * (z3 - z2), y3 - y2, z3 - z2);
          const Eigen::Vector3f normal = along_row.cross(along_column);
          const Eigen::Vector3f ray(ray_centre, ray_v, 1.0f);
          const float squared_scale = normal.squaredNorm() * ray.squaredNorm();
          const float cosine = std::min(1.0f, std::abs(normal.dot(ray)) / std::sqrt(std::max(squared_scale, 1e-30f)));
          const bool has_normal = (left | right) & (up | down) & (squared_scale > 0.0f);
          const bool reads = (zc > 0.0f) & (zc < kInfinity) & (zc >= near_limit) & (zc <= far_limit);
          cosines[u] = reads ? (has_normal ? cosine : 1.0f) : -1.0f;
        }
      }
      // Each reading pixel's ratio theta / (pi/2 - theta), which both sigmas of the model use
      // (lateralSigma, axialSigma), for the whole row (no branches: it vectorizes); then NaN
      // for grazing pixels (cosine below cos_max) and those without a reading.
      float* const grazings = grazing_row.data();
      for (int u = 0; u < w; ++u) {
        const float theta = acosUnit(std::max(cosines[u], cos_max));
        grazings[u] = incidenceRatio(theta);
      }
      std::uint32_t reading = 0;
      for (int u = 0; u < w; ++u) {
        const bool reads = cosines[u] >= cos_max;
        cosines[u] = reads ? grazings[u] : nan;
        reading += reads ? 1 : 0;
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

  // Pass 3: lateral jitter, axial noise, disparity quantization; a row at a time in three
  // steps, so that the arithmetic (four divisions and a square root per pixel, which one
  // pixel after another would wait on) runs over whole rows: (a) the jittered source pixel of
  // each reading, (b) its noisy, quantized depth, (c) the points.
  const NormalTable& normal = normals();
  const double focal_baseline = in.fx * o.baseline;
  const double inverse_step = 1.0 / o.disparity_step;
  const bool quantize = o.quantize_disparity;
  const Sigmas sigmas(o);
  const int width = w;
  const int height = h;
  const std::uint8_t* const surface_at = surface.data();
  const double step = o.disparity_step;
  const double min_range = o.min_range;
  const double max_range = o.max_range;
  parallelRows(h, threads, [&](int v_begin, int v_end) {
    std::vector<double> depth_row(static_cast<std::size_t>(w));  // (a): the source's clean depth
    std::vector<double> grazing_row(static_cast<std::size_t>(w));
    std::vector<double> axial_row(static_cast<std::size_t>(w));  // the standard normal for the depth
    std::vector<int> column(static_cast<std::size_t>(w));        // the reading's own pixel
    for (int v = v_begin; v < v_end; ++v) {
      const std::uint64_t* draw = draws.data() + reading_rows[static_cast<std::size_t>(v)];
      const float* const grazing_at = incidence.data() + static_cast<std::size_t>(v) * width;
      int readings = 0;
      for (int u = 0; u < width; ++u) {
        const float grazing = grazing_at[u];
        if (std::isnan(grazing)) {
          continue;
        }
        // Lateral noise: the reading comes from a jittered pixel.
        const std::uint64_t bits = *draw++;
        const double sigma_l = sigmas.lateral(grazing);
        const int su = roundToInt(u + sigma_l * normal[bits]);
        const int sv = roundToInt(v + sigma_l * normal[bits >> 16]);
        // Off the image or off the surface: no reading.
        if (static_cast<unsigned>(su) >= static_cast<unsigned>(width) ||
            static_cast<unsigned>(sv) >= static_cast<unsigned>(height)) {
          continue;
        }
        const std::size_t source = static_cast<std::size_t>(sv) * width + su;
        if (surface_at[source] == 0) {
          continue;
        }
        depth_row[readings] = z_at[source];
        grazing_row[readings] = grazing;
        axial_row[readings] = normal[bits >> 32];
        column[readings] = u;
        ++readings;
      }
      // (b) Axial noise and quantization, without branches so that it vectorizes. A reading
      // nearer than the sensor's range (the noise can take it below zero) quantizes to a depth
      // far below it; one beyond 630 m to 315 m: (c) drops both.
      double* const depths = depth_row.data();
      const double* const grazings = grazing_row.data();
      const double* const axials = axial_row.data();
      for (int k = 0; k < readings; ++k) {
        const double z = depths[k];
        depths[k] = z + sigmas.axial(z, grazings[k]) * axials[k];
      }
      if (quantize) {
        for (int k = 0; k < readings; ++k) {
          // The disparity in steps, rounded to the nearest: floor(scaled + 0.5), the floor
          // taken by adding and taking away 1.5 * 2^52 (which rounds to an integer) and
          // stepping down where that rounded up (SSE2 has no vector floor).
          const double scaled = std::min(focal_baseline / std::max(depths[k], 1e-9) * inverse_step, 2e9);
          const double half_up = scaled + 0.5;
          const double nearest = (half_up + 6755399441055744.0) - 6755399441055744.0;
          const double steps = nearest - (nearest > half_up ? 1.0 : 0.0);
          depths[k] = focal_baseline / (std::max(steps, 1.0) * step);
        }
      }
      // (c) The points; every other pixel reads nothing.
      Eigen::Vector3f* const out = points.data() + static_cast<std::size_t>(v) * w;
      std::fill(out, out + w, Eigen::Vector3f(nan, nan, nan));
      for (int k = 0; k < readings; ++k) {
        const double z = depths[k];
        if (z >= min_range && z <= max_range) {
          const int u = column[k];
          out[u] = Eigen::Vector3f(static_cast<float>(ray_x[u] * z), static_cast<float>(ray_y[v] * z),
                                   static_cast<float>(z));
        }
      }
    }
  });
}

}  // namespace costar::sim
