#include "perception/median_filter.h"

#include <algorithm>
#include <array>
#include <limits>
#include <stdexcept>
#include <thread>
#include <vector>

namespace costar::perception {

namespace {

constexpr int kMaxFrames = 256;

/// The median filter of one pixel: the valid sample of (lower) median depth, or NaN when
/// no more than half the samples are valid.
inline void filterPixel(std::span<const camera::RgbdFrame> frames, std::size_t pixel, camera::RgbdFrame& out) {
  const std::size_t count = frames.size();
  std::array<float, kMaxFrames> depths;
  std::size_t valid = 0;
  for (std::size_t f = 0; f < count; ++f) {
    const float z = frames[f].points[pixel].z();
    if (z == z) {  // not NaN
      depths[valid++] = z;
    }
  }
  if (2 * valid <= count) {
    const float nan = std::numeric_limits<float>::quiet_NaN();
    out.points[pixel] = Eigen::Vector3f(nan, nan, nan);
    return;
  }
  // Insertion sort: at most a few dozen samples.
  for (std::size_t i = 1; i < valid; ++i) {
    const float value = depths[i];
    std::size_t j = i;
    for (; j > 0 && depths[j - 1] > value; --j) {
      depths[j] = depths[j - 1];
    }
    depths[j] = value;
  }
  const float median = depths[(valid - 1) / 2];
  // The whole sample of that depth (the first frame that has it): it stays on its ray.
  for (std::size_t f = 0; f < count; ++f) {
    if (frames[f].points[pixel].z() == median) {
      out.points[pixel] = frames[f].points[pixel];
      return;
    }
  }
}

void checkFrames(std::span<const camera::RgbdFrame> frames) {
  if (frames.empty()) {
    throw std::invalid_argument("medianFrame: no frames");
  }
  if (frames.size() > kMaxFrames) {
    throw std::invalid_argument("medianFrame: at most 256 frames");
  }
  const camera::RgbdFrame& last = frames.back();
  const std::size_t pixels = static_cast<std::size_t>(last.intrinsics.width) * last.intrinsics.height;
  for (const auto& frame : frames) {
    if (frame.intrinsics.width != last.intrinsics.width || frame.intrinsics.height != last.intrinsics.height ||
        frame.points.size() != pixels) {
      throw std::invalid_argument("medianFrame: the frames differ in size");
    }
  }
}

camera::RgbdFrame emptyLike(const camera::RgbdFrame& last) {
  camera::RgbdFrame out;
  out.intrinsics = last.intrinsics;
  out.rgb = last.rgb;
  out.camera_pose = last.camera_pose;
  out.stamp = last.stamp;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  out.points.assign(static_cast<std::size_t>(last.intrinsics.width) * last.intrinsics.height,
                    Eigen::Vector3f(nan, nan, nan));
  return out;
}

/// Runs `rows(v_begin, v_end)` over [v_min, v_max) split across `threads`.
template <typename Rows>
void parallelRows(int v_min, int v_max, int threads, const Rows& rows) {
  threads = std::clamp(threads, 1, 16);
  if (threads == 1 || v_max - v_min < 2) {
    rows(v_min, v_max);
    return;
  }
  std::vector<std::thread> workers;
  const int count = v_max - v_min;
  for (int t = 1; t < threads; ++t) {
    workers.emplace_back(rows, v_min + count * t / threads, v_min + count * (t + 1) / threads);
  }
  rows(v_min, v_min + count / threads);
  for (auto& worker : workers) {
    worker.join();
  }
}

}  // namespace

camera::RgbdFrame medianFrame(std::span<const camera::RgbdFrame> frames, PixelRect region, int threads) {
  checkFrames(frames);
  const camera::RgbdFrame& last = frames.back();
  const int width = last.intrinsics.width;
  const int height = last.intrinsics.height;
  if (region.empty()) {
    region = {0, 0, width, height};
  }
  region.u_min = std::clamp(region.u_min, 0, width);
  region.u_max = std::clamp(region.u_max, 0, width);
  region.v_min = std::clamp(region.v_min, 0, height);
  region.v_max = std::clamp(region.v_max, 0, height);
  camera::RgbdFrame out = emptyLike(last);
  if (region.empty()) {
    return out;
  }
  parallelRows(region.v_min, region.v_max, threads, [&](int v_begin, int v_end) {
    for (int v = v_begin; v < v_end; ++v) {
      for (int u = region.u_min; u < region.u_max; ++u) {
        filterPixel(frames, static_cast<std::size_t>(v) * width + u, out);
      }
    }
  });
  return out;
}

camera::RgbdFrame medianFrame(std::span<const camera::RgbdFrame> frames, const std::vector<std::uint8_t>& mask,
                              int threads) {
  checkFrames(frames);
  const camera::RgbdFrame& last = frames.back();
  const int width = last.intrinsics.width;
  const int height = last.intrinsics.height;
  if (mask.size() != static_cast<std::size_t>(width) * height) {
    throw std::invalid_argument("medianFrame: the mask has the wrong size");
  }
  camera::RgbdFrame out = emptyLike(last);
  parallelRows(0, height, threads, [&](int v_begin, int v_end) {
    for (std::size_t pixel = static_cast<std::size_t>(v_begin) * width; pixel < static_cast<std::size_t>(v_end) * width;
         ++pixel) {
      if (mask[pixel] != 0) {
        filterPixel(frames, pixel, out);
      }
    }
  });
  return out;
}

}  // namespace costar::perception
