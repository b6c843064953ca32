#include <algorithm>
#include <functional>
#include <stdexcept>

#include "perception/pose_estimation.h"

namespace costar::perception {

namespace {

/// Detections are kept best first: their agreement with the depth image times the fraction seen.
double rank(const Detection& detection) { return detection.confidence * detection.visible_fraction; }

std::vector<Detection> mergeBy(std::vector<Detection> detections,
                               const std::function<const ObjectModel&(const std::string&)>& model_of) {
  std::stable_sort(detections.begin(), detections.end(),
                   [](const Detection& a, const Detection& b) { return rank(a) > rank(b); });
  std::vector<Detection> kept;
  for (auto& detection : detections) {
    const ObjectModel& model = model_of(detection.object_class);
    const bool taken = std::any_of(kept.begin(), kept.end(), [&](const Detection& other) {
      return overlapFraction(model, detection.pose_in_camera, model_of(other.object_class), other.pose_in_camera) > 0.2;
    });
    if (!taken) {
      kept.push_back(std::move(detection));
    }
  }
  return kept;
}

}  // namespace

std::vector<Detection> mergeDetections(std::vector<Detection> detections, const std::vector<ObjectModel>& models) {
  return mergeBy(std::move(detections), [&models](const std::string& name) -> const ObjectModel& {
    for (const auto& model : models) {
      if (model.name() == name) {
        return model;
      }
    }
    throw std::invalid_argument("mergeDetections: no model of class '" + name + "'");
  });
}

std::vector<Detection> mergeDetections(std::vector<Detection> detections, const ObjectModel& model) {
  return mergeBy(std::move(detections), [&model](const std::string&) -> const ObjectModel& { return model; });
}

}  // namespace costar::perception
