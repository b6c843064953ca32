#include "sim/speed_separation.h"

#include <algorithm>
#include <cstdio>
#include <limits>

namespace costar::sim {

namespace {

/// The shortest distance between segments p1-q1 and p2-q2 (Ericson, Real-Time Collision
/// Detection, 5.1.9).
double segmentDistance(const Eigen::Vector3d& p1, const Eigen::Vector3d& q1, const Eigen::Vector3d& p2,
                       const Eigen::Vector3d& q2) {
  constexpr double kTiny = 1e-12;
  const Eigen::Vector3d d1 = q1 - p1;
  const Eigen::Vector3d d2 = q2 - p2;
  const Eigen::Vector3d r = p1 - p2;
  const double a = d1.squaredNorm();
  const double e = d2.squaredNorm();
  const double f = d2.dot(r);
  double s = 0.0;
  double t = 0.0;
  if (a <= kTiny && e <= kTiny) {
    return r.norm();
  }
  if (a <= kTiny) {
    t = std::clamp(f / e, 0.0, 1.0);
  } else {
    const double c = d1.dot(r);
    if (e <= kTiny) {
      s = std::clamp(-c / a, 0.0, 1.0);
    } else {
      const double b = d1.dot(d2);
      const double denominator = a * e - b * b;
      s = denominator > kTiny ? std::clamp((b * f - c * e) / denominator, 0.0, 1.0) : 0.0;
      t = (b * s + f) / e;
      if (t < 0.0) {
        t = 0.0;
        s = std::clamp(-c / a, 0.0, 1.0);
      } else if (t > 1.0) {
        t = 1.0;
        s = std::clamp((b - c) / a, 0.0, 1.0);
      }
    }
  }
  return ((p1 + d1 * s) - (p2 + d2 * t)).norm();
}

}  // namespace

double capsuleDistance(const Capsule& first, const Capsule& second) {
  return segmentDistance(first.a, first.b, second.a, second.b) - first.radius - second.radius;
}

double protectiveDistance(const SpeedSeparationParams& params, double robot_speed) {
  const double reaction = params.reactionTime();
  return params.human_speed * (reaction + params.stopping_time) + robot_speed * reaction +
         params.stopping_distance_per_speed * robot_speed + params.intrusion + params.sensor_uncertainty +
         params.robot_uncertainty;
}

SpeedSeparationMonitor::SpeedSeparationMonitor(SpeedSeparationParams params, CollaborativeParams collaborative)
    : params_(params), collaborative_params_(collaborative) {}

void SpeedSeparationMonitor::setCollaborative(bool on) {
  collaborative_ = on;
  contact_stop_.clear();
}

void SpeedSeparationMonitor::setContact(double force, bool hand_only) {
  if (!collaborative_ || force <= 0.0 || !contact_stop_.empty()) {
    return;
  }
  if (!hand_only) {
    contact_stop_ = "contact outside the hand";
  } else if (force > collaborative_params_.hand_force_limit) {
    char text[64];
    std::snprintf(text, sizeof text, "hand force above %.0f N", collaborative_params_.hand_force_limit);
    contact_stop_ = text;
  }
}

double SpeedSeparationMonitor::update(double dt, std::optional<double> sensed_separation, double arm_speed) {
  const double before = scale_;
  std::string reason;
  if (collaborative_) {
    allowed_ = contact_stop_.empty() ? collaborative_params_.max_speed : 0.0;
    reason = contact_stop_;
  } else if (!sensed_separation) {
    allowed_ = std::numeric_limits<double>::infinity();
  } else {
    const double standing = protectiveDistance(params_, 0.0) + params_.margin;
    allowed_ =
        std::max(0.0, (*sensed_separation - standing) / (params_.reactionTime() + params_.stopping_distance_per_speed));
    if (state_ == State::kStopped && *sensed_separation < standing + params_.resume_gap) {
      allowed_ = 0.0;  // hysteresis: stay stopped until the person is clearly back
    }
    reason = allowed_ <= 0.0 ? "separation" : "";
  }
  if (stop_input_) {
    allowed_ = 0.0;
    reason = "stop input";
  }
  if (allowed_ <= 0.0 || arm_speed > allowed_) {
    scale_ = std::max(0.0, scale_ - dt / params_.ramp_down);
  } else if (arm_speed < 0.8 * allowed_) {
    scale_ = std::min(1.0, scale_ + dt / params_.ramp_up);
  }
  if (allowed_ <= 0.0) {
    if (state_ != State::kStopped) {
      ++stops_;
    }
    state_ = State::kStopped;
    stop_reason_ = reason;
  } else {
    state_ = scale_ < 1.0 ? State::kLimited : State::kFree;
    stop_reason_.clear();
  }
  rate_ = dt > 0.0 ? (scale_ - before) / dt : 0.0;
  return scale_;
}

std::string stateName(SpeedSeparationMonitor::State state) {
  switch (state) {
    case SpeedSeparationMonitor::State::kFree:
      return "free";
    case SpeedSeparationMonitor::State::kLimited:
      return "limited";
    case SpeedSeparationMonitor::State::kStopped:
      return "stopped";
  }
  return "free";
}

}  // namespace costar::sim
