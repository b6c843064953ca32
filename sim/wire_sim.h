#pragma once
// The bending jig and its wire in MuJoCo (sim/wire.h says what they are): their MJCF, and the
// simulation's side of them, which Simulation calls after every physics step: the wire's and
// the pins' plasticity, and watching how the gripper holds the wire.
//
// Plasticity moves spring rest positions (mjModel's qpos_spring): MuJoCo 2.2.2 keeps them in
// the model only. Each Simulation loads its own model and a SimJig writes only its own jig's
// joints, so nothing outside the simulation that owns the model sees it change.
//
// No MuJoCo type appears here: the model and data are passed as MuJoCo's opaque structs.

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "sim/wire.h"

struct mjModel_;
struct mjData_;

namespace costar::sim {

/// The jig (its clamp, the template sheet with the drawing, the pins) and the wire, as bodies
/// for the world body of a model stepped every `timestep` seconds (the joints' armature and
/// damping keep them stable at that step); names: body "jig", pins "pin_NAME", wire segments
/// "wire_I". `material` may be null only without a wire.
std::string jigMjcf(const JigSpec& jig, const std::optional<WireSpec>& wire, const WireMaterial* material,
                    const JigDraw& draw, double timestep);

class SimJig {
 public:
  /// What the jig needs of the gripper to watch it hold the wire.
  struct Gripper {
    /// The finger a geom belongs to (0, 1, ...), -1 for any other geom.
    std::function<int(int geom)> finger_of_geom;
    /// How far the fingers were last told to close, 0 (open) to 1 (closed).
    std::function<double()> commanded_closure;
    int tcp_site = -1;
  };

  /// Finds the jig's bodies and joints in the compiled model (of jigMjcf's text).
  /// @throws std::runtime_error naming what the model lacks.
  SimJig(mjModel_* model, mjData_* data, JigSpec jig, std::optional<WireSpec> wire, JigDraw draw, Gripper gripper);

  /// After each physics step at simulated time `time_s`: plasticity, the pins, the grip.
  void afterStep(double time_s);
  JigState state() const;
  /// "wire", "pin_NAME", "jig" for the jig's geoms; empty for any other.
  std::string geomLabel(int geom) const;

 private:
  struct Pin {
    int body = -1;
    int qpos_x = 0;
    int qpos_y = 0;
    double max_force = 0.0;
  };
  void plasticity();
  void watchPins();
  void watchGrip(double time_s);
  Eigen::Vector3d wirePoint(int segment, double along) const;

  mjModel_* model_;
  mjData_* data_;
  JigSpec jig_;
  std::optional<WireSpec> wire_;
  JigDraw draw_;
  Gripper gripper_;
  WireJoints joints_;
  std::vector<int> wire_bodies_;  // segments 1..N
  std::vector<int> wire_qpos_;    // the wire's hinges
  std::vector<Pin> pins_;
  std::vector<int> geom_kind_;  // per geom: -1 not the jig's, 0 the wire, 1 + i pin i, -2 the jig
  // The grip.
  WireGrip grip_;
  int touching_steps_ = 0;  // consecutive steps with two fingers on the wire
  int apart_steps_ = 0;     // consecutive steps without, while held
  double closure_at_hold_ = 0.0;
  int grasp_segment_ = 0;  // the material point under the TCP when the hold began
  double grasp_along_ = 0.0;
  Eigen::Vector3d grasp_in_tcp_ = Eigen::Vector3d::Zero();
};

}  // namespace costar::sim
