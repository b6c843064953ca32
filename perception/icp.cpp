#include "perception/icp.h"

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace costar::perception {

namespace {

Eigen::Matrix3d rotationFromVector(const Eigen::Vector3d& omega) {
  const double angle = omega.norm();
  if (angle < 1e-12) {
    return Eigen::Matrix3d::Identity();
  }
  return Eigen::AngleAxisd(angle, omega / angle).toRotationMatrix();
}

Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

/// At most this many points in an iteration of refinePose while its gate still shrinks.
constexpr std::size_t kSubsetPoints = 300;

}  // namespace

IcpResult refinePose(const ObjectModel& model, const std::vector<Eigen::Vector3f>& scene, const world::Pose& initial,
                     int iterations, double initial_distance, double final_distance, double point_to_point_weight) {
  IcpResult result;
  // Work with the inverse: camera -> object frame, where the grid lives.
  Eigen::Isometry3d to_object = initial.inverse();
  const int total = std::max(1, iterations);
  for (int iteration = 0; iteration < total; ++iteration) {
    const double fraction = total == 1 ? 1.0 : static_cast<double>(iteration) / (total - 1);
    const double gate = initial_distance + (final_distance - initial_distance) * std::min(1.0, 1.5 * fraction);
    const double gate_squared = gate * gate;
    Eigen::Matrix<double, 6, 6> a = Eigen::Matrix<double, 6, 6>::Zero();
    Eigen::Matrix<double, 6, 1> b = Eigen::Matrix<double, 6, 1>::Zero();
    const Eigen::Isometry3f transform = to_object.cast<float>();
    double squared_sum = 0.0;
    int inliers = 0;
    // Coarse to fine: while the gate still shrinks, an even subset of the points (each step is a
    // 6-parameter least-squares fit, which a few hundred points set as well as all); from the
    // final gate on, all of them.
    const bool shrinking = 1.5 * fraction < 1.0;
    const std::size_t stride =
        shrinking && scene.size() > kSubsetPoints ? (scene.size() + kSubsetPoints - 1) / kSubsetPoints : 1;
    for (std::size_t index = 0; index < scene.size(); index += stride) {
      const Eigen::Vector3f q = transform * scene[index];
      const int nearest = model.grid.lookup(q);
      if (nearest < 0) {
        continue;
      }
      const Eigen::Vector3f& m = model.surface.points[static_cast<std::size_t>(nearest)];
      const Eigen::Vector3f d = q - m;
      if (d.squaredNorm() > gate_squared) {
        continue;
      }
      const Eigen::Vector3d n = model.surface.normals[static_cast<std::size_t>(nearest)].cast<double>();
      const Eigen::Vector3d qd = q.cast<double>();
      const double r = n.dot(d.cast<double>());
      // Huber weight; the knee follows the gate (wide early: far points pull as a whole).
      const double knee = std::max(0.0015, gate / 4.0);
      const double weight = std::abs(r) < knee ? 1.0 : knee / std::abs(r);
      Eigen::Matrix<double, 6, 1> j;
      j << qd.cross(n), n;
      // The lower triangle only (all the LDLT solve below reads), each term as Eigen's outer
      // product forms it: the same sums as the whole matrix's lower half.
      const Eigen::Matrix<double, 6, 1> weighted = weight * j;
      for (int col = 0; col < 6; ++col) {
        for (int row = col; row < 6; ++row) {
          a(row, col) += j(col) * weighted(row);
        }
      }
      b.noalias() += weight * j * r;
      // An optional weak point-to-point term: past an edge, the nearest sample of a face says
      // nothing along the face, and this term still pulls (an elongated object sliding along
      // its axis); inside faces it adds the sample spacing's jitter, so only coarse runs use it.
      if (point_to_point_weight > 0) {
        Eigen::Matrix<double, 3, 6> jp;
        jp << -skew(qd), Eigen::Matrix3d::Identity();
        const Eigen::Vector3d dd = d.cast<double>();
        const double point_weight = point_to_point_weight * (dd.norm() < knee ? 1.0 : knee / dd.norm());
        a.noalias() += point_weight * jp.transpose() * jp;
        b.noalias() += point_weight * jp.transpose() * dd;
      }
      squared_sum += r * r;
      ++inliers;
    }
    result.inliers = inliers;
    result.rms = inliers > 0 ? std::sqrt(squared_sum / inliers) : 0.0;
    result.iterations = iteration + 1;
    if (inliers < 6) {
      break;
    }
    // Damped normal equations: directions the visible surface does not constrain stay put. (Only
    // the lower triangle of `a` is filled: LDLT reads no more.)
    a.diagonal().array() += 1e-9 + 1e-6 * a.trace() / 6.0;
    const Eigen::Matrix<double, 6, 1> x = a.ldlt().solve(-b);
    Eigen::Isometry3d step = Eigen::Isometry3d::Identity();
    step.linear() = rotationFromVector(x.head<3>());
    step.translation() = x.tail<3>();
    to_object = step * to_object;
    // Converged once the gate has shrunk to its final value.
    if (x.head<3>().norm() < 2e-5 && x.tail<3>().norm() < 2e-6 && 1.5 * fraction >= 1.0) {
      break;
    }
  }
  result.pose = to_object.inverse();
  result.pose.linear() = Eigen::Quaterniond(result.pose.linear()).normalized().toRotationMatrix();
  return result;
}

}  // namespace costar::perception
