#pragma once
// The gripper descriptions (robots/grippers/NAME.json, format costar-gripper-description/1,
// robots/README.md): one file per gripper, from which the build generates its simulator and
// planner models and the runtime reads what its component needs. Each is of a kind: "parallel"
// (gripper/parallel_gripper_description.h) or "adaptive-3f"
// (gripper/adaptive_gripper_description.h).

#include <filesystem>
#include <string>
#include <vector>

namespace costar::gripper {

/// robots/grippers/NAME.json under `data_root` (default: dataRoot()).
std::filesystem::path gripperDescriptionFile(const std::string& name, const std::filesystem::path& data_root = {});

/// The names of the grippers described under `data_root` (robots/grippers/*.json), sorted.
std::vector<std::string> gripperDescriptionNames(const std::filesystem::path& data_root = {});

/// The description's "kind": "parallel" or "adaptive-3f".
/// @throws std::runtime_error naming the file and the problem.
std::string gripperKind(const std::filesystem::path& file);

}  // namespace costar::gripper
