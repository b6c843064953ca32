#pragma once
// Grasps taught by demonstration: for each gripper and object class, named transforms T = the
// tool centre point's pose in the object's frame (SmartMove goes to object * symmetry * T).
// Defaults ship in data/grasps.json; taught ones are kept per workcell and take precedence.
// A grasp belongs to one gripper (its "gripper" field; none: the 2-finger parallel gripper,
// kParallelGripper), so one class has a 2-finger and a 3-finger grasp; a library answers for
// the gripper it was made for and keeps the others' grasps in its files untouched.

#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include "world/object_class.h"
#include "world/pose.h"

namespace costar::smartmove {

/// The grasp files' key of the 2-finger parallel gripper (entries without a "gripper" field).
inline constexpr const char* kParallelGripper = "parallel-2f";
/// The 3-finger adaptive gripper (robots/grippers/robotiq3f.json).
inline constexpr const char* kAdaptiveGripper = "robotiq3f";

struct Grasp {
  std::string object_class;
  std::string name;
  world::Pose tcp_in_object = world::Pose::Identity();
  /// Which gripper it is for; empty in teach(): the library's gripper.
  std::string gripper;
  /// The gripper mode the grasp needs ("pinch", "basic", ...: the gripper's SetMode names);
  /// SmartGrasp sets it while the fingers are open. Empty: whatever mode the gripper is in.
  std::string mode;
};

class GraspLibrary {
 public:
  /// Reads the defaults and, if it exists, the taught file (which wins for equal names), and
  /// answers for `gripper`'s grasps. Taught grasps are saved to `taught_file` (none when empty).
  /// @throws std::runtime_error naming a file that cannot be read, or the entry that is wrong.
  GraspLibrary(const std::filesystem::path& defaults_file, std::filesystem::path taught_file,
               std::string gripper = kParallelGripper);
  const std::string& gripper() const { return gripper_; }

  std::optional<Grasp> find(const std::string& object_class, const std::string& name) const;
  std::vector<Grasp> forClass(const std::string& object_class) const;
  /// The grasp used when a plan names none: the class's first in the defaults file (as taught,
  /// when a taught grasp has its name), else its first taught one.
  std::optional<Grasp> defaultFor(const std::string& object_class) const;
  std::vector<std::string> names() const;
  /// Adds or replaces a taught grasp (for the library's gripper when grasp.gripper is empty)
  /// and saves the taught file atomically, other grippers' taught grasps included.
  void teach(const Grasp& grasp);

 private:
  /// (gripper, class, name)
  using Key = std::tuple<std::string, std::string, std::string>;
  std::filesystem::path taught_file_;
  std::string gripper_;
  std::map<Key, Grasp> defaults_;
  std::vector<Key> default_order_;  ///< the defaults file's order (defaultFor)
  std::map<Key, Grasp> taught_;
};

/// The symmetric equivalent of a grasp demonstrated at `tcp_in_object`: among (s^-1 * T) for
/// the class's symmetries s, the one whose tool points most nearly down the object's -z with
/// its fingers closing along the object's y (the canonical top grasp), so the same grasp taught
/// on a part turned by a symmetry gives the same T.
world::Pose snapToCanonical(const world::Pose& tcp_in_object, const world::ObjectClass& object_class);

}  // namespace costar::smartmove
