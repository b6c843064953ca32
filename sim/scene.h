#pragma once
// Scene files: which parts lie on the table and where, fixed or at random in named regions
// (any yaw), with a seed. Example (sim/scenes/assembly.json):
//   {"description": "...", "seed": 1,
//    "regions": {"right": {"x": [0.35, 0.7], "y": [-0.4, -0.1]}},
//    "parts": [{"class": "node", "color": "red", "at": [0.5, -0.2, 30]},
//              {"class": "node", "count": 2, "region": "right"},
//              {"class": "link", "region": "right"}]}
// "at" is x, y (m, world frame: the robot's base, table top z = 0) and yaw (degrees); with
// "height" (m, 0 to 0.5) such a part starts that far above the table and falls onto what lies
// under it: {"class": "link", "at": [0.6, 0.05, 90], "height": 0.05} across a node at (0.6, 0.05).
// Two parts placed with "at" that overlap by more than 1 mm (and are not one above the other)
// are refused naming both: the physics would throw them apart at the first step.
// A bending jig and the wire it holds: "jig" and "wire" (sim/wire.h). Optional: "min_gap" (m,
// 0 to 0.5, default 0.02) between randomly placed parts. A workpiece to polish: "workpiece":
// {"at": [x, y, yaw_deg], "size": [sx, sy, sz], "marked": [mx, my]} (a block fixed on the table,
// its top's middle mx by my marked for polishing; sizes in m), which random placements keep
// clear of; "power_tool": true puts the cell's power tool on its stand (workcells/NAME.json
// "power_tool", sim/power_tool.h). A person beside the table, driven by a script: "person"
// (sim/person.h). Custom
// regions add to (or replace) the default ones. A field the format does not know, a value of
// the wrong type or out of range (a count of 4294967297, a negative min_gap, a region or an
// "at" off the table) is an error naming the file and the field, e.g.
//   scene 'my.json': parts[1].count: must be a whole number from 1 to 100, not 0

#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "sim/person.h"
#include "sim/wire.h"
#include "world/object_class.h"
#include "world/pose.h"

