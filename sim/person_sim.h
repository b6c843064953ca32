#pragma once
// The scene's person in MuJoCo (sim/person.h): the bodies, driven every physics step, and the
// capsules that enclose every geom of the person and of the arm with its gripper, from which
// the separation between them is measured (sim/speed_separation.h).
//
// Bodies: the hand ("person_hand": the palm, a free body at the wrist welded to the mocap body
// "person_hand_target" that the script places), the fingers
// ("person_fingers", four capsules on one hinge at the palm's end) and the thumb
// ("person_thumb", a hinge at the palm's heel), each finger hinge driven by a force-limited
// position servo, so a closing hand holds a part by contact and friction only; the forearm and
// upper arm (mocap capsules from the wrist to the elbow to the shoulder) and the torso with the
// head (a mocap body too: "leave" and "enter" walk the whole person away and back). The hand's geoms touch parts, the
// table and the arm; the forearm, upper arm, torso and head touch the arm only. Skin-coloured, so the RGB-D camera sees
// them.
//
// No MuJoCo type appears here: the model and data are passed as MuJoCo's opaque structs.

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "sim/person.h"
#include "sim/speed_separation.h"

struct mjModel_;
struct mjData_;

namespace costar::sim {

/// The person's bodies (for the worldbody), the hand's weld to its target (an <equality>
/// section for the model's top level) and the finger servos (for <actuator>).
std::string personBodiesMjcf(const PersonSpec& spec);
std::string personEqualityMjcf();
std::string personActuatorsMjcf();

/// The conservative capsule around geom `geom` of a compiled model, as placed now: capsules as
/// they are, cylinders as the capsule of the same radius and length, boxes as the capsule
/// along their longest side through the rectangle of the other two, anything else as its
/// bounding sphere.
Capsule geomCapsule(const mjModel_* model, const mjData_* data, int geom);

/// How far the robot must be from the person before a "take" closes the hand on the part (m).
inline constexpr double kTakeClearance = 0.05;

class SimPerson {
 public:
  /// `parts`: the bodies of the parts a "take" waits for.
  /// @throws std::runtime_error when the model lacks the person's bodies.
  SimPerson(mjModel_* model, mjData_* data, const PersonSpec& spec, std::uint64_t seed, std::vector<int> parts = {});

  /// Places the person as the script has it at `seconds` and sets the fingers' servos; call
  /// before every physics step, with `seconds` never decreasing. A "take" step ends early once
  /// a part lies on the palm and the robot is `kTakeClearance` clear of the person
  /// (`arm_clearance`, m: the gripper has let go and withdrawn, so the closing fingers do not
  /// catch it): the rest of the script runs that much sooner.
  void drive(double seconds, double arm_clearance = std::numeric_limits<double>::infinity());
  /// The body of the part lying on the open palm now, or -1.
  int partOnPalm() const;
  const PersonPose& pose() const { return pose_; }
  /// The person's geoms, and whether a geom is one.
  const std::vector<int>& geoms() const { return geoms_; }
  bool isPersonGeom(int geom) const;
  /// Whether a geom is the hand's: the palm, the fingers or the thumb.
  bool isHandGeom(int geom) const;
  /// A label for contacts(): "person_hand", "person_fingers", "person_thumb", "person_forearm" ...
  std::string geomLabel(int geom) const;

 private:
  mjModel_* model_;
  mjData_* data_;
  PersonMotion motion_;
  PersonPose pose_;
  std::vector<int> parts_;
  /// How far the script is ahead of the clock: the time takes ended early saved.
  double ahead_ = 0.0;
  std::vector<int> geoms_;
  int hand_mocap_ = 0;
  int hand_body_ = 0;
  int forearm_mocap_ = 0;
  int upper_arm_mocap_ = 0;
  int torso_mocap_ = 0;
  int fingers_actuator_ = 0;
  int thumb_actuator_ = 0;
  Eigen::Vector3d shoulder_ = Eigen::Vector3d::Zero();
};

}  // namespace costar::sim
