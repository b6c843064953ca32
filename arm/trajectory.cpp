#include "arm/trajectory.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <stdexcept>

namespace costar::arm {
namespace {

// Consecutive path points closer than this (radians, Euclidean) are one point.
constexpr double kSamePointDistance = 1e-12;

std::string number(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.6g", value);
  return buffer;
}

[[noreturn]] void fail(const std::string& who, const std::string& message) {
  throw std::invalid_argument(who + ": " + message);
}

void checkSpeedScale(double speed_scale, const std::string& who) {
  if (!(speed_scale > 0.0 && speed_scale <= 1.0)) {  // also rejects NaN
    fail(who, "speed_scale must be in (0, 1], got " + number(speed_scale));
  }
}

void checkFinite(const JointVector& q, const std::string& who, const std::string& what) {
  for (int j = 0; j < q.size(); ++j) {
    if (!std::isfinite(q[j])) {
      fail(who, what + ": joint " + std::to_string(j + 1) + " is " + number(q[j]));
    }
  }
}

// Finite and within the position limits; `what` names the point in the message.
void checkPosition(const JointVector& q, const JointLimits& limits, const std::string& who, const std::string& what) {
  if (q.size() != limits.size()) {
    fail(who, what + " has " + std::to_string(q.size()) + " joints, the limits " + std::to_string(limits.size()));
  }
  checkFinite(q, who, what);
  for (int j = 0; j < q.size(); ++j) {
    if (q[j] >= limits.min_position[j] && q[j] <= limits.max_position[j]) {
      continue;
    }
    const std::string joint = "joint " + std::to_string(j + 1) + " of " + what + " is " + number(q[j]) + " rad, ";
    if (q[j] < limits.min_position[j]) {
      fail(who, joint + "below its minimum " + number(limits.min_position[j]) + " rad by " +
                    number(limits.min_position[j] - q[j]) + " rad");
    }
    if (q[j] > limits.max_position[j]) {
      fail(who, joint + "above its maximum " + number(limits.max_position[j]) + " rad by " +
                    number(q[j] - limits.max_position[j]) + " rad");
    }
  }
}

JointVector scaled(const JointVector& v, double factor) {
  JointVector result = v;
  for (int j = 0; j < v.size(); ++j) {
    result[j] = v[j] * factor;
  }
  return result;
}

JointVector difference(const JointVector& a, const JointVector& b) {
  JointVector result = a;
  for (int j = 0; j < a.size(); ++j) {
    result[j] = a[j] - b[j];
  }
  return result;
}

double norm(const JointVector& v) {
  double sum = 0.0;
  for (double value : v) {
    sum += value * value;
  }
  return std::sqrt(sum);
}

// origin + distance * direction.
JointVector along(const JointVector& origin, const JointVector& direction, double distance) {
  JointVector result = origin;
  for (int j = 0; j < origin.size(); ++j) {
    result[j] = origin[j] + distance * direction[j];
  }
  return result;
}

// Largest rate along the unit direction `direction` that keeps every joint within
// `per_joint_limit` (velocity or acceleration): min_j limit_j / |direction_j|.
double rateLimitAlong(const JointVector& direction, const JointVector& per_joint_limit) {
  double limit = std::numeric_limits<double>::infinity();
  for (int j = 0; j < direction.size(); ++j) {
    if (direction[j] != 0.0) {
      limit = std::min(limit, per_joint_limit[j] / std::abs(direction[j]));
    }
  }
  return limit;
}

}  // namespace

// Appends constant-acceleration phases back to back.
class JointTrajectory::Builder {
 public:
  /// A phase starting at `position` with `velocity`, accelerating at `acceleration` for
  /// `duration` seconds. Phases of zero duration are dropped.
  void add(const JointVector& position, const JointVector& velocity, const JointVector& acceleration, double duration) {
    if (!(duration > 0.0)) {
      return;
    }
    phases_.push_back(Phase{time_, position, velocity, acceleration});
    time_ += duration;
  }

