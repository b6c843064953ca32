#include "sim/depth_noise.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace costar::sim {
namespace {

const camera::Intrinsics kIntrinsics = camera::Intrinsics::fromHorizontalFov(640, 480, 58.0 * M_PI / 180.0);

/// Depth image of a plane through (0, 0, distance) tilted by `tilt` about the camera's x axis.
std::vector<float> planeDepth(double distance, double tilt) {
  std::vector<float> depth(640 * 480);
  const Eigen::Vector3d normal(0, std::sin(tilt), -std::cos(tilt));
  for (int v = 0; v < 480; ++v) {
    for (int u = 0; u < 640; ++u) {
      const Eigen::Vector3d ray((u - kIntrinsics.cx) / kIntrinsics.fx, (v - kIntrinsics.cy) / kIntrinsics.fy, 1.0);
      const double t = distance * normal.z() / normal.dot(ray);  // ray(t).z == t
      depth[v * 640 + u] = t > 0 ? static_cast<float>(t) : 0.0f;
    }
  }
  return depth;
}

struct Stats {
  double mean = 0;
  double sigma = 0;
  int valid = 0;
};

Stats residuals(const std::vector<float>& clean, const std::vector<Eigen::Vector3f>& points) {
  Stats s;
  double sum = 0;
  double sum2 = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (std::isfinite(points[i].z())) {
      const double r = points[i].z() - clean[i];
      sum += r;
      sum2 += r * r;
      ++s.valid;
    }
  }
  s.mean = sum / s.valid;
  s.sigma = std::sqrt(sum2 / s.valid - s.mean * s.mean);
  return s;
}

TEST(DepthNoise, AxialNoiseOfAFrontalPlaneFollowsTheModel) {
  DepthNoiseOptions options;
  options.quantize_disparity = false;
  for (const double distance : {0.8, 1.2, 2.0}) {
    const auto clean = planeDepth(distance, 0.0);
    std::vector<Eigen::Vector3f> points;
    noisyPointCloud(clean, kIntrinsics, options, 42, points);
    const Stats stats = residuals(clean, points);
    const double expected = axialSigma(options, distance, 0.0);
    EXPECT_NEAR(stats.sigma, expected, 0.05 * expected) << "at " << distance << " m";
    EXPECT_NEAR(stats.mean, 0.0, 0.1 * expected);
    EXPECT_GT(stats.valid, 0.99 * 640 * 480);
  }
  EXPECT_NEAR(axialSigma(options, 1.2, 0.0), 0.0012 + 0.0019 * 0.64, 1e-12);
}

TEST(DepthNoise, QuantizationAddsTheDisparityStep) {
  DepthNoiseOptions options;
  const auto clean = planeDepth(2.0, 0.0);
  std::vector<Eigen::Vector3f> points;
  noisyPointCloud(clean, kIntrinsics, options, 1, points);
  // Every depth is f*b / (k * step) for an integer k.
  const double focal_baseline = kIntrinsics.fx * options.baseline;
  for (std::size_t i = 0; i < points.size(); i += 997) {
    if (std::isfinite(points[i].z())) {
      const double k = focal_baseline / points[i].z() / options.disparity_step;
      EXPECT_NEAR(k, std::round(k), 1e-3);
    }
  }
}

TEST(DepthNoise, GrazingSurfacesAndOutOfRangeReadNothing) {
  DepthNoiseOptions options;
  std::vector<Eigen::Vector3f> points;
  // A plane tilted by 75 degrees: seen at 53-97 degrees of incidence across the image rows.
  const double tilt = 75.0 * M_PI / 180.0;
  const Eigen::Vector3d normal(0, std::sin(tilt), -std::cos(tilt));
  const auto clean = planeDepth(1.0, tilt);
  noisyPointCloud(clean, kIntrinsics, options, 1, points);
  int steep_valid = 0;
  int steep = 0;
  int moderate_valid = 0;
  int moderate = 0;
  for (int v = 1; v < 479; ++v) {
    for (int u = 1; u < 639; ++u) {
      if (clean[v * 640 + u] <= 0) {
        continue;
      }
      const Eigen::Vector3d ray =
          Eigen::Vector3d((u - kIntrinsics.cx) / kIntrinsics.fx, (v - kIntrinsics.cy) / kIntrinsics.fy, 1.0)
              .normalized();
      const double incidence = std::acos(std::abs(normal.dot(ray))) * 180.0 / M_PI;
      const bool valid = std::isfinite(points[v * 640 + u].z());
      if (incidence > 80.0) {
        ++steep;
        steep_valid += valid ? 1 : 0;
      } else if (incidence < 70.0) {
        ++moderate;
        moderate_valid += valid ? 1 : 0;
      }
    }
  }
  ASSERT_GT(steep, 1000);
  ASSERT_GT(moderate, 1000);
  EXPECT_EQ(steep_valid, 0);                   // beyond the 78 degree cut-off: no reading
  EXPECT_GT(moderate_valid, 0.95 * moderate);  // well below it: nearly all read
  // Out of range, too far or too near.
  noisyPointCloud(planeDepth(4.0, 0.0), kIntrinsics, options, 1, points);
  EXPECT_FALSE(std::isfinite(points[240 * 640 + 320].z()));
  noisyPointCloud(planeDepth(0.2, 0.0), kIntrinsics, options, 1, points);
  EXPECT_FALSE(std::isfinite(points[240 * 640 + 320].z()));
}

