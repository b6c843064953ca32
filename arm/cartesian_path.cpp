#include "arm/cartesian_path.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include <Eigen/Geometry>

namespace costar::arm {

namespace {

/// Metres a turn of one radian counts as.
constexpr double kTurnLength = 0.1;
constexpr double kTiny = 1e-9;

bool finite(const world::Pose& pose) { return pose.matrix().allFinite(); }

}  // namespace

CartesianPath CartesianPath::through(const std::vector<world::Pose>& poses, const Options& options) {
  if (poses.empty()) {
    throw std::invalid_argument("a Cartesian path needs at least one pose");
  }
  for (std::size_t i = 0; i < poses.size(); ++i) {
    if (!finite(poses[i])) {
      throw std::invalid_argument("a Cartesian path's pose " + std::to_string(i + 1) + " is not finite");
    }
  }
  if (!(options.speed > 0 && std::isfinite(options.speed)) ||
      !(options.acceleration > 0 && std::isfinite(options.acceleration)) ||
      !(options.blend >= 0 && std::isfinite(options.blend))) {
    throw std::invalid_argument("a Cartesian path needs a positive speed and acceleration and a blend of 0 or more");
  }
  CartesianPath path;
  const std::size_t n = poses.size();
  std::vector<Eigen::Vector3d> p(n);
  std::vector<Eigen::Quaterniond> q(n);
  for (std::size_t i = 0; i < n; ++i) {
    p[i] = poses[i].translation();
    q[i] = Eigen::Quaterniond(poses[i].linear()).normalized();
    if (i > 0 && q[i].dot(q[i - 1]) < 0) {
      q[i].coeffs() = -q[i].coeffs();  // the short way round
    }
  }
  // Lines between the poses and the trim of each corner's blend.
  std::vector<Eigen::Vector3d> direction(n > 1 ? n - 1 : 0, Eigen::Vector3d::Zero());
  std::vector<double> distance(direction.size(), 0.0);
  for (std::size_t i = 0; i + 1 < n; ++i) {
    distance[i] = (p[i + 1] - p[i]).norm();
    if (distance[i] > kTiny) {
      direction[i] = (p[i + 1] - p[i]) / distance[i];
    }
  }
  std::vector<double> trim(n, 0.0);
  std::vector<double> turn(n, 0.0);  // the corner's angle
  for (std::size_t k = 1; k + 1 < n; ++k) {
    if (distance[k - 1] <= kTiny || distance[k] <= kTiny) {
      continue;
    }
    const double angle = std::acos(std::clamp(direction[k - 1].dot(direction[k]), -1.0, 1.0));
    if (angle < 1e-6 || angle > M_PI - 1e-6) {
      continue;
    }
    trim[k] = std::min({options.blend * std::tan(angle / 2), 0.4 * distance[k - 1], 0.4 * distance[k]});
    turn[k] = trim[k] > kTiny ? angle : 0.0;
    if (turn[k] == 0.0) {
      trim[k] = 0.0;
    }
  }
  double arc = 0.0;
  path.waypoint_arc_.assign(n, 0.0);
  for (std::size_t i = 0; i + 1 < n; ++i) {
    Piece line;
    line.start = arc;
    line.from = p[i] + direction[i] * trim[i];
    line.direction = direction[i];
    line.travel = std::max(0.0, distance[i] - trim[i] - trim[i + 1]);
    line.length = std::max(line.travel, kTurnLength * q[i].angularDistance(q[i + 1]));
    line.rotation_from = q[i];
    line.rotation_to = q[i + 1];
    path.pieces_.push_back(line);
    arc += line.length;
    if (i + 2 < n && turn[i + 1] > 0.0) {
      const std::size_t k = i + 1;
      Piece blend;
      blend.arc = true;
      blend.start = arc;
      blend.angle = turn[k];
      blend.radius = trim[k] / std::tan(turn[k] / 2);
      blend.length = blend.radius * blend.angle;
      const Eigen::Vector3d normal =
          (direction[k] - direction[k].dot(direction[k - 1]) * direction[k - 1]).normalized();
      const Eigen::Vector3d begin = p[k] - direction[k - 1] * trim[k];
      blend.centre = begin + blend.radius * normal;
      blend.u = -normal;
      blend.v = direction[k - 1];
      blend.rotation_from = q[k];
      blend.rotation_to = q[k];
      path.pieces_.push_back(blend);
      path.waypoint_arc_[k] = arc + blend.length / 2;
      arc += blend.length;
    } else {
      path.waypoint_arc_[i + 1] = arc;
    }
  }
  if (path.pieces_.empty()) {
    Piece hold;
    hold.from = p[0];
    hold.rotation_from = q[0];
    hold.rotation_to = q[0];
    path.pieces_.push_back(hold);
  }
  path.length_ = arc;
  path.acceleration_ = options.acceleration;
  path.speed_ = std::min(options.speed, std::sqrt(options.acceleration * arc));
  if (arc > 0.0) {
    path.ramp_time_ = path.speed_ / path.acceleration_;
    path.total_time_ = arc / path.speed_ + path.ramp_time_;
  }
  path.duration_ = Duration(static_cast<std::int64_t>(std::ceil(path.total_time_ * 1e9)));
  return path;
}

std::pair<double, double> CartesianPath::progress(double t) const {
  if (total_time_ <= 0.0) {
    return {0.0, 0.0};
  }
  t = std::clamp(t, 0.0, total_time_);
  if (t < ramp_time_) {
    return {0.5 * acceleration_ * t * t, acceleration_ * t};
  }
  if (t > total_time_ - ramp_time_) {
    const double left = total_time_ - t;
    return {length_ - 0.5 * acceleration_ * left * left, acceleration_ * left};
  }
  return {0.5 * acceleration_ * ramp_time_ * ramp_time_ + speed_ * (t - ramp_time_), speed_};
}

const CartesianPath::Piece& CartesianPath::pieceAt(double arc) const {
  const auto after = std::upper_bound(pieces_.begin(), pieces_.end(), arc,
                                      [](double s, const Piece& piece) { return s < piece.start; });
  return after == pieces_.begin() ? pieces_.front() : *std::prev(after);
}

Eigen::Vector3d CartesianPath::positionIn(const Piece& piece, double along) const {
  if (piece.arc) {
    const double angle = piece.length > 0 ? piece.angle * along / piece.length : 0.0;
    return piece.centre + piece.radius * (piece.u * std::cos(angle) + piece.v * std::sin(angle));
  }
  const double fraction = piece.length > 0 ? along / piece.length : 0.0;
  return piece.from + piece.direction * piece.travel * fraction;
}

Eigen::Vector3d CartesianPath::tangentIn(const Piece& piece, double along) const {
  if (piece.arc) {
    const double angle = piece.length > 0 ? piece.angle * along / piece.length : 0.0;
    return -piece.u * std::sin(angle) + piece.v * std::cos(angle);
  }
  // Metres of travel per metre of arc (less than 1 where a turn takes longer than the travel).
  if (piece.length <= 0) {
    return Eigen::Vector3d::Zero();
  }
  return piece.direction * (piece.travel / piece.length);
}

Eigen::Quaterniond CartesianPath::rotationIn(const Piece& piece, double along) const {
  const double fraction = piece.length > 0 ? std::clamp(along / piece.length, 0.0, 1.0) : 0.0;
  return piece.rotation_from.slerp(fraction, piece.rotation_to);
}

world::Pose CartesianPath::poseAt(double arc) const {
  arc = std::clamp(arc, 0.0, length_);
  const Piece& piece = pieceAt(arc);
  const double along = std::min(arc - piece.start, piece.length);
  world::Pose pose = world::Pose::Identity();
  pose.linear() = rotationIn(piece, along).toRotationMatrix();
  pose.translation() = positionIn(piece, along);
  return pose;
}

CartesianPath::Sample CartesianPath::sample(Duration t) const {
  const auto [arc, speed] = progress(toSeconds(t));
  Sample sample;
  sample.arc = arc;
  const Piece& piece = pieceAt(arc);
  const double along = std::min(arc - piece.start, piece.length);
  sample.pose.linear() = rotationIn(piece, along).toRotationMatrix();
  sample.pose.translation() = positionIn(piece, along);
  sample.velocity = tangentIn(piece, along) * speed;
  if (piece.length > 0 && piece.rotation_from.angularDistance(piece.rotation_to) > 0) {
    const Eigen::AngleAxisd turn(piece.rotation_to * piece.rotation_from.inverse());
    sample.angular_velocity = turn.axis() * turn.angle() / piece.length * speed;
  }
  return sample;
}

}  // namespace costar::arm
