#pragma once
// Grasps taught by demonstration: for each object class, named transforms T = the tool centre
// point's pose in the object's frame (SmartMove goes to object * symmetry * T). Defaults ship
// in data/grasps.json; taught ones are kept per workcell and take precedence.

#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "world/object_class.h"
#include "world/pose.h"

namespace costar::smartmove {

struct Grasp {
  std::string object_class;
  std::string name;
  world::Pose tcp_in_object = world::Pose::Identity();
};

class GraspLibrary {
 public:
  /// Reads the defaults and, if it exists, the taught file (which wins for equal names).
  /// Taught grasps are saved to `taught_file` (none when empty).
  /// @throws std::runtime_error naming a file that cannot be read.
  GraspLibrary(const std::filesystem::path& defaults_file, std::filesystem::path taught_file);

  std::optional<Grasp> find(const std::string& object_class, const std::string& name) const;
  std::vector<Grasp> forClass(const std::string& object_class) const;
  /// The grasp used when a plan names none: the class's first in the defaults file (as taught,
  /// when a taught grasp has its name), else its first taught one.
  std::optional<Grasp> defaultFor(const std::string& object_class) const;
  std::vector<std::string> names() const;
  /// Adds or replaces a taught grasp and saves the taught file atomically.
  void teach(const Grasp& grasp);

 private:
  std::filesystem::path taught_file_;
  std::map<std::pair<std::string, std::string>, Grasp> defaults_;
  std::map<std::pair<std::string, std::string>, Grasp> taught_;
};

/// The symmetric equivalent of a grasp demonstrated at `tcp_in_object`: among (s^-1 * T) for
/// the class's symmetries s, the one whose tool points most nearly down the object's -z with
/// its fingers closing along the object's y (the canonical top grasp), so the same grasp taught
/// on a part turned by a symmetry gives the same T.
world::Pose snapToCanonical(const world::Pose& tcp_in_object, const world::ObjectClass& object_class);

}  // namespace costar::smartmove
