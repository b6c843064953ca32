#pragma once
// A person beside the cell, from data: a scene file's "person" entry says where the person's
// shoulder is and what the hand does, step by step (sim/scenes/handover.json):
//   "person": {"shoulder": [0.55, 0.8, 0.4], "seed": 7, "repeat": false,
//              "script": [{"do": "reach", "to": [0.45, 0.35, 0.12], "speed": 0.8},
//                         {"do": "gesture", "seconds": 1.5},
//                         {"do": "wait", "seconds": 2},
//                         {"do": "close", "seconds": 0.6},
//                         {"do": "withdraw", "speed": 0.6},
//                         {"do": "reach_random", "min": [0.3, -0.2, 0.05], "max": [0.7, 0.4, 0.3], "speed": 1.6},
//                         {"do": "open", "seconds": 0.4}]}
// Steps ("do"):
// - "reach": the wrist moves on a straight line to "to" (x, y, z in m, world frame; table top
//   z = 0) with a minimum-jerk profile whose peak speed is "speed" (m/s, at most 1.6: ISO 13855's
//   walking speed, the speed-and-separation monitor's assumption), fingers as they are; an open
//   hand turns palm down on the way, a closed one keeps its palm as it was (what it holds stays in it).
// - "reach_random": the same to a point drawn uniformly in the box "min".."max" (seeded by "seed",
//   default: the scene's seed), at a speed drawn from half of "speed" to "speed": the unexpected
//   reach. A point beyond the arm's reach is pulled toward the shoulder until it is within it.
// - "gesture": the offer gesture: the hand turns palm up in 0.4 s and holds still, open, for
//   "seconds".
// - "take": the hand offers (as "gesture") and waits, open and palm up, for a part to be put on
//   it, at most "seconds": once a part lies on the palm (released onto it) the step ends and the
//   script goes on (a "close" next holds it). The only step that reacts to the cell: a person
//   taking a part closes the hand when it is in it, whenever the robot brings it.
// - "wait": the hand holds still for "seconds".
// - "close" / "open": the fingers close (or open) over "seconds"; closing around a part holds it
//   (force-limited finger joints, contact and friction only: whoever else holds it must let go).
// - "withdraw": a reach back to where the hand started ("rest", default: beside the body, 0.1 m
//   toward the table's middle from the shoulder and 0.35 m lower, at least 5 cm above the table
//   top's height).
// - "leave" / "enter": the whole person walks 1.5 m straight away from the table (along y, on
//   the shoulder's side) or back, the hand at rest, at "speed" (m/s, default 1, at most 1.6);
//   "start": "away" has the person away at first. Away, only "enter", "wait", "open" and
//   "close" may follow (away, an "open" puts down what the hand carried off).
// "scripts": [[steps], [steps], ...] in place of "script": one of them, drawn from the seed (a
// mix of behaviours for trials: with a gesture, without one, reaching at random).
// "repeat": true starts the script again when it ends (drawing new random reaches), for long
// randomized runs. Every target must lie within the arm's reach (0.56 m from the shoulder) and at
// least 3 cm above the table top's height (also beside the table: the simulator's table top is an
// endless plane). A field or step the format does not know, a value of the wrong
// type or out of range is an error naming the field, e.g.
//   scene 'x.json': person.script[1].speed: must be from 0.05 to 1.6 m/s, not 2.5
//
// The person is driven kinematically (the simulator's mocap bodies for the hand, forearm and
// upper arm, the torso with the head); only the fingers are dynamic (sim/person_sim.h).
// PersonMotion is the script as a function of time: pure, no MuJoCo.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace costar::sim {

struct PersonStep {
  enum class Kind { kReach, kReachRandom, kGesture, kTake, kWait, kClose, kOpen, kWithdraw, kLeave, kEnter };
  Kind kind = Kind::kWait;
  Eigen::Vector3d to = Eigen::Vector3d::Zero();       // kReach
  Eigen::Vector3d box_min = Eigen::Vector3d::Zero();  // kReachRandom
  Eigen::Vector3d box_max = Eigen::Vector3d::Zero();
  double speed = 0.8;    // m/s: reaches' peak speed
  double seconds = 1.0;  // gesture, take (at most), wait, close, open
};