  /// Straight motion along the unit `direction` from origin + offset * direction over
  /// `distance`, from speed `speed_from` to `speed_to` (path speeds, rad/s along the direction),
  /// never faster than `max_speed` nor accelerating faster than `max_acceleration`: accelerate,
  /// cruise, decelerate. Precondition: |speed_from^2 - speed_to^2| <= 2 max_acceleration
  /// distance, both speeds <= max_speed.
  void addRamp(const JointVector& origin, const JointVector& direction, double offset, double speed_from,
               double speed_to, double distance, double max_speed, double max_acceleration) {
    if (!(distance > 0.0)) {
      return;
    }
    // Peak speed: where the acceleration and deceleration parabolas meet, capped.
    double peak = std::sqrt(max_acceleration * distance + 0.5 * (speed_from * speed_from + speed_to * speed_to));
    peak = std::max(std::min(peak, max_speed), std::max(speed_from, speed_to));
    const double accelerate_time = (peak - speed_from) / max_acceleration;
    const double accelerate_distance = 0.5 * (speed_from + peak) * accelerate_time;
    const double decelerate_time = (peak - speed_to) / max_acceleration;
    const double decelerate_distance = 0.5 * (peak + speed_to) * decelerate_time;
    const double cruise_distance = std::max(0.0, distance - accelerate_distance - decelerate_distance);
    const double cruise_time = peak > 0.0 ? cruise_distance / peak : 0.0;
    const JointVector zero = JointVector::zero(origin.size());
    add(along(origin, direction, offset), scaled(direction, speed_from), scaled(direction, max_acceleration),
        accelerate_time);
    add(along(origin, direction, offset + accelerate_distance), scaled(direction, peak), zero, cruise_time);
    add(along(origin, direction, offset + accelerate_distance + cruise_distance), scaled(direction, peak),
        scaled(direction, -max_acceleration), decelerate_time);
  }

  /// The trajectory, ending at rest at `final_position`.
  JointTrajectory finish(const JointVector& final_position) {
    if (phases_.empty()) {
      const JointVector zero = JointVector::zero(final_position.size());
      phases_.push_back(Phase{0.0, final_position, zero, zero});
    }
    return JointTrajectory(std::move(phases_), time_, final_position);
  }

