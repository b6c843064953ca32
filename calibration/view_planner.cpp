#include "calibration/view_planner.h"

#include <array>
#include <cmath>
#include <random>

#include "calibration/hand_eye.h"

namespace costar::calibration {

namespace {
constexpr double kDeg = M_PI / 180.0;
}

world::Pose facingCamera(const Eigen::Vector3d& position, const world::Pose& camera_in_world) {
  const Eigen::Vector3d z = (camera_in_world.translation() - position).normalized();
  Eigen::Vector3d y = Eigen::Vector3d::UnitZ() - Eigen::Vector3d::UnitZ().dot(z) * z;
  if (y.norm() < 1e-6) {
    y = Eigen::Vector3d::UnitY();
  }
  y.normalize();
  world::Pose pose = world::Pose::Identity();
  pose.linear().col(0) = y.cross(z);
  pose.linear().col(1) = y;
  pose.linear().col(2) = z;
  pose.translation() = position;
  return pose;
}

std::vector<world::Pose> candidateMarkerPoses(const world::Pose& camera_in_world, const ViewPlanOptions& options,
                                              int count) {
  std::vector<world::Pose> out;
  const Eigen::Vector3d lo = options.region_min;
  const Eigen::Vector3d hi = options.region_max;
  const Eigen::Vector3d mid = (lo + hi) / 2;
  const bool tilted = options.tilt_deg > 0 || options.roll_deg > 0;
  if (!tilted) {
    // Spread: the region's far corners at alternating heights, its centre, then the rest.
    const std::array<Eigen::Vector3d, 9> pattern = {Eigen::Vector3d(lo.x(), lo.y(), lo.z()),
                                                    Eigen::Vector3d(hi.x(), hi.y(), lo.z()),
                                                    Eigen::Vector3d(lo.x(), hi.y(), hi.z()),
                                                    Eigen::Vector3d(hi.x(), lo.y(), hi.z()),
                                                    mid,
                                                    Eigen::Vector3d(lo.x(), hi.y(), lo.z()),
                                                    Eigen::Vector3d(hi.x(), lo.y(), lo.z()),
                                                    Eigen::Vector3d(lo.x(), lo.y(), hi.z()),
                                                    Eigen::Vector3d(hi.x(), hi.y(), hi.z())};
    const std::array<double, 4> rolls = {1.0, -1.0, 0.5, -0.5};
    for (std::size_t i = 0; i < pattern.size(); ++i) {
      world::Pose pose = facingCamera(pattern[i], camera_in_world);
      pose.linear() = pose.linear() * Eigen::AngleAxisd(options.facing_roll_deg * kDeg * rolls[i % rolls.size()],
                                                        Eigen::Vector3d::UnitZ())
                                          .toRotationMatrix();
      out.push_back(pose);
    }
  }
  std::mt19937_64 random(options.seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const auto signedUnit = [&] { return 2.0 * unit(random) - 1.0; };
  for (int attempt = 0; attempt < 200 * count && static_cast<int>(out.size()) < count; ++attempt) {
    const Eigen::Vector3d p = lo + (hi - lo).cwiseProduct(Eigen::Vector3d(unit(random), unit(random), unit(random)));
    world::Pose pose = facingCamera(p, camera_in_world);
    if (!tilted) {
      const double roll = options.facing_roll_deg * kDeg * signedUnit();
      pose.linear() = pose.linear() * Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    }
    if (tilted) {
      const Eigen::Matrix3d turn =
          (Eigen::AngleAxisd(options.tilt_deg * kDeg * signedUnit(), Eigen::Vector3d::UnitX()) *
           Eigen::AngleAxisd(options.tilt_deg * kDeg * signedUnit(), Eigen::Vector3d::UnitY()) *
           Eigen::AngleAxisd(options.roll_deg * kDeg * signedUnit(), Eigen::Vector3d::UnitZ()))
              .toRotationMatrix();
      pose.linear() = pose.linear() * turn;
    }
    bool separate = true;
    for (const auto& other : out) {
      if (world::rotationAngle(other, pose) < options.min_separation_deg * kDeg) {
        separate = false;
        break;
      }
    }
    if (separate) {
      out.push_back(pose);
    }
  }
  if (static_cast<int>(out.size()) > count) {
    out.resize(static_cast<std::size_t>(count));
  }
  return out;
}

bool markerInView(const world::Pose& marker, double size, const world::Pose& camera_in_world,
                  const camera::Intrinsics& in, double margin_px, double max_angle_deg) {
  const world::Pose in_camera = camera_in_world.inverse() * marker;
  const Eigen::Vector3d to_camera = -in_camera.translation().normalized();
  if (in_camera.linear().col(2).dot(to_camera) < std::cos(max_angle_deg * kDeg)) {
    return false;
  }
  for (const auto& corner : markerCorners(size)) {
    const Eigen::Vector3d c = in_camera * corner;
    if (c.z() < 0.1) {
      return false;
    }
    const double u = in.fx * c.x() / c.z() + in.cx;
    const double v = in.fy * c.y() / c.z() + in.cy;
    if (u < margin_px || v < margin_px || u > in.width - margin_px || v > in.height - margin_px) {
      return false;
    }
  }
  return true;
}

}  // namespace costar::calibration
