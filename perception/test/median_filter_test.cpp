// Stage 1: the per-pixel temporal median.

#include "perception/median_filter.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

namespace costar::perception {
namespace {

constexpr float kNan = std::numeric_limits<float>::quiet_NaN();

camera::RgbdFrame blankFrame(int width, int height) {
  camera::RgbdFrame frame;
  frame.intrinsics.width = width;
  frame.intrinsics.height = height;
  frame.points.assign(static_cast<std::size_t>(width) * height, Eigen::Vector3f(kNan, kNan, kNan));
  frame.rgb = RgbImage(width, height);
  return frame;
}

TEST(MedianFilter, TakesTheMedianSampleOfEachPixel) {
  std::vector<camera::RgbdFrame> frames;
  const std::vector<float> depths = {1.05f, 0.98f, 1.00f, 1.20f, 0.99f};
  for (const float z : depths) {
    camera::RgbdFrame frame = blankFrame(2, 1);
    frame.points[0] = Eigen::Vector3f(0.1f * z, 0.0f, z);  // a point on the pixel's ray
    frame.points[1] = Eigen::Vector3f(0.0f, 0.0f, 2.0f);
    frames.push_back(frame);
  }
  const camera::RgbdFrame median = medianFrame(frames);
  EXPECT_FLOAT_EQ(median.points[0].z(), 1.00f);
  EXPECT_FLOAT_EQ(median.points[0].x(), 0.1f);  // the whole sample: it stays on the ray
  EXPECT_FLOAT_EQ(median.points[1].z(), 2.0f);
}

TEST(MedianFilter, APixelIsValidOnlyIfMoreThanHalfItsSamplesAre) {
  std::vector<camera::RgbdFrame> frames;
  for (int f = 0; f < 4; ++f) {
    camera::RgbdFrame frame = blankFrame(3, 1);
    frame.points[0] = Eigen::Vector3f(0, 0, 1.0f + 0.01f * f);             // 4 of 4 valid
    if (f < 3) frame.points[1] = Eigen::Vector3f(0, 0, 1.0f + 0.01f * f);  // 3 of 4 valid
    if (f < 2) frame.points[2] = Eigen::Vector3f(0, 0, 1.0f);              // 2 of 4: not more than half
    frames.push_back(frame);
  }
  const camera::RgbdFrame median = medianFrame(frames);
  EXPECT_FLOAT_EQ(median.points[0].z(), 1.01f);  // lower median of an even count
  EXPECT_FLOAT_EQ(median.points[1].z(), 1.01f);
  EXPECT_TRUE(std::isnan(median.points[2].z()));
}

TEST(MedianFilter, RemovesOutliersAndNoise) {
  std::mt19937 random(3);
  std::normal_distribution<float> noise(0.0f, 0.002f);
  std::vector<camera::RgbdFrame> frames;
  for (int f = 0; f < 15; ++f) {
    camera::RgbdFrame frame = blankFrame(20, 10);
    for (auto& p : frame.points) {
      p = Eigen::Vector3f(0, 0, 1.0f + noise(random));
    }
    if (f < 5) {
      frame.points[7] = Eigen::Vector3f(0, 0, 3.0f);  // a flying pixel in a third of the frames
    }
    frames.push_back(frame);
  }
  const camera::RgbdFrame median = medianFrame(frames);
  double squared = 0;
  for (const auto& p : median.points) {
    squared += (p.z() - 1.0) * (p.z() - 1.0);
  }
  EXPECT_LT(std::sqrt(squared / median.points.size()), 0.0012);  // well below 2 mm
  EXPECT_NEAR(median.points[7].z(), 1.0f, 0.01f);
}

TEST(MedianFilter, FiltersOnlyTheRegionAndGivesTheSameResultOnAnyNumberOfThreads) {
  std::mt19937 random(5);
  std::uniform_real_distribution<float> depth(0.8f, 1.2f);
  std::vector<camera::RgbdFrame> frames;
  for (int f = 0; f < 7; ++f) {
    camera::RgbdFrame frame = blankFrame(64, 48);
    for (auto& p : frame.points) {
      p = Eigen::Vector3f(0, 0, depth(random));
    }
    frame.stamp = TimePoint(std::chrono::milliseconds(33 * f));
    frames.push_back(frame);
  }
  const PixelRect region{10, 5, 30, 40};
  const camera::RgbdFrame one = medianFrame(frames, region, 1);
  const camera::RgbdFrame three = medianFrame(frames, region, 3);
  EXPECT_EQ(one.stamp, frames.back().stamp);
  for (int v = 0; v < 48; ++v) {
    for (int u = 0; u < 64; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * 64 + u;
      const bool inside = u >= 10 && u < 30 && v >= 5 && v < 40;
      EXPECT_EQ(std::isfinite(one.points[i].z()), inside);
      if (inside) {
        EXPECT_EQ(one.points[i], three.points[i]);
      }
    }
  }
}

TEST(MedianFilter, RefusesAnEmptyOrMixedFrameSet) {
  EXPECT_THROW(medianFrame(std::vector<camera::RgbdFrame>{}), std::invalid_argument);
  std::vector<camera::RgbdFrame> frames{blankFrame(4, 4), blankFrame(5, 4)};
  EXPECT_THROW(medianFrame(frames), std::invalid_argument);
}

// Any number of frames up to 16 goes through a sorting network several pixels at a time, more
// through a sort of each pixel: both give, for every pixel, the valid sample of lower median
// depth, the first frame's with that depth (depths repeat: quantized), or NaN when no more than
// half are valid. Checked against that definition on pixels of random depths, some invalid.
TEST(MedianFilter, EveryFrameCountGivesTheLowerMedianSampleOfEachPixel) {
  std::mt19937 random(11);
  std::uniform_int_distribution<int> step(0, 12);  // depths on a 1 mm grid: ties are common
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  for (const int count : {1, 2, 3, 7, 8, 15, 16, 17, 31}) {
    const int width = 37;  // not a multiple of the lanes
    const int height = 5;
    std::vector<camera::RgbdFrame> frames;
    const float invalid_share = count % 2 == 0 ? 0.3f : 0.5f;
    for (int f = 0; f < count; ++f) {
      camera::RgbdFrame frame = blankFrame(width, height);
      for (auto& p : frame.points) {
        if (unit(random) >= invalid_share) {
          const float z = 1.0f + 0.001f * static_cast<float>(step(random));
          p = Eigen::Vector3f(unit(random), static_cast<float>(f), z);  // x, y tell the samples apart
        }
      }
      frames.push_back(std::move(frame));
    }
    std::vector<std::uint8_t> mask(static_cast<std::size_t>(width) * height, 1);
    for (std::size_t pixel = 0; pixel < mask.size(); pixel += 3) {
      mask[pixel] = 0;
    }
    for (int threads : {1, 2}) {
      const camera::RgbdFrame whole = medianFrame(frames, PixelRect{}, threads);
      const camera::RgbdFrame masked = medianFrame(frames, mask, threads);
      for (std::size_t pixel = 0; pixel < mask.size(); ++pixel) {
        std::vector<float> depths;
        for (const auto& frame : frames) {
          if (!std::isnan(frame.points[pixel].z())) {
            depths.push_back(frame.points[pixel].z());
          }
        }
        std::sort(depths.begin(), depths.end());
        Eigen::Vector3f expected(kNan, kNan, kNan);
        if (2 * depths.size() > frames.size()) {
          const float median = depths[(depths.size() - 1) / 2];
          for (const auto& frame : frames) {
            if (frame.points[pixel].z() == median) {
              expected = frame.points[pixel];
              break;
            }
          }
        }
        const auto same = [&](const Eigen::Vector3f& got) {
          return std::isnan(expected.z()) ? std::isnan(got.z()) : got == expected;
        };
        ASSERT_TRUE(same(whole.points[pixel])) << count << " frames, pixel " << pixel;
        if (mask[pixel] != 0) {
          ASSERT_TRUE(same(masked.points[pixel])) << count << " frames, pixel " << pixel << " (mask)";
        } else {
          ASSERT_TRUE(std::isnan(masked.points[pixel].z()));
        }
      }
    }
  }
}

}  // namespace
}  // namespace costar::perception
