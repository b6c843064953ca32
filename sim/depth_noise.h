#pragma once
// The depth noise of a Kinect v1 / PrimeSense Carmine structured-light sensor, after
// C. V. Nguyen, S. Izadi, D. Lovell, "Modeling Kinect Sensor Noise for Improved 3D
// Reconstruction and Tracking", 3DIMPVT 2012:
//   axial   sigma_z(z, theta) = 0.0012 + 0.0019 (z - 0.4)^2
//                               + 0.0001 / sqrt(z) * theta^2 / (pi/2 - theta)^2      [m]
//   lateral sigma_L(theta)    = 0.8 + 0.035 theta / (pi/2 - theta)                   [px]
// with theta the angle between the surface normal and the viewing ray. Pixels at grazing
// angles or outside the working range read as invalid (NaN); depth is quantized as the
// sensor quantizes disparity (1/8 pixel, 7.5 cm baseline).

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "camera/rgbd.h"

namespace costar::sim {

struct DepthNoiseOptions {
  bool enabled = true;
  double min_range = 0.35;  // m
  double max_range = 3.5;   // m
  /// Surfaces seen at a larger angle between normal and ray return no depth.
  double max_incidence_deg = 78.0;
  bool quantize_disparity = true;
  double baseline = 0.075;             // m
  double disparity_step = 1.0 / 8.0;   // px
  double axial_constant = 0.0012;      // m
  double axial_quadratic = 0.0019;     // m per m^2
  double axial_reference_depth = 0.4;  // m
  double lateral_constant = 0.8;       // px
  double lateral_angular = 0.035;      // px
};

/// Converts a clean metric depth image (row-major; 0 or NaN where there is no surface) into
/// the organized point cloud the sensor would report, in the optical frame, with the noise
/// above drawn from a generator seeded with `seed` (same seed, same output). Runs on up to
/// `threads` threads; the output does not depend on how many.
void noisyPointCloud(const std::vector<float>& clean_depth, const camera::Intrinsics& intrinsics,
                     const DepthNoiseOptions& options, std::uint64_t seed, std::vector<Eigen::Vector3f>& points,
                     int threads = 1);

/// sigma_z of the model at depth z (m) and incidence angle theta (rad).
double axialSigma(const DepthNoiseOptions& options, double z, double theta);
/// sigma_L of the model (px) at incidence angle theta (rad).
double lateralSigma(const DepthNoiseOptions& options, double theta);

}  // namespace costar::sim
