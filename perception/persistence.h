#pragma once
// Stage 6 of the pipeline: persistenceUpdate (the paper's Algorithm 1). The objects of the
// previous detection sit in a Boost.Geometry R*-tree, bulk-loaded with the packing algorithm
// (STR). Each new detection takes the name of the nearest previous object of the same class
// within d_max, which then leaves the tree (one match per object); a detection without one
// gets a fresh name, <class>_<n>, n counting up per class and never reused. Matches are made
// closest pair first, so the result does not depend on the order of the detections.
// Previous objects that find no detection are dropped, or kept (unchanged) for up to
// `keep_for` detections. Every detection is set to its canonical orientation, with the
// world frame as the reference for a new object and the previous pose for a matched one.

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "perception/pose_estimation.h"
#include "world/object_class.h"
#include "world/pose.h"

namespace costar::perception {

struct PersistenceOptions {
  /// d_max: a detection keeps a previous object's name only within this distance (m).
  double max_distance = 0.03;
  /// An object not seen is kept for this many detections before it is dropped (0: dropped
  /// at once, as in the paper).
  int keep_for = 0;
  /// Apply setCanonicalOrientation to every detection.
  bool canonical_orientation = true;
  /// Reference orientation of new objects (world frame).
  Eigen::Matrix3d new_object_reference = Eigen::Matrix3d::Identity();
};

struct TrackedObject {
  /// Unique name, e.g. "node_3".
  std::string name;
  std::string object_class;
  /// Object frame in the world, in canonical orientation.
  world::Pose pose = world::Pose::Identity();
  double confidence = 0.0;
  /// Mean colour seen on it (RGB in [0, 1]; the latest detection's, else the one before).
  std::optional<Eigen::Vector3f> color;
  /// Detections since it was last seen (0: seen in the latest).
  int missed = 0;
  /// Number of detections it has been seen in.
  int seen = 0;
};

class PersistenceFilter {
 public:
  /// `classes` gives each class's symmetries and axis priority (for canonical orientation);
  /// a detection of a class not in it is kept as it is.
  explicit PersistenceFilter(std::vector<world::ObjectClass> classes, PersistenceOptions options = {});
  ~PersistenceFilter();
  PersistenceFilter(PersistenceFilter&&) noexcept;
  PersistenceFilter& operator=(PersistenceFilter&&) noexcept;

  /// Algorithm 1 on `detections` (their `pose`, world frame, and class). Returns the objects
  /// now known: the detections in their order, then any kept unseen objects.
  const std::vector<TrackedObject>& update(const std::vector<Detection>& detections);

  const std::vector<TrackedObject>& objects() const { return objects_; }
  const PersistenceOptions& options() const { return options_; }
  /// Forgets every object (names keep counting up).
  void clear();

 private:
  struct Index;
  std::vector<world::ObjectClass> classes_;
  PersistenceOptions options_;
  std::vector<TrackedObject> objects_;
  std::unique_ptr<Index> index_;
  std::vector<std::pair<std::string, int>> counters_;  // per class, the last number given
};

}  // namespace costar::perception
