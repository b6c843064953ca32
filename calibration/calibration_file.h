#pragma once
// The cell's calibration, saved with the cell: the marker's place on the flange (the one-time
// marker calibration) and the camera's pose in the world (the latest Calibrate), with the
// residuals each was accepted with. JSON; written atomically, so a crash never loses it.

#include <filesystem>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "calibration/hand_eye.h"

namespace costar::calibration {

struct CellCalibration {
  /// Stage (a): the marker in the flange, and how it was found.
  std::optional<world::Pose> marker_in_flange;
  std::string marker_method;
  Residuals marker_residuals;
  int marker_views = 0;
  /// Stage (b): the camera's optical frame in the world.
  std::optional<world::Pose> camera_in_world;
  Residuals camera_residuals;
  int camera_views = 0;
};

nlohmann::json poseToJson(const world::Pose& pose);
/// @throws std::runtime_error naming the field.
world::Pose poseFromJson(const nlohmann::json& json, const std::string& field);

nlohmann::json toJson(const CellCalibration& calibration);
/// @throws std::runtime_error naming `label`, the field and the problem.
CellCalibration calibrationFromJson(const nlohmann::json& json, const std::string& label);

/// Reads a calibration file; nullopt when it does not exist.
/// @throws std::runtime_error naming the file and the problem when it exists but is unreadable.
std::optional<CellCalibration> loadCalibration(const std::filesystem::path& file);
/// @throws std::runtime_error naming the file.
void saveCalibration(const std::filesystem::path& file, const CellCalibration& calibration);

}  // namespace costar::calibration
