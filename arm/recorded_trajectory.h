#pragma once
// A path the tool was guided along (free-drive, arm/free_drive.h), recorded and kept beside the
// waypoints (arm/waypoints.h: the same file, lock and merging): the tool centre point's poses,
// timed from the start, relative to a frame ("world", or a frame symbol such as a detected part,
// so that a stroke demonstrated on one workpiece is replayed on another wherever it lies).
// Recorded at every tick (100 Hz) and simplified: the Ramer-Douglas-Peucker algorithm on
// position and orientation together, against the pose interpolated in time (lerp and slerp
// between the samples kept), so that the samples kept also keep the speed along the path.

#include <string>
#include <vector>

#include "world/pose.h"

namespace costar::arm {

struct RecordedTrajectory {
  std::string name;
  std::string frame = "world";
  std::vector<double> times;       // s from the first sample, increasing
  std::vector<world::Pose> poses;  // the tool centre point in `frame`, one a time

  double duration() const { return times.empty() ? 0.0 : times.back() - times.front(); }
  /// The pose at `t` s (lerp and slerp between the samples; clamped to the ends).
  world::Pose at(double t) const;
  /// The path's length (m of the tool centre point).
  double length() const;
};

/// The tolerances of the simplification: a sample dropped is within both of the trajectory kept.
struct SimplifyTolerance {
  double position = 0.0005;                        // m
  double angle = 0.25 * 3.14159265358979 / 180.0;  // rad
};

/// `recorded` with the samples dropped that the ones kept interpolate within `tolerance` (its
/// first and last kept). @throws std::invalid_argument for times and poses of different counts,
/// or times that do not increase.
RecordedTrajectory simplify(const RecordedTrajectory& recorded, const SimplifyTolerance& tolerance = {});

/// Checks a recorded trajectory's fields: a valid name (as a waypoint's), a frame, two samples at
/// least, increasing finite times, finite poses within 10 m. Empty when valid, else the problem
/// ("times[3]: must be later than times[2] (1.25 s)").
std::string checkRecordedTrajectory(const RecordedTrajectory& trajectory);

}  // namespace costar::arm
