#include "perception/median_filter.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <thread>
#include <vector>

namespace costar::perception {

namespace {

constexpr int kMaxFrames = 256;

/// The whole sample of depth `median` at `pixel` (the first frame that has it): it stays on its
/// ray.
inline void takeSample(std::span<const camera::RgbdFrame> frames, std::size_t pixel, float median,
                       camera::RgbdFrame& out) {
  for (const camera::RgbdFrame& frame : frames) {
    if (frame.points[pixel].z() == median) {
      out.points[pixel] = frame.points[pixel];
      return;
    }
  }
}

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
  takeSample(frames, pixel, depths[(valid - 1) / 2], out);
}

/// Up to 16 frames: kLanes pixels at a time through a sorting network (Batcher's odd-even
/// merge sort of 16 depths, 63 compare-exchanges as min/max across the lanes, no branches;
/// an invalid depth sorts last as +inf). The same median as filterPixel's sort, about 3x
/// faster (BM_Stage1_MedianFilter15): the insertion sort's branches mispredict on noisy depths.
constexpr std::size_t kNetworkSize = 16;
constexpr std::size_t kLanes = 8;

struct CompareExchange {
  std::uint8_t low;
  std::uint8_t high;
};

constexpr auto kNetwork = [] {
  std::array<CompareExchange, 63> network{};
  std::size_t n = 0;
  constexpr std::size_t size = kNetworkSize;
  for (std::size_t p = 1; p < size; p *= 2) {
    for (std::size_t k = p; k >= 1; k /= 2) {
      for (std::size_t j = k % p; j + k < size; j += 2 * k) {
        for (std::size_t i = 0; i < k && i + j + k < size; ++i) {
          if ((i + j) / (2 * p) == (i + j + k) / (2 * p)) {
            network[n++] = {static_cast<std::uint8_t>(i + j), static_cast<std::uint8_t>(i + j + k)};
          }
        }
      }
    }
  }
  return network;
}();

/// Four depths, one per pixel: compare-exchanges of whole vectors compile to SSE compares and
/// masks (GCC and Clang vector extensions; GCC leaves a loop over lanes as branches).
using Depths4 = float __attribute__((vector_size(16)));
constexpr std::size_t kVectors = kLanes / 4;

/// The pixels `pixels[0..lanes)` (lanes <= kLanes), frames.size() <= kNetworkSize.
void filterLanes(std::span<const camera::RgbdFrame> frames, const std::size_t* pixels, std::size_t lanes,
                 camera::RgbdFrame& out) {
  const std::size_t count = frames.size();
  constexpr float kInvalid = std::numeric_limits<float>::infinity();
  alignas(16) float gathered[kNetworkSize][kLanes];
  std::array<int, kLanes> valid{};
  for (std::size_t f = 0; f < kNetworkSize; ++f) {
    const Eigen::Vector3f* points = f < count ? frames[f].points.data() : nullptr;
    for (std::size_t l = 0; l < kLanes; ++l) {
      const float z = points != nullptr && l < lanes ? points[pixels[l]].z() : kInvalid;
      const bool ok = z == z;  // not NaN
      gathered[f][l] = ok ? z : kInvalid;
      valid[l] += points != nullptr && l < lanes && ok ? 1 : 0;
    }
  }
  Depths4 depth[kNetworkSize][kVectors];
  std::memcpy(depth, gathered, sizeof depth);
  for (const CompareExchange& c : kNetwork) {
    for (std::size_t v = 0; v < kVectors; ++v) {
      const Depths4 a = depth[c.low][v];
      const Depths4 b = depth[c.high][v];
      depth[c.low][v] = b < a ? b : a;
      depth[c.high][v] = b < a ? a : b;
    }
  }
  std::memcpy(gathered, depth, sizeof depth);
  for (std::size_t l = 0; l < lanes; ++l) {
    const auto n = static_cast<std::size_t>(valid[l]);
    if (2 * n <= count) {
      const float nan = std::numeric_limits<float>::quiet_NaN();
      out.points[pixels[l]] = Eigen::Vector3f(nan, nan, nan);
    } else {
      takeSample(frames, pixels[l], gathered[(n - 1) / 2][l], out);
    }
  }
}

/// Filters pixels handed to it one at a time, kLanes at once when the frames fit the network.
class PixelBatch {
 public:
  PixelBatch(std::span<const camera::RgbdFrame> frames, camera::RgbdFrame& out) : frames_(frames), out_(out) {}
  ~PixelBatch() { flush(); }
  PixelBatch(const PixelBatch&) = delete;
  PixelBatch& operator=(const PixelBatch&) = delete;

  void add(std::size_t pixel) {
    if (frames_.size() > kNetworkSize) {
      filterPixel(frames_, pixel, out_);
      return;
    }
    pixels_[lanes_++] = pixel;
    if (lanes_ == kLanes) {
      flush();
    }
  }
  void flush() {
    if (lanes_ > 0) {
      filterLanes(frames_, pixels_.data(), lanes_, out_);
      lanes_ = 0;
    }
  }

 private:
  std::span<const camera::RgbdFrame> frames_;
  camera::RgbdFrame& out_;
  std::array<std::size_t, kLanes> pixels_{};
  std::size_t lanes_ = 0;
};

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
    PixelBatch batch(frames, out);
    for (int v = v_begin; v < v_end; ++v) {
      for (int u = region.u_min; u < region.u_max; ++u) {
        batch.add(static_cast<std::size_t>(v) * width + u);
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
    PixelBatch batch(frames, out);
    for (std::size_t pixel = static_cast<std::size_t>(v_begin) * width; pixel < static_cast<std::size_t>(v_end) * width;
         ++pixel) {
      if (mask[pixel] != 0) {
        batch.add(pixel);
      }
    }
  });
  return out;
}

}  // namespace costar::perception