TEST(DepthNoise, TheSameSeedGivesTheSameFrame) {
  DepthNoiseOptions options;
  const auto clean = planeDepth(1.0, 0.3);
  std::vector<Eigen::Vector3f> a;
  std::vector<Eigen::Vector3f> b;
  std::vector<Eigen::Vector3f> c;
  noisyPointCloud(clean, kIntrinsics, options, 5, a);
  noisyPointCloud(clean, kIntrinsics, options, 5, b);
  noisyPointCloud(clean, kIntrinsics, options, 6, c);
  int same = 0;
  int differ = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (std::isfinite(a[i].z())) {
      same += a[i] == b[i] ? 1 : 0;
      differ += (std::isfinite(c[i].z()) && a[i] != c[i]) ? 1 : 0;
    }
  }
  EXPECT_EQ(same, static_cast<int>(std::count_if(a.begin(), a.end(), [](auto& p) { return std::isfinite(p.z()); })));
  EXPECT_GT(differ, 1000);
}

TEST(DepthNoise, TheFrameDoesNotDependOnTheNumberOfThreads) {
  // A step (two planes at different depths), a hole and a grazing band: every branch of the
  // model, split across threads at different rows.
  std::vector<float> clean = planeDepth(0.9, 0.4);
  const auto far = planeDepth(1.6, -0.2);
  for (int v = 0; v < 480; ++v) {
    for (int u = 0; u < 640; ++u) {
      const int i = v * 640 + u;
      if (u > 400) {
        clean[i] = far[i];
      }
      if ((u - 200) * (u - 200) + (v - 300) * (v - 300) < 900) {
        clean[i] = v % 2 == 0 ? 0.0f : std::numeric_limits<float>::quiet_NaN();
      }
    }
  }
  const auto grazing = planeDepth(1.0, 80.0 * M_PI / 180.0);
  std::copy(grazing.begin(), grazing.begin() + 640 * 40, clean.begin());
  DepthNoiseOptions options;
  std::vector<Eigen::Vector3f> one;
  noisyPointCloud(clean, kIntrinsics, options, 11, one, 1);
  const auto same = [](const Eigen::Vector3f& a, const Eigen::Vector3f& b) {
    return (std::isnan(a.z()) && std::isnan(b.z())) || a == b;
  };
  int valid = 0;
  for (const auto& p : one) {
    valid += std::isfinite(p.z()) ? 1 : 0;
  }
  EXPECT_GT(valid, 640 * 480 / 2);
  EXPECT_LT(valid, 640 * 480 - 640 * 30);  // the grazing rows read nothing
  for (const int threads : {2, 3, 8}) {
    std::vector<Eigen::Vector3f> many(7, Eigen::Vector3f::Zero());  // reused storage is overwritten
    noisyPointCloud(clean, kIntrinsics, options, 11, many, threads);
    ASSERT_EQ(many.size(), one.size());
    int differ = 0;
    for (std::size_t i = 0; i < one.size(); ++i) {
      differ += same(one[i], many[i]) ? 0 : 1;
    }
    EXPECT_EQ(differ, 0) << threads << " threads";
  }
}

TEST(DepthNoise, DisabledNoiseGivesTheExactSurface) {
  DepthNoiseOptions options;
  options.enabled = false;
  const auto clean = planeDepth(1.0, 0.2);
  std::vector<Eigen::Vector3f> points;
  noisyPointCloud(clean, kIntrinsics, options, 1, points);
  EXPECT_NEAR(points[100 * 640 + 100].z(), clean[100 * 640 + 100], 1e-6);
}

}  // namespace
}  // namespace costar::sim
