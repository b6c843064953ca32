#pragma once
// Named waypoints the user teaches: a joint configuration, or a pose of the tool centre point
// relative to a frame ("world", or any frame symbol such as "table_center" or a detected
// part). Stored in one JSON file per workcell, rewritten atomically on every change, so a
// crash never loses a saved waypoint.

#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "arm/joints.h"
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
  /// `persist`; an empty path or persist = false keeps changes in memory only.
  /// `joint_count`: the number of joints of the arm, which every joint waypoint in the file must
  /// have; 0 accepts any count from 1 to kMaxJoints (a reader that knows no robot).
  /// @throws std::runtime_error naming the file when it cannot be read.
  explicit WaypointStore(std::filesystem::path file = {}, bool persist = true, int joint_count = 0);

  std::optional<Waypoint> find(const std::string& name) const;
  std::vector<Waypoint> all() const;
  /// Adds or replaces, then saves. @throws std::invalid_argument for a bad name,
  /// std::runtime_error when the file cannot be written (the old file is kept).
  void put(const Waypoint& waypoint);
  /// @return false when there is no such waypoint.
  bool remove(const std::string& name);
  /// @throws std::invalid_argument when `from` is unknown, `to` is taken or invalid.
  void rename(const std::string& from, const std::string& to);
  const std::filesystem::path& file() const { return file_; }

 private:
  void save() const;
  std::filesystem::path file_;
  bool persist_ = true;
  int joint_count_ = 0;
  std::map<std::string, Waypoint> waypoints_;
};

}  // namespace costar::arm
