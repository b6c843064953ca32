#pragma once
// Named waypoints the user teaches: a joint configuration, or a pose of the tool centre point
// relative to a frame ("world", or any frame symbol such as "table_center" or a detected
// part). Stored in one JSON file per workcell, rewritten atomically on every change, so a
// crash never loses a saved waypoint. Several writers of one file (the editor's server and
// `costar teach`, in two processes) keep each other's changes: each change is applied to the
// file's contents of the moment under an advisory lock (FILE.lock, flock), and every reader
// picks up the file anew when another process changed it. The same file keeps the trajectories
// recorded while guiding the arm by hand (arm/recorded_trajectory.h), under "trajectories".

#include <filesystem>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "arm/joints.h"
#include "arm/recorded_trajectory.h"
#include "world/pose.h"

namespace costar::arm {

struct Waypoint {
  enum class Kind { kJoints, kPose };
  std::string name;
  Kind kind = Kind::kPose;
  JointVector joints{};                        // kJoints
  world::Pose pose = world::Pose::Identity();  // kPose: the TCP in `frame`
  std::string frame = "world";                 // kPose
};

/// Names are 1-64 characters of letters, digits, '_' and '-'; empty result when valid.
std::string checkWaypointName(const std::string& name);

class WaypointStore {
 public:
  /// Loads `file` if it exists (an empty store otherwise). Changes are saved to it when
  /// `persist`; an empty path or persist = false keeps changes in memory only (a snapshot of the
  /// file: later changes of the file are not read).
  /// `joint_count`: the number of joints of the arm, which every joint waypoint in the file must
  /// have; 0 accepts any count from 1 to kMaxJoints (a reader that knows no robot).
  /// @throws std::runtime_error naming the file when it cannot be read.
  explicit WaypointStore(std::filesystem::path file = {}, bool persist = true, int joint_count = 0);
  WaypointStore(const WaypointStore&) = delete;
  WaypointStore& operator=(const WaypointStore&) = delete;

  /// What the file holds now (a persisting store reads it again when another writer changed
  /// it; a file that became unreadable leaves the last good contents). Thread-safe.
  std::optional<Waypoint> find(const std::string& name) const;
  std::vector<Waypoint> all() const;
  /// Adds or replaces, then saves. @throws std::invalid_argument for a bad name,
  /// std::runtime_error when the file cannot be read or written (the old file is kept).
  void put(const Waypoint& waypoint);
  /// @return false when there is no such waypoint (in the file as it is now).
  bool remove(const std::string& name);
  /// @throws std::invalid_argument when `from` is unknown, `to` is taken or invalid.
  void rename(const std::string& from, const std::string& to);
  const std::filesystem::path& file() const { return file_; }

  // --- recorded trajectories (their names are checked as waypoints' are; a name of its own) --
  std::optional<RecordedTrajectory> findTrajectory(const std::string& name) const;
  std::vector<RecordedTrajectory> trajectories() const;
  /// Adds or replaces, then saves. @throws std::invalid_argument naming the field for a
  /// trajectory checkRecordedTrajectory refuses; std::runtime_error as put().
  void putTrajectory(const RecordedTrajectory& trajectory);
  /// @return false when there is no such trajectory.
  bool removeTrajectory(const std::string& name);

 private:
  struct Map {
    std::map<std::string, Waypoint> waypoints;
    std::map<std::string, RecordedTrajectory> trajectories;
  };
  /// What identifies one version of the file: another writer's rename changes the inode.
  struct Stamp {
    bool exists = false;
    unsigned long long device = 0, inode = 0, size = 0;
    long long modified_ns = 0;
    bool operator==(const Stamp&) const = default;
  };
  bool watched() const { return persist_ && !file_.empty(); }
  Stamp stamp() const;
  /// The file's waypoints (empty when it does not exist). @throws std::runtime_error.
  Map read() const;
  /// Reads the file again when its stamp changed (caller holds mutex_).
  void refresh() const;
  /// Under the file's lock: the file's current waypoints, `change` applied, saved; or, for a
  /// store that does not persist, `change` applied in memory.
  template <typename Change>
  auto update(Change&& change);
  void save(const Map& waypoints) const;

  std::filesystem::path file_;
  bool persist_ = true;
  int joint_count_ = 0;
  mutable std::mutex mutex_;
  mutable Map waypoints_;
  mutable Stamp stamp_;
};

}  // namespace costar::arm
