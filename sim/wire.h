#pragma once
// A bending jig and a wire that stays bent: what a scene's "jig" and "wire" entries describe,
// the numbers a trial draws for them, and their true state for tests and the trial judge.
// No MuJoCo type appears here (the simulated jig is sim/wire_sim.h).
//
// Scene JSON (sim/scenes/wire_bending.json):
//   "jig": {"at": [0.42, -0.12, 0],                 x, y (m) of the clamp's mouth, yaw (deg) of the wire leaving it
//           "placement_error": {"xy": 0.001, "yaw_deg": 0.3},  a cell's error, drawn per seed within +-
//           "height": 0.03,                          the wire's axis above the table (m)
//           "clamp_tolerance": 0.002,                how far the wire's start may sit along its axis (+- m)
//           "pins": [{"name": "A", "at": [0.06, 0.0135], "radius": 0.01, "height": 0.06,
//                     "hold_force": 150, "stiffness": 200000}, ...],   in the jig's frame (m, N, N/m)
//           "target": [{"at": 0.0735, "angle_deg": 90}, ...]},  the drawing: bends at arc lengths from the
//                                                              clamp's mouth (m), + to the left (counter-clockwise)
//   "wire": {"material": "steel_annealed", "diameter": 0.0025, "length": 0.25, "segments": 20}
// The jig's frame: origin at the clamp's mouth on the table top, x along the wire as it leaves
// the clamp, z up. Materials are data (data/wire_materials.json): their values are ranges a
// batch of wire varies within, drawn per seed.
//
// The wire is a chain of capsules clamped at its start, joined by two hinges each (a bend in
// the table's plane and one out of it) with rotational springs of the wire's bending stiffness
// E*I/segment. It is elastic-perfectly plastic: when a joint's bend from its spring's rest angle
// passes the yield angle (the plastic moment sigma_y*d^3/6 over the spring's stiffness), the
// rest angle follows the bend, so that a bend beyond yield stays, less the yield angle sprung
// back; a bend below it springs back entirely. A pin is press-fitted in the jig: it gives
// elastically (its stiffness) and slips for good when pushed harder than its hold force.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "world/pose.h"

namespace costar::sim {

/// A value drawn per placement seed, uniformly from low to high (equal: fixed).
struct ValueRange {
  double low = 0.0;
  double high = 0.0;
};

/// A wire material, as its maker's sheet gives it (data/wire_materials.json).
struct WireMaterial {
  std::string name;
  std::string description;
  ValueRange youngs_modulus_gpa;
  ValueRange yield_strength_mpa;
  double density = 7850.0;  // kg/m^3
  double friction = 0.3;    // sliding, against the jig's pins
};

/// The materials of `file` (default: data/wire_materials.json under the data root).
/// @throws std::runtime_error naming the file, the field and the problem.
std::vector<WireMaterial> loadWireMaterials(const std::filesystem::path& file = {});

/// "wire": a round wire of `diameter`, `length` of it out of the jig's clamp.
struct WireSpec {
  std::string material;
  double diameter = 0.0025;  // m
  double length = 0.25;      // m, out of the clamp (nominal)
  int segments = 20;
};

/// A pin pressed into the jig, standing on the table.
struct PinSpec {
  std::string name;
  Eigen::Vector2d at = Eigen::Vector2d::Zero();  // in the jig's frame, m
  double radius = 0.01;                          // m
  double height = 0.06;                          // m
  double hold_force = 150.0;                     // N: pushed harder, it slips for good
  double stiffness = 2e5;                        // N/m: how much it gives before that
};

/// One bend of the jig's drawing.
struct BendTarget {
  double at = 0.0;         // arc length from the clamp's mouth to the bend's corner, m
  double angle_deg = 0.0;  // + to the left (counter-clockwise seen from above)
};

/// "jig": where it stands, the clamp, the pins and the shape the wire should take.
struct JigSpec {
  Eigen::Vector3d at = Eigen::Vector3d::Zero();  // x, y (m), yaw (degrees)
  double xy_error = 0.0;                         // m, +- in x and in y
  double yaw_error_deg = 0.0;                    // +-
  double height = 0.03;                          // the wire's axis above the table, m
  double clamp_tolerance = 0.0;                  // m, +-
  std::vector<PinSpec> pins;
  std::vector<BendTarget> target;
};

/// What one trial's cell has: the jig where it was put and the wire's numbers, drawn from the
/// seed within the scene's tolerances and the material's ranges.
struct JigDraw {
  world::Pose pose = world::Pose::Identity();  // the jig's frame in the world, error included
  double wire_length = 0.0;                    // m out of the clamp
  double youngs_modulus_gpa = 0.0;
  double yield_strength_mpa = 0.0;
};

/// Draws a trial's jig (a stream of its own: the part placements do not change).
JigDraw drawJig(const JigSpec& jig, const std::optional<WireSpec>& wire, const WireMaterial* material,
                std::uint64_t seed);

/// The wire's joint model: bending stiffness per joint (N m/rad), the yield angle (rad), the
/// segment length (m).
struct WireJoints {
  double segment = 0.0;
  double stiffness = 0.0;
  double yield_angle = 0.0;
};
WireJoints wireJoints(const WireSpec& wire, double length, double youngs_modulus_gpa, double yield_strength_mpa);

/// The drawing's polyline in the jig's frame: the clamp's mouth, each bend's corner, the end
/// (a wire of `length`).
std::vector<Eigen::Vector2d> targetPolyline(const std::vector<BendTarget>& target, double length);

/// A bend as measured on a wire: the turn between the straight stretches either side of it.
struct MeasuredBend {
  double target_deg = 0.0;
  double angle_deg = 0.0;         // in the table's plane, + to the left
  double out_of_plane_deg = 0.0;  // the change in pitch (0: the wire stays flat)
};

/// Measures the drawing's bends on a centreline (points from the clamp's mouth to the end,
/// equally spaced along the wire). The stretches are cut at the target's arc lengths; each is
/// measured by the chord over its middle half, as one lays a protractor along the straight
/// parts, so that where exactly a bend rounds a pin does not matter.
std::vector<MeasuredBend> measureBends(const std::vector<Eigen::Vector3d>& centreline,
                                       const std::vector<BendTarget>& target);

// --- the true state (tests and the trial judge) ------------------------------------------------

struct PinState {
  std::string name;
  Eigen::Vector2d nominal = Eigen::Vector2d::Zero();  // where it was pressed in (world x, y)
  Eigen::Vector2d position = Eigen::Vector2d::Zero();
  double slipped = 0.0;    // how far it has moved for good, m (0: it held)
  double max_force = 0.0;  // the most it was pushed with, N
};

/// How the gripper held the wire, watched at every physics step.
struct WireGrip {
  bool held = false;            // now: the wire touches two of the gripper's fingers
  int holds = 0;                // times the gripper took hold of it
  int releases = 0;             // times it let go after the gripper was told to open
  int pulled_out = 0;           // times it came out of fingers still told to close
  double pulled_out_at = -1.0;  // simulated s of the first time, -1: never
  double max_slip = 0.0;        // how far the wire slid in the fingers while held, m
};

struct JigState {
  JigSpec spec;
  JigDraw draw;
  std::vector<PinState> pins;
  bool has_wire = false;
  WireJoints joints;
  std::vector<Eigen::Vector3d> wire;  // the centreline, the clamp's mouth first
  double wire_speed = 0.0;            // the fastest point of the wire, m/s
  WireGrip grip;
  std::vector<MeasuredBend> bends;
};

}  // namespace costar::sim