namespace costar::sim {

struct Region {
  Eigen::Vector2d min = Eigen::Vector2d::Zero();
  Eigen::Vector2d max = Eigen::Vector2d::Zero();
};

struct PartRequest {
  std::string object_class;
  /// Colour name of the class; empty: the class's colours in turn.
  std::string color;
  int count = 1;
  /// Fixed placement: x, y (m) and yaw (degrees).
  std::optional<Eigen::Vector3d> at;
  /// With `at`: how high above the table its underside starts (m; 0: on the table). A part put
  /// over another falls onto it when the simulation starts (a link across a node, a stack).
  double height = 0.0;
  /// Random placement in this region (any yaw), when `at` is absent.
  std::string region;
};

/// Where the RGB-D camera really is relative to its drawn mounting (the set-up a technician
/// finds after the camera was bumped or the cell moved). Either fixed ("xyz", m, world axes;
/// "rpy_deg", degrees) or random ("distance" m in a uniformly random direction and "angle_deg"
/// about a uniformly random axis, drawn from "seed", default: the placement seed).
/// Scene JSON: "camera_offset": {"xyz": [0.03, 0, -0.04], "rpy_deg": [0, 3, 4]} or
///             "camera_offset": {"distance": 0.05, "angle_deg": 5, "seed": 7}.
struct CameraOffset {
  Eigen::Vector3d xyz = Eigen::Vector3d::Zero();
  Eigen::Vector3d rpy_deg = Eigen::Vector3d::Zero();
  bool random = false;
  double distance = 0.0;
  double angle_deg = 0.0;
  std::optional<std::uint64_t> seed;
};

/// The offset as a pose (translation in world axes; rotation about the camera's centre in
/// world axes): Simulation's camera_offset. Random offsets draw from `seed` unless the offset
/// names its own.
world::Pose cameraOffsetPose(const CameraOffset& offset, std::uint64_t seed);

/// A block fixed on the table whose top is polished (sim/power_tool.h records its marked area).
struct WorkpieceRequest {
  Eigen::Vector3d at = Eigen::Vector3d::Zero();  // x, y (m) of its centre and yaw (degrees)
  Eigen::Vector3d size = Eigen::Vector3d::Zero();
  Eigen::Vector2d marked = Eigen::Vector2d::Zero();  // the marked rectangle in the middle of its top
};

struct Scene {
  std::string label;  // the file it came from
  std::string description;
  std::uint64_t seed = 0;
  std::map<std::string, Region> regions;
  std::vector<PartRequest> parts;
  /// Smallest gap between the footprints of randomly placed parts (m).
  double min_gap = 0.02;
  /// The camera away from its drawn mounting (absent: as drawn).
  std::optional<CameraOffset> camera_offset;
  /// A bending jig on the table, and the wire clamped in it (sim/wire.h).
  std::optional<JigSpec> jig;
  std::optional<WireSpec> wire;
  std::optional<WorkpieceRequest> workpiece;
  /// The cell's power tool sits on its stand.
  bool power_tool = false;
  /// A person beside the table and what the hand does (sim/person.h).
  std::optional<PersonSpec> person;
};

/// The table top (x, y in m), as sim/models/table_cell.xml has it; regions and fixed
/// placements must lie on it.
Region tableTop();

/// The regions every scene knows: "table" (the reachable part of the table), "right" and
/// "left" halves (y < 0 and y > 0, the robot's right and left).
std::map<std::string, Region> defaultRegions();

/// Reads a scene file. @throws std::runtime_error naming the file, the field and the problem.
Scene loadScene(const std::filesystem::path& file);
Scene parseScene(const std::string& json_text, const std::string& label);

/// The scene as a scene file's text (parseScene reads it back to the same scene): description,
/// seed, min_gap, custom regions, camera_offset, every part, fixed ("at") or in a region, the
/// jig and the wire.
std::string sceneFileText(const Scene& scene);

/// A part as placed: its simulator name (node_0, link_1, ...), class, colour, and pose.
struct PartPlacement {
  std::string name;
  std::string object_class;
  std::string color;
  world::Pose pose;
};

/// Places every requested part resting on the table: fixed ones where asked, random ones
/// uniformly in their region with a uniform yaw, keeping `min_gap` between footprints (each
/// part's bounding rectangle turned by its yaw, so long parts can lie side by side).
/// Deterministic for a given `seed` (the scene's seed unless overridden).
/// @throws std::runtime_error for an unknown class, colour or region, when the parts do not
/// fit, or when two parts placed with "at" overlap (naming both).
std::vector<PartPlacement> placeParts(const Scene& scene, const std::vector<world::ObjectClass>& classes,
                                      std::optional<std::uint64_t> seed = std::nullopt);

/// A part's footprint on the table: the rectangle of its bounding box, turned by its yaw.
struct Footprint {
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  Eigen::Vector2d half_size = Eigen::Vector2d::Zero();  // along the part's own x and y
  double yaw = 0.0;

  /// The footprint of a part of `object` whose origin lies at (x, y), turned by `yaw` (rad).
  static Footprint of(const world::ObjectClass& object, double x, double y, double yaw);
  Eigen::Matrix2d axes() const;
};

/// True when the two rectangles, each grown by `gap` / 2 on every side, overlap (separating
/// axis test over the four edge normals). A negative gap lets them overlap by that much.
bool closerThan(const Footprint& a, const Footprint& b, double gap);

/// A cluttered scene of fixed placements (the perception evaluation's): `counts` parts per
/// class in random order, each uniformly in the "table" region with any yaw and `gap` or more
/// from every other part, or, with probability `touching`, against a side of a part already
/// placed (turned like it give or take 12 degrees, slid along that side, 1 mm apart before the
/// physics settles them). Draws from `random`; parts that find no place in 400 tries are left
/// out. @throws std::runtime_error for an unknown class.
struct ClutteredScene {
  Scene scene;  // every part placed with "at"
  int touching_parts = 0;
};
ClutteredScene clutteredScene(const std::vector<world::ObjectClass>& classes,
                              const std::vector<std::pair<std::string, int>>& counts, double touching,
                              std::mt19937_64& random, const std::string& label, double gap = 0.01);

}  // namespace costar::sim
