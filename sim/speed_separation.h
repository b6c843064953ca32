#pragma once
// Speed and separation monitoring (ISO/TS 15066:2016, 5.5.4): the arm's speed is scaled so that
// the separation S between the arm (with its gripper) and a person stays at or above the
// protective separation distance
//   S_p(v_r) = v_h (T_r + T_s) + v_r T_r + S_s(v_r) + C + Z_d + Z_r
// with v_h the person's speed (1.6 m/s), v_r the arm's fastest point speed, T_r the reaction
// time (the separation sensor's period plus one control period), T_s the arm's stopping time,
// S_s(v_r) = k_s v_r its stopping distance (T_s and k_s measured on the simulated arm:
// bench/ssm_bench), C the intrusion distance, Z_d the sensor's and Z_r the arm's position
// uncertainty. docs/PERSON.md has the numbers and what is not protected.
//
// The monitor is the cell controller's speed override: a scale s in [0, 1] by which the arm's
// trajectory time advances (the path is kept; s = 0 holds the arm still on it). Each control
// period it compares the arm's speed with what the last sensed separation allows, less a margin
// for what can change before the next reading and while braking:
//   v_allowed(S) = (S - v_h (T_r + T_s) - C - Z_d - Z_r - margin) / (T_r + k_s);
// above it s falls at the braking rate (1 / ramp_down seconds from full speed to still), below
// 80 % of it s rises at 1 / ramp_up. At v_allowed(S) <= 0 the arm stops (a protective stop) and
// resumes only once S is `resume_gap` beyond that. Pure logic, no simulator: sim/simulation.cpp
// feeds it the separation and the speed.
//
// Collaborative mode (power and force limiting, ISO/TS 15066 5.5.5), for a hand-over: asked for
// by the plan (the safety component's Collaborate), it replaces the separation rule by a speed
// cap (`CollaborativeParams::max_speed` for the arm's fastest point, at any separation) and
// watches contact with the person: contact with any part of the person but the hand, or a hand
// contact force above the hand's limit (ISO/TS 15066 Table A.2, hand and fingers: 140 N
// quasi-static), stops the arm (a protective stop) until collaborative mode is left; the
// separation rule then decides when it resumes. Every stop has a reason (stopReason()).

#include <optional>
#include <string>

#include <Eigen/Core>

namespace costar::sim {

struct SpeedSeparationParams {
  double human_speed = 1.6;                   // v_h, m/s (ISO 13855)
  double sensor_period = 0.030;               // the separation is sensed this often, s
  double control_period = 0.002;              // the controller's period (the physics step), s
  double stopping_time = 0.25;                // T_s, s: measured (bench/ssm_bench), rounded up
  double stopping_distance_per_speed = 0.13;  // k_s, s: S_s = k_s v_r, measured, rounded up
  double intrusion = 0.02;                    // C, m
  double sensor_uncertainty = 0.02;           // Z_d, m
  double robot_uncertainty = 0.01;            // Z_r, m
  double margin = 0.20;                       // the controller's buffer beyond S_p, m (tuned: docs/PERSON.md)
  double ramp_down = 0.20;                    // s from full speed to still while braking
  double ramp_up = 0.60;                      // s from still to full speed when resuming
  double resume_gap = 0.10;                   // m beyond the stop distance before the arm resumes

  double reactionTime() const { return sensor_period + control_period; }
};

/// Power and force limiting near the hand (collaborative mode).
struct CollaborativeParams {
  double max_speed = 0.20;          // m/s, the arm's fastest point: below the 0.25 m/s of "moving fast"
  double hand_force_limit = 140.0;  // N, ISO/TS 15066 Table A.2, hand and fingers, quasi-static
};

/// A capsule: the points within `radius` of the segment a-b (a sphere when a = b). The
/// separation is measured between capsules that enclose every arm, gripper and person geom
/// (sim/person_sim.h), so it never exceeds the true distance.
struct Capsule {
  Eigen::Vector3d a = Eigen::Vector3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  double radius = 0.0;
};

/// The distance between the two capsules' surfaces (negative where they overlap).
double capsuleDistance(const Capsule& first, const Capsule& second);

/// S_p for an arm moving at `robot_speed` (m/s).
double protectiveDistance(const SpeedSeparationParams& params, double robot_speed);

class SpeedSeparationMonitor {
 public:
  enum class State { kFree, kLimited, kStopped };

  explicit SpeedSeparationMonitor(SpeedSeparationParams params = {}, CollaborativeParams collaborative = {});

  /// One control period of `dt` seconds: the separation as last sensed (absent: nobody
  /// sensed, full speed allowed) and the arm's fastest point speed now. Returns the scale for
  /// the next period.
  double update(double dt, std::optional<double> sensed_separation, double arm_speed);

  /// Collaborative mode on or off (power and force limiting; see the file's comment). Leaving it
  /// clears a contact stop; the separation rule applies again from the next update.
  void setCollaborative(bool on);
  bool collaborative() const { return collaborative_; }
  /// The contact with the person in the last physics step: the largest total normal force (N;
  /// 0: none) and whether every contact was with the hand. Outside collaborative mode it changes
  /// nothing (the separation rule keeps the arm away; contact is recorded, not acted on).
  void setContact(double force, bool hand_only);

  /// Why the arm is held ("" while it is not): "separation", "stop input", "contact outside
  /// the hand", "hand force above 140 N".
  const std::string& stopReason() const { return stop_reason_; }

  /// A stop input (a safety-rated stop: an emergency stop button, a light curtain, or the
  /// bench measuring the arm's stopping): while set, the arm brakes to rest and stays there.
  void setStopInput(bool stop) { stop_input_ = stop; }

  double scale() const { return scale_; }
  /// The scale's rate of change in the last period, 1/s.
  double scaleRate() const { return rate_; }
  State state() const { return state_; }
  /// What the last update allowed, m/s (infinite with nobody sensed).
  double allowedSpeed() const { return allowed_; }
  /// How many protective stops (the arm brought to rest for the person) so far.
  int stops() const { return stops_; }
  const SpeedSeparationParams& params() const { return params_; }
  const CollaborativeParams& collaborativeParams() const { return collaborative_params_; }

 private:
  SpeedSeparationParams params_;
  CollaborativeParams collaborative_params_;
  bool collaborative_ = false;
  std::string contact_stop_;  // the contact that stopped the arm in collaborative mode
  std::string stop_reason_;
  double scale_ = 1.0;
  double rate_ = 0.0;
  double allowed_ = 0.0;
  State state_ = State::kFree;
  int stops_ = 0;
  bool stop_input_ = false;
};

std::string stateName(SpeedSeparationMonitor::State state);

}  // namespace costar::sim