 private:
  std::vector<Phase> phases_;
  double time_ = 0.0;
};

JointTrajectory::JointTrajectory(std::vector<Phase> phases, double total_seconds, const JointVector& final_position)
    : phases_(std::move(phases)),
      total_seconds_(total_seconds),
      duration_(static_cast<std::int64_t>(std::ceil(total_seconds * 1e9))),
      final_position_(final_position) {}

void JointTrajectory::validate(const JointLimits& limits, const std::string& who) {
  const int count = limits.min_position.size();
  if (count == 0 || limits.max_position.size() != count || limits.max_velocity.size() != count ||
      limits.max_acceleration.size() != count) {
    fail(who,
         "the limits need one value per joint in each of min_position, max_position, max_velocity and "
         "max_acceleration, got " +
             std::to_string(limits.min_position.size()) + ", " + std::to_string(limits.max_position.size()) + ", " +
             std::to_string(limits.max_velocity.size()) + " and " + std::to_string(limits.max_acceleration.size()));
  }
  for (int j = 0; j < count; ++j) {
    const auto joint = [j] { return "joint " + std::to_string(j + 1) + " "; };
    if (!std::isfinite(limits.min_position[j]) || !std::isfinite(limits.max_position[j]) ||
        limits.min_position[j] > limits.max_position[j]) {
      fail(who, joint() + "position limits [" + number(limits.min_position[j]) + ", " + number(limits.max_position[j]) +
                    "] are not a finite interval");
    }
    if (!(limits.max_velocity[j] > 0.0) || !std::isfinite(limits.max_velocity[j])) {
      fail(who, joint() + "max_velocity must be positive and finite, got " + number(limits.max_velocity[j]));
    }
    if (!(limits.max_acceleration[j] > 0.0) || !std::isfinite(limits.max_acceleration[j])) {
      fail(who, joint() + "max_acceleration must be positive and finite, got " + number(limits.max_acceleration[j]));
    }
  }
}

JointTrajectory JointTrajectory::hold(const JointVector& position) {
  checkFinite(position, "JointTrajectory::hold", "position");
  return Builder().finish(position);
}

JointTrajectory JointTrajectory::pointToPoint(const JointVector& from, const JointVector& to, const JointLimits& limits,
                                              double speed_scale) {
  const std::string who = "JointTrajectory::pointToPoint";
  validate(limits, who);
  checkSpeedScale(speed_scale, who);
  checkPosition(from, limits, who, "the start");
  checkPosition(to, limits, who, "the target");
  const JointVector displacement = difference(to, from);
  const double distance = norm(displacement);
  Builder builder;
  if (distance > 0.0) {
    const JointVector direction = scaled(displacement, 1.0 / distance);
    builder.addRamp(from, direction, 0.0, 0.0, 0.0, distance,
                    rateLimitAlong(direction, scaled(limits.max_velocity, speed_scale)),
                    rateLimitAlong(direction, scaled(limits.max_acceleration, speed_scale)));
  }
  return builder.finish(to);
}

JointTrajectory JointTrajectory::alongPath(const std::vector<JointVector>& path, const JointLimits& limits,
                                           double speed_scale, double path_tolerance) {
  const std::string who = "JointTrajectory::alongPath";
  validate(limits, who);
  checkSpeedScale(speed_scale, who);
  if (!(path_tolerance > 0.0) || !std::isfinite(path_tolerance)) {
    fail(who, "path_tolerance must be positive and finite, got " + number(path_tolerance));
  }
  if (path.empty()) {
    fail(who, "the path is empty");
  }
  for (std::size_t k = 0; k < path.size(); ++k) {
    bool valid = path[k].size() == limits.size();
    for (int j = 0; valid && j < limits.size(); ++j) {
      valid = valid && path[k][j] >= limits.min_position[j] && path[k][j] <= limits.max_position[j];  // NaN: false
    }
    if (!valid) {
      checkPosition(path[k], limits, who, "path point " + std::to_string(k));  // throws, saying why
    }
  }
  std::vector<JointVector> points;
  points.reserve(path.size());
  for (const JointVector& point : path) {
    if (points.empty() || norm(difference(point, points.back())) > kSamePointDistance) {
      points.push_back(point);
    }
  }
  const std::size_t segment_count = points.size() - 1;
  if (segment_count == 0) {
    return hold(points.front());
  }
  const JointVector max_velocity = scaled(limits.max_velocity, speed_scale);
  const JointVector max_acceleration = scaled(limits.max_acceleration, speed_scale);

  // Segments: length, unit direction, and the path speed and acceleration limits along it.
  std::vector<double> length(segment_count);
  std::vector<JointVector> direction(segment_count);
  std::vector<double> max_speed(segment_count);
  std::vector<double> max_path_acceleration(segment_count);
  for (std::size_t i = 0; i < segment_count; ++i) {
    const JointVector displacement = difference(points[i + 1], points[i]);
    length[i] = norm(displacement);
    direction[i] = scaled(displacement, 1.0 / length[i]);
    max_speed[i] = rateLimitAlong(direction[i], max_velocity);
    max_path_acceleration[i] = rateLimitAlong(direction[i], max_acceleration);
  }

  // Corners (points 1 .. n-1; points 0 and n are the ends, at rest). A corner taken at path
  // speed s has a blend of duration b = s * turn[c] (turn = max_j |e_out_j - e_in_j| / a_j:
  // every joint within its acceleration limit, the most turning one at it), which reaches
  // reach = s * b / 2 = s^2 * turn / 2 into each adjacent segment and deviates from the corner
  // by at most s * b * |e_out - e_in| / 8. squared_speed[c] is s^2: first its bound at the
  // corner itself (velocity limits on both segments, the tolerance, and a reach of at most half
  // of each adjacent segment).
  std::vector<double> squared_speed(segment_count + 1, 0.0);
  std::vector<double> turn(segment_count + 1, 0.0);
  for (std::size_t c = 1; c < segment_count; ++c) {
    const JointVector change = difference(direction[c], direction[c - 1]);
    for (int j = 0; j < change.size(); ++j) {
      turn[c] = std::max(turn[c], std::abs(change[j]) / max_acceleration[j]);
    }
    double bound = std::min(max_speed[c - 1] * max_speed[c - 1], max_speed[c] * max_speed[c]);
    if (turn[c] > 0.0) {
      bound = std::min(bound, 8.0 * path_tolerance / (turn[c] * norm(change)));  // deviation
      bound = std::min(bound, std::min(length[c - 1], length[c]) / turn[c]);     // reach <= length / 2
    }
    squared_speed[c] = bound;
  }
  // Between the blends, segment i changes speed at most at its path acceleration a_i over what
  // the blends leave of it: |w_i+1 - w_i| <= 2 a_i (L_i - turn_i w_i / 2 - turn_i+1 w_i+1 / 2)
  // with w = s^2. A forward pass enforces it when speeding up, a backward pass when slowing
  // down; the backward pass only lowers speeds, which keeps what the forward pass ensured (a
  // corner it lowers ends up at least as fast as the next one). The half-segment bound on the
  // reach keeps both numerators positive.
  for (std::size_t c = 1; c <= segment_count; ++c) {
    const double a = max_path_acceleration[c - 1];
    const double reachable =
        (squared_speed[c - 1] * (1.0 - a * turn[c - 1]) + 2.0 * a * length[c - 1]) / (1.0 + a * turn[c]);
    squared_speed[c] = std::min(squared_speed[c], std::max(0.0, reachable));
  }
  squared_speed[segment_count] = 0.0;
  for (std::size_t c = segment_count; c-- > 0;) {
    const double a = max_path_acceleration[c];
    const double stoppable =
        (squared_speed[c + 1] * (1.0 - a * turn[c + 1]) + 2.0 * a * length[c]) / (1.0 + a * turn[c]);
    squared_speed[c] = std::min(squared_speed[c], std::max(0.0, stoppable));
  }

  Builder builder;
  for (std::size_t i = 0; i < segment_count; ++i) {
    const double speed_from = std::sqrt(squared_speed[i]);
    const double speed_to = std::sqrt(squared_speed[i + 1]);
    const double reach_from = 0.5 * squared_speed[i] * turn[i];
    const double reach_to = 0.5 * squared_speed[i + 1] * turn[i + 1];
    builder.addRamp(points[i], direction[i], reach_from, speed_from, speed_to, length[i] - reach_from - reach_to,
                    max_speed[i], max_path_acceleration[i]);
    if (i + 1 < segment_count && turn[i + 1] > 0.0 && speed_to > 0.0) {
      // Parabolic blend around point i + 1: constant acceleration from speed_to * e_in to
      // speed_to * e_out, centred on the time the straight path would pass the point.
      JointVector acceleration = difference(direction[i + 1], direction[i]);
      acceleration = scaled(acceleration, 1.0 / turn[i + 1]);
      builder.add(along(points[i + 1], direction[i], -reach_to), scaled(direction[i], speed_to), acceleration,
                  speed_to * turn[i + 1]);
    }
  }
  return builder.finish(points.back());
}

JointTrajectory JointTrajectory::stopFrom(const TrajectoryPoint& state, const JointLimits& limits) {
  const std::string who = "JointTrajectory::stopFrom";
  validate(limits, who);
  checkFinite(state.position, who, "the position");
  checkFinite(state.velocity, who, "the velocity");
  if (state.position.size() != limits.size() || state.velocity.size() != limits.size()) {
    fail(who, "the state has " + std::to_string(state.position.size()) + " positions and " +
                  std::to_string(state.velocity.size()) + " velocities, the limits " + std::to_string(limits.size()) +
                  " joints");
  }
  double stop_time = 0.0;
  for (int j = 0; j < limits.size(); ++j) {
    stop_time = std::max(stop_time, std::abs(state.velocity[j]) / limits.max_acceleration[j]);
  }
  if (stop_time == 0.0) {
    return hold(state.position);
  }
  Builder builder;
  builder.add(state.position, state.velocity, scaled(state.velocity, -1.0 / stop_time), stop_time);
  return builder.finish(along(state.position, state.velocity, 0.5 * stop_time));
}

TrajectoryPoint JointTrajectory::sample(Duration t) const {
  double seconds = toSeconds(t);
  if (t >= duration_ || !(seconds < total_seconds_)) {
    const JointVector zero = JointVector::zero(final_position_.size());
    return TrajectoryPoint{final_position_, zero, zero};
  }
  seconds = std::max(seconds, 0.0);
  // The last phase starting at or before `seconds` (the first starts at 0).
  const auto next = std::upper_bound(phases_.begin(), phases_.end(), seconds,
                                     [](double time, const Phase& phase) { return time < phase.start_time; });
  const Phase& phase = *(next - 1);
  const double tau = seconds - phase.start_time;
  TrajectoryPoint point{phase.position, phase.velocity, phase.acceleration};
  for (int j = 0; j < phase.position.size(); ++j) {
    point.position[j] = phase.position[j] + tau * (phase.velocity[j] + 0.5 * tau * phase.acceleration[j]);
    point.velocity[j] = phase.velocity[j] + tau * phase.acceleration[j];
    point.acceleration[j] = phase.acceleration[j];
  }
  return point;
}

}  // namespace costar::arm
