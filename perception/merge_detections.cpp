#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
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
  std::vector<PlacedModel> placed;
  for (auto& detection : detections) {
    const ObjectModel& model = model_of(detection.object_class);
    // Taken when the kept ones claim a fifth of its volume, one or several together.
    if (overlapFraction(model, detection.pose_in_camera, placed) > kOverlapTaken) {
      continue;
    }
    placed.push_back({&model, detection.pose_in_camera});
    kept.push_back(std::move(detection));
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

std::vector<Detection> keepSupported(const std::vector<Detection>& detections, const std::vector<ObjectModel>& models,
                                     const TablePlane& table, double tolerance,
                                     const std::vector<std::vector<Eigen::Vector3f>>& unfound) {
  struct Extent {
    double low = 0.0, high = 0.0;
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();  // the origin projected onto the table
    double radius = 0.0;                               // of the footprint about it
    bool leaning = false;                              // no face within kLeaning of lying flat
  };
  std::vector<Extent> extents;
  for (const Detection& detection : detections) {
    const auto model = std::find_if(models.begin(), models.end(),
                                    [&detection](const ObjectModel& m) { return m.name() == detection.object_class; });
    if (model == models.end()) {
      throw std::invalid_argument("keepSupported: no model of class '" + detection.object_class + "'");
    }
    Extent extent;
    const Eigen::Vector3d origin = detection.pose_in_camera.translation();
    extent.centre = origin - table.normal * (table.normal.dot(origin) + table.offset);
    const Eigen::Matrix3d rotation = detection.pose_in_camera.linear();
    extent.leaning = (rotation.transpose() * table.normal.normalized()).cwiseAbs().maxCoeff() < std::cos(kLeaning);
    extent.low = std::numeric_limits<double>::infinity();
    extent.high = -std::numeric_limits<double>::infinity();
    for (const world::Box& box : model->object_class.boxes) {
      for (int corner = 0; corner < 8; ++corner) {
        const Eigen::Vector3d local(box.center.x() + ((corner & 1) ? 1 : -1) * box.half_size.x(),
                                    box.center.y() + ((corner & 2) ? 1 : -1) * box.half_size.y(),
                                    box.center.z() + ((corner & 4) ? 1 : -1) * box.half_size.z());
        const Eigen::Vector3d point = detection.pose_in_camera * local;
        const double height = table.normal.dot(point) + table.offset;
        extent.low = std::min(extent.low, height);
        extent.high = std::max(extent.high, height);
        const Eigen::Vector3d on_table = point - table.normal * height;
        extent.radius = std::max(extent.radius, (on_table - extent.centre).norm());
      }
    }
    extents.push_back(extent);
  }
  std::vector<bool> kept(detections.size(), false);
  for (std::size_t d = 0; d < detections.size(); ++d) {
    kept[d] = std::abs(extents[d].low) <= tolerance && !extents[d].leaning;
  }
  // A cluster where nothing was found, standing on the table, holds up what lies on its top as
  // a kept detection does: a part hidden but for its sides (a node under a link across it).
  for (const std::vector<Eigen::Vector3f>& points : unfound) {
    if (points.empty()) {
      continue;
    }
    std::vector<double> heights;
    heights.reserve(points.size());
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const Eigen::Vector3f& point : points) {
      heights.push_back(table.height(point));
      mean += point.cast<double>();
    }
    mean /= static_cast<double>(points.size());
    std::sort(heights.begin(), heights.end());
    Extent extent;
    extent.low = heights[heights.size() / 20];
    extent.high = heights[heights.size() - 1 - heights.size() / 20];
    if (extent.low > kRaisedSupport) {
      continue;
    }
    extent.centre = mean - table.normal * (table.normal.dot(mean) + table.offset);
    for (const Eigen::Vector3f& point : points) {
      const Eigen::Vector3d p = point.cast<double>();
      extent.radius =
          std::max(extent.radius, (p - table.normal * (table.normal.dot(p) + table.offset) - extent.centre).norm());
    }
    extents.push_back(extent);
    kept.push_back(true);
  }
  // Resting on a kept one: its bottom at the other's top, their footprints meeting.
  const auto restsOn = [&](std::size_t d, std::size_t e) {
    return std::abs(extents[d].low - extents[e].high) <= tolerance &&
           (extents[d].centre - extents[e].centre).norm() < extents[d].radius + extents[e].radius;
  };
  // A leaning part is held up at its raised end: a kept one rising above its bottom, its
  // footprint reaching under the leaning one's middle half (it may rise higher: a node tilted
  // against a link that leans more steeply); or what holds it is hidden, and more of it is seen.
  const auto holdsUp = [&](std::size_t e, std::size_t d) {
    return extents[e].high > extents[d].low + tolerance &&
           (extents[d].centre - extents[e].centre).norm() < extents[e].radius + 0.5 * extents[d].radius;
  };
  for (bool changed = true; changed;) {
    changed = false;
    for (std::size_t d = 0; d < detections.size(); ++d) {
      if (kept[d]) {
        continue;
      }
      bool rests = extents[d].leaning && std::abs(extents[d].low) <= tolerance;
      bool held = !extents[d].leaning || detections[d].visible_fraction >= kLeaningSeen;
      for (std::size_t e = 0; e < extents.size(); ++e) {
        if (kept[e] && e != d) {
          rests = rests || restsOn(d, e);
          held = held || holdsUp(e, d);
        }
      }
      if (rests && held) {
        kept[d] = true;
        changed = true;
      }
    }
  }
  std::vector<Detection> out;
  for (std::size_t d = 0; d < detections.size(); ++d) {
    if (kept[d]) {
      out.push_back(detections[d]);
    }
  }
  return out;
}

}  // namespace costar::perception
