#include "calibration/calibration_file.h"

#include <cmath>
#include <stdexcept>

#include "core/files.h"
#include "core/json_file.h"

namespace costar::calibration {

namespace {

nlohmann::json residualsJson(const Residuals& r) {
  return {{"reprojection_rms_px", r.reprojection_rms_px},
          {"reprojection_max_px", r.reprojection_max_px},
          {"rotation_deg", r.rotation_deg},
          {"translation_m", r.translation_m}};
}

Residuals residualsFrom(const nlohmann::json& json) {
  Residuals r;
  r.reprojection_rms_px = json.value("reprojection_rms_px", 0.0);
  r.reprojection_max_px = json.value("reprojection_max_px", 0.0);
  r.rotation_deg = json.value("rotation_deg", 0.0);
  r.translation_m = json.value("translation_m", 0.0);
  return r;
}

}  // namespace

nlohmann::json poseToJson(const world::Pose& pose) {
  const Eigen::Quaterniond q(pose.linear());
  const Eigen::Vector3d t = pose.translation();
  const Eigen::Vector3d rpy = world::rpyOf(pose.linear()) * 180.0 / M_PI;
  return {{"xyz", {t.x(), t.y(), t.z()}},
          {"quaternion_wxyz", {q.w(), q.x(), q.y(), q.z()}},
          {"rpy_deg", {rpy.x(), rpy.y(), rpy.z()}}};
}

world::Pose poseFromJson(const nlohmann::json& json, const std::string& field) {
  try {
    const auto& t = json.at("xyz");
    const auto& q = json.at("quaternion_wxyz");
    if (t.size() != 3 || q.size() != 4) {
      throw std::runtime_error("xyz needs 3 numbers and quaternion_wxyz 4");
    }
    Eigen::Quaterniond rotation(q.at(0).get<double>(), q.at(1).get<double>(), q.at(2).get<double>(),
                                q.at(3).get<double>());
    if (!(rotation.norm() > 0.5 && rotation.norm() < 2.0)) {
      throw std::runtime_error("quaternion_wxyz is not a rotation (its norm should be 1)");
    }
    world::Pose pose = world::Pose::Identity();
    pose.linear() = rotation.normalized().toRotationMatrix();
    pose.translation() = Eigen::Vector3d(t.at(0).get<double>(), t.at(1).get<double>(), t.at(2).get<double>());
    if (!pose.matrix().allFinite()) {
      throw std::runtime_error("not finite");
    }
    return pose;
  } catch (const std::exception& e) {
    throw std::runtime_error(field + ": " + e.what());
  }
}

nlohmann::json toJson(const CellCalibration& c) {
  nlohmann::json json = nlohmann::json::object();
  if (c.marker_in_flange) {
    json["marker"] = {{"marker_in_flange", poseToJson(*c.marker_in_flange)},
                      {"method", c.marker_method},
                      {"views", c.marker_views},
                      {"residuals", residualsJson(c.marker_residuals)}};
  }
  if (c.camera_in_world) {
    json["camera"] = {{"camera_in_world", poseToJson(*c.camera_in_world)},
                      {"views", c.camera_views},
                      {"residuals", residualsJson(c.camera_residuals)}};
  }
  return json;
}

CellCalibration calibrationFromJson(const nlohmann::json& json, const std::string& label) {
  try {
    if (!json.is_object()) {
      throw std::runtime_error("the file must hold a JSON object with \"marker\" and/or \"camera\"");
    }
    // Any other JSON file (an object class, a scene) is not a calibration.
    for (const auto& [key, value] : json.items()) {
      if (key != "marker" && key != "camera") {
        throw std::runtime_error(key +
                                 ": unknown field: a calibration holds \"marker\" and/or \"camera\" (is this "
                                 "a calibration file?)");
      }
    }
    CellCalibration c;
    if (json.contains("marker")) {
      const auto& marker = json.at("marker");
      c.marker_in_flange = poseFromJson(marker.at("marker_in_flange"), "marker.marker_in_flange");
      c.marker_method = marker.value("method", "");
      c.marker_views = marker.value("views", 0);
      c.marker_residuals = residualsFrom(marker.value("residuals", nlohmann::json::object()));
    }
    if (json.contains("camera")) {
      const auto& camera = json.at("camera");
      c.camera_in_world = poseFromJson(camera.at("camera_in_world"), "camera.camera_in_world");
      c.camera_views = camera.value("views", 0);
      c.camera_residuals = residualsFrom(camera.value("residuals", nlohmann::json::object()));
    }
    return c;
  } catch (const std::exception& e) {
    throw std::runtime_error("calibration '" + label + "': " + e.what());
  }
}

std::optional<CellCalibration> loadCalibration(const std::filesystem::path& file) {
  std::error_code error;
  if (file.empty() || !std::filesystem::exists(file, error)) {
    return std::nullopt;
  }
  const std::string text = readFile(file, "calibration");
  nlohmann::json json;
  try {
    json = core::parseJson(text);
  } catch (const core::JsonSyntaxError& e) {
    throw std::runtime_error("calibration '" + file.string() + "': not valid JSON: " + e.what());
  } catch (const std::exception& e) {
    throw std::runtime_error("calibration '" + file.string() + "': " + e.what());
  }
  return calibrationFromJson(json, file.string());
}

void saveCalibration(const std::filesystem::path& file, const CellCalibration& calibration) {
  if (!file.parent_path().empty()) {
    std::filesystem::create_directories(file.parent_path());
  }
  writeFileAtomically(file, toJson(calibration).dump(2) + "\n");
}

}  // namespace costar::calibration
