#include "perception/hand_detector.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "perception/clustering.h"

namespace costar::perception {

namespace {

struct Chromaticity {
  double r = 0, g = 0, b = 0, brightness = 0;
};

Chromaticity chromaticity(const unsigned char* rgb) {
  const double sum = static_cast<double>(rgb[0]) + rgb[1] + rgb[2];
  if (sum <= 0.0) {
    return {};
  }
  return {rgb[0] / sum, rgb[1] / sum, rgb[2] / sum, std::max({rgb[0], rgb[1], rgb[2]}) / 255.0};
}

}  // namespace

bool isSkinColour(const unsigned char* rgb, const HandOptions& options) {
  const Chromaticity c = chromaticity(rgb);
  const double red_minus_blue = c.r - c.b;
  return c.brightness >= options.min_brightness && c.r > c.g && c.g >= c.b &&
         red_minus_blue >= options.min_red_minus_blue && red_minus_blue <= options.max_red_minus_blue &&
         c.b >= options.min_blue;
}

std::optional<HandObservation> detectHand(const camera::RgbdFrame& frame, const world::Pose& camera_pose,
                                          const HandOptions& options) {
  const int width = frame.intrinsics.width;
  const int height = frame.intrinsics.height;
  if (frame.rgb.width != width || frame.rgb.height != height ||
      frame.points.size() != static_cast<std::size_t>(width) * height) {
    throw std::invalid_argument("detectHand: the frame's colour image (" + std::to_string(frame.rgb.width) + "x" +
                                std::to_string(frame.rgb.height) + ") does not match its points (" +
                                std::to_string(width) + "x" + std::to_string(height) + ")");
  }
  const world::Pose to_table = options.table_center.inverse() * camera_pose;
  std::vector<Eigen::Vector3f> table_points;  // skin points in the table's frame
  std::vector<int> pixels;
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      if (!frame.valid(u, v)) {
        continue;
      }
      const Eigen::Vector3d p = to_table * frame.point(u, v).cast<double>();
      if (std::abs(p.x()) > options.half_size_x || std::abs(p.y()) > options.half_size_y ||
          p.z() < options.min_height || p.z() > options.max_height) {
        continue;
      }
      const unsigned char* rgb = frame.rgb.pixels.data() + (static_cast<std::size_t>(v) * width + u) * 3;
      if (!isSkinColour(rgb, options)) {
        continue;
      }
      table_points.push_back(p.cast<float>());
      pixels.push_back(v * width + u);
    }
  }
  if (static_cast<int>(table_points.size()) < options.min_points) {
    return std::nullopt;
  }
  const auto groups =
      organizedClusters(table_points, pixels, width, height, options.cluster_tolerance, 3, options.min_points);
  const std::vector<int>* largest = nullptr;
  for (const auto& group : groups) {
    if (largest == nullptr || group.size() > largest->size()) {
      largest = &group;
    }
  }
  if (largest == nullptr) {
    return std::nullopt;
  }
  // The root: where the forearm enters, farthest from the table's centre across the table.
  int root = largest->front();
  for (const int i : *largest) {
    if (table_points[i].head<2>().norm() > table_points[root].head<2>().norm()) {
      root = i;
    }
  }
  int tip = root;
  for (const int i : *largest) {
    if ((table_points[i] - table_points[root]).norm() > (table_points[tip] - table_points[root]).norm()) {
      tip = i;
    }
  }
  const Eigen::Vector3d tip_t = table_points[tip].cast<double>();
  std::vector<Eigen::Vector3d> hand;
  int palm_coloured = 0;
  Eigen::Vector3d palm_sum = Eigen::Vector3d::Zero();
  for (const int i : *largest) {
    const Eigen::Vector3d p = table_points[i].cast<double>();
    const double from_tip = (p - tip_t).norm();
    if (from_tip <= options.hand_radius) {
      hand.push_back(p);
      const Chromaticity c = chromaticity(frame.rgb.pixels.data() + static_cast<std::size_t>(pixels[i]) * 3);
      if (c.g - c.b < options.palm_max_green_minus_blue) {
        ++palm_coloured;
        palm_sum += p;
      }
    }
  }
  HandObservation seen;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const auto& p : hand) {
    centre += p;
  }
  centre /= static_cast<double>(hand.size());
  seen.position = options.table_center * centre;
  seen.tip = options.table_center * tip_t;
  seen.direction = options.table_center.linear() * (tip_t - table_points[root].cast<double>()).normalized();
  seen.palm_fraction = static_cast<double>(palm_coloured) / static_cast<double>(hand.size());
  seen.palm_to_tip = palm_coloured > 0 ? (palm_sum / palm_coloured - tip_t).norm() : 0.0;
  seen.open_palm_up =
      seen.palm_fraction >= options.palm_up_min_fraction && seen.palm_to_tip >= options.open_min_palm_to_tip;
  seen.hand_points = static_cast<int>(hand.size());
  seen.group_points = static_cast<int>(largest->size());
  return seen;
}

}  // namespace costar::perception
