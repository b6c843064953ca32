#pragma once
// A timed Cartesian path of the tool centre point: straight lines through poses, each corner
// rounded by a circular blend, travelled at one speed with a trapezoidal profile over the whole
// length (at rest at both ends). The orientation turns along each line by slerp and holds
// through a blend; a pose that only turns the tool counts 0.1 m per radian of turn. Used as
// the reference of the controller's Cartesian motions (arm/cartesian_controller.h). Units m,
// m/s, m/s^2; time is costar::Duration from the start of the path.

#include <cstddef>
#include <vector>

#include <Eigen/Core>

#include "core/clock.h"
#include "world/pose.h"

namespace costar::arm {

class CartesianPath {
 public:
  struct Options {
    double speed = 0.05;        // m/s along the path
    double acceleration = 0.5;  // m/s^2
    /// Radius of the corners' blends (m): at most this, and at most 40 % of either line.
    double blend = 0.01;
  };

  /// A path through `poses` (one pose: holding it). @throws std::invalid_argument for no pose,
  /// a pose that is not finite, or a speed, acceleration or blend that is not positive and finite
  /// (a blend of 0 is allowed: sharp corners).
  static CartesianPath through(const std::vector<world::Pose>& poses, const Options& options);

  struct Sample {
    world::Pose pose = world::Pose::Identity();
    Eigen::Vector3d velocity = Eigen::Vector3d::Zero();          // m/s, world
    Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();  // rad/s, world
    double arc = 0.0;                                            // m travelled along the path
  };
  /// The reference at `t` from the start, clamped into [0, duration()].
  Sample sample(Duration t) const;
  /// The pose `arc` m along the path (clamped to its ends).
  world::Pose poseAt(double arc) const;
  Duration duration() const { return duration_; }
  /// The path's length (m; a turn counts 0.1 m per radian).
  double length() const { return length_; }
  /// Where along the path (m) it passes pose `index` of those it was made through (at a corner:
  /// the middle of its blend).
  double arcAt(std::size_t index) const { return waypoint_arc_.at(index); }
  std::size_t waypointCount() const { return waypoint_arc_.size(); }

 private:
  struct Piece {
    double start = 0.0;   // arc length where it begins
    double length = 0.0;  // its arc length
    // A line: from `from` along `direction` (unit; zero for a turn in place). A blend: an arc
    // about `centre` in the plane of `u` (from the centre to its start) and `v` (perpendicular,
    // toward the way it turns), through `angle` with `radius`.
    bool arc = false;
    Eigen::Vector3d from = Eigen::Vector3d::Zero();
    Eigen::Vector3d direction = Eigen::Vector3d::Zero();
    double travel = 0.0;  // m of straight travel (less than length for a turn)
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    Eigen::Vector3d u = Eigen::Vector3d::Zero();
    Eigen::Vector3d v = Eigen::Vector3d::Zero();
    double radius = 0.0;
    double angle = 0.0;
    Eigen::Quaterniond rotation_from = Eigen::Quaterniond::Identity();
    Eigen::Quaterniond rotation_to = Eigen::Quaterniond::Identity();
  };
  Eigen::Vector3d positionIn(const Piece& piece, double along) const;
  Eigen::Vector3d tangentIn(const Piece& piece, double along) const;
  Eigen::Quaterniond rotationIn(const Piece& piece, double along) const;
  const Piece& pieceAt(double arc) const;
  /// Arc length and path speed at time t (s).
  std::pair<double, double> progress(double t) const;

  std::vector<Piece> pieces_;
  std::vector<double> waypoint_arc_;
  double length_ = 0.0;
  double speed_ = 0.0;         // cruise speed reached
  double acceleration_ = 0.0;  // m/s^2
  double ramp_time_ = 0.0;     // s to reach speed_
  double total_time_ = 0.0;
  Duration duration_{0};
};

}  // namespace costar::arm
