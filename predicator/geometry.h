#pragma once
// The geometric predicates and their one convention (docs/PREDICATES.md has a picture).
//
// Directions are read in the axes of a viewpoint frame, table_center by default: x points away
// from the robot, y to the robot's left, z up. Offsets are from the reference symbol's
// position to the subject's:
//   left_of(a, r)      a is more than lateral_margin toward +y of r   (the robot's left)
//   right_of(a, r)     ... toward -y                                   (the robot's right)
//   in_front_of(a, r)  ... toward +x   (farther from the robot than r)
//   behind(a, r)       ... toward -x   (nearer the robot than r)
//   above(a, r)        a is more than vertical_margin higher than r
//   below(a, r)        ... lower
//   near(a, b)         less than near_distance between them (between their boxes; between
//                      positions for frames without extent)
//   on(a, b)           a rests on b: a's lowest point within on_gap of b's highest, and a's
//                      centre over b's footprint
// Every margin is a dead band: nearly equal positions are neither left nor right, neither
// above nor below (the original fired `above` on equal heights).

#include <Eigen/Geometry>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "world/pose.h"

namespace costar::predicator {

struct GeometryOptions {
  double lateral_margin = 0.02;   // m
  double vertical_margin = 0.02;  // m
  double near_distance = 0.05;    // m
  double on_gap = 0.01;           // m
};

enum class Relation { kLeftOf, kRightOf, kInFrontOf, kBehind, kAbove, kBelow, kNear, kOn };

/// "left_of", "right_of", "in_front_of", "behind", "above", "below", "near", "on".
const char* toString(Relation relation);
std::optional<Relation> relationFromName(std::string_view name);
const std::vector<Relation>& allRelations();
/// near and on compare two objects' extents; the others compare positions.
bool isContactRelation(Relation relation);

/// A symbol as the predicates see it: a position, and for objects their extent in the world.
struct Placed {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  /// World-aligned box around the object; empty for a frame without extent.
  Eigen::AlignedBox3d extent;
};

/// The world-aligned box around a box `local` (object frame) placed at `pose`.
Eigen::AlignedBox3d worldBox(const Eigen::AlignedBox3d& local, const world::Pose& pose);

/// Whether `relation(subject, reference)` holds, reading directions in `axes` (a rotation:
/// the viewpoint frame's orientation in the world).
bool relationHolds(Relation relation, const Placed& subject, const Placed& reference, const Eigen::Matrix3d& axes,
                   const GeometryOptions& options);

}  // namespace costar::predicator