struct PersonSpec {
  Eigen::Vector3d shoulder = Eigen::Vector3d(0.55, 0.8, 0.4);
  /// Where the wrist starts and withdraws to; absent: 0.1 m from the shoulder toward the
  /// table's middle (y = 0) and 0.35 m lower (at least 5 cm above the table top's height).
  std::optional<Eigen::Vector3d> rest;
  std::optional<std::uint64_t> seed;
  bool repeat = false;
  /// The person starts away from the table ("start": "away"; an "enter" brings them).
  bool starts_away = false;
  /// The script, or the scripts one of which is drawn from the seed ("scripts").
  std::vector<std::vector<PersonStep>> scripts;
  /// The entry as the file wrote it (sceneFileText writes it back).
  std::string source;

  Eigen::Vector3d restPosition() const;
  /// How far the whole person is when away: kLeaveDistance straight away from the table
  /// (along y, on the shoulder's side).
  Eigen::Vector3d awayOffset() const;
};

/// The person's body sizes (m).
inline constexpr double kUpperArmLength = 0.30;
inline constexpr double kForearmLength = 0.27;  // wrist to elbow
inline constexpr double kPersonReach = 0.56;    // shoulder to wrist, arm nearly straight
inline constexpr double kPersonMaxSpeed = 1.6;  // m/s, ISO 13855's
inline constexpr double kLeaveDistance = 1.5;   // m, how far "leave" walks away

/// Reads a "person" entry (JSON text). @throws std::runtime_error "FIELD: PROBLEM" with FIELD
/// under `field` ("person.script[2].to").
PersonSpec parsePerson(const std::string& json_text, const std::string& field);

/// Where the person is at one instant.
struct PersonPose {
  Eigen::Vector3d wrist = Eigen::Vector3d::Zero();
  /// The hand's frame at the wrist: x along the fingers, z out of the back of the hand (palm
  /// down: z up).
  Eigen::Quaterniond hand = Eigen::Quaterniond::Identity();
  Eigen::Vector3d elbow = Eigen::Vector3d::Zero();
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();  // the wrist's, m/s
  /// Where the shoulder is now, and how far the whole person has walked from where the scene
  /// puts them (zero at the table).
  Eigen::Vector3d shoulder = Eigen::Vector3d::Zero();
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();
  double closure = 0.0;  // fingers: 0 open, 1 closed
  bool palm_up = false;
  /// The labels a perception test judges against: the step being done ("reach", "gesture" ...)
  /// and whether the hand is making the offer gesture (palm up, open, still).
  std::string step;
  bool offering = false;
};

/// The elbow of an arm from `shoulder` to `wrist` (upper arm and forearm lengths above),
/// hanging down in the vertical plane through both.
Eigen::Vector3d elbowPosition(const Eigen::Vector3d& shoulder, const Eigen::Vector3d& wrist);

/// The script as a function of time, its random reaches drawn once from `seed`.
class PersonMotion {
 public:
  /// A repeating script is laid out up to `horizon` seconds.
  PersonMotion(const PersonSpec& spec, std::uint64_t seed, double horizon = 3600.0);
  /// The pose at `t` seconds (before 0: at rest; after the end: as the last step left it).
  PersonPose at(double t) const;
  /// When the (first pass of the) script ends.
  double duration() const { return duration_; }
  /// Which of the spec's scripts was drawn.
  std::size_t scriptIndex() const { return script_index_; }
  /// The step being done at `t` and when it ends (the last step's end after the script).
  struct StepAt {
    PersonStep::Kind kind = PersonStep::Kind::kWait;
    double end = 0.0;
    /// The palm has finished turning: a take's hand is ready for the part.
    bool settled = false;
  };
  StepAt stepAt(double t) const;

 private:
  struct Segment {
    double start = 0.0;
    double end = 0.0;
    Eigen::Vector3d from = Eigen::Vector3d::Zero();
    Eigen::Vector3d to = Eigen::Vector3d::Zero();
    bool palm_up_from = false;
    bool palm_up_to = false;
    double turn_seconds = 0.0;  // how long the palm takes to turn, from the start
    double closure_from = 0.0;
    double closure_to = 0.0;
    Eigen::Vector3d offset_from = Eigen::Vector3d::Zero();
    Eigen::Vector3d offset_to = Eigen::Vector3d::Zero();
    PersonStep::Kind kind = PersonStep::Kind::kWait;
  };
  Eigen::Vector3d shoulder_;
  std::vector<Segment> segments_;
  double duration_ = 0.0;
  std::size_t script_index_ = 0;
};

}  // namespace costar::sim
