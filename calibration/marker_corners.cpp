#include "calibration/marker_corners.h"

#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include <cmath>

#include "calibration/hand_eye.h"

namespace costar::calibration {

namespace {

/// Grey level at a sub-pixel point (pixel centres at whole coordinates), bilinear; empty
/// outside the image.
std::optional<double> greyAt(const cv::Mat& grey, const Eigen::Vector2d& p) {
  const double x = std::floor(p.x());
  const double y = std::floor(p.y());
  if (x < 0 || y < 0 || x + 1 >= grey.cols || y + 1 >= grey.rows) {
    return std::nullopt;
  }
  const int ix = static_cast<int>(x);
  const int iy = static_cast<int>(y);
  const double fx = p.x() - x;
  const double fy = p.y() - y;
  const auto at = [&grey](int u, int v) { return static_cast<double>(grey.at<float>(v, u)); };
  return (1 - fy) * ((1 - fx) * at(ix, iy) + fx * at(ix + 1, iy)) +
         fy * ((1 - fx) * at(ix, iy + 1) + fx * at(ix + 1, iy + 1));
}

/// A line as a point and a unit direction.
struct Line {
  Eigen::Vector2d point;
  Eigen::Vector2d direction;
};

std::optional<Eigen::Vector2d> intersect(const Line& a, const Line& b) {
  // a.point + s a.direction = b.point + t b.direction
  Eigen::Matrix2d m;
  m.col(0) = a.direction;
  m.col(1) = -b.direction;
  if (std::abs(m.determinant()) < 1e-3) {
    return std::nullopt;
  }
  const Eigen::Vector2d st = m.inverse() * (b.point - a.point);
  return a.point + st(0) * a.direction;
}

/// The edge between `from` and `to` (the marker's inside towards `inside`): where the grey
/// level crosses halfway from black to white across it, sampled every half pixel along it,
/// and the line fitted to those points.
std::optional<Line> fitEdge(const cv::Mat& grey, const Eigen::Vector2d& from, const Eigen::Vector2d& to,
                            const Eigen::Vector2d& inside, const MarkerCornerOptions& options) {
  const Eigen::Vector2d along = to - from;
  const double length = along.norm();
  if (length < 8.0) {
    return std::nullopt;
  }
  const Eigen::Vector2d direction = along / length;
  Eigen::Vector2d normal(-direction.y(), direction.x());
  if (normal.dot(inside - from) > 0) {
    normal = -normal;  // outwards, towards the white border
  }
  constexpr double kStep = 0.25;  // across the edge (pixels)
  const int steps = static_cast<int>(std::round(2 * options.search_px / kStep));
  std::vector<cv::Point2f> points;
  for (double s = options.end_margin * length; s <= (1 - options.end_margin) * length; s += 0.5) {
    const Eigen::Vector2d centre = from + s * direction;
    std::vector<double> profile;
    profile.reserve(static_cast<std::size_t>(steps) + 1);
    for (int i = 0; i <= steps; ++i) {
      const auto value = greyAt(grey, centre + (-options.search_px + i * kStep) * normal);
      if (!value) {
        break;
      }
      profile.push_back(*value);
    }
    if (static_cast<int>(profile.size()) != steps + 1) {
      continue;
    }
    const double dark = profile.front();
    const double light = profile.back();
    if (light - dark < options.min_contrast) {
      continue;
    }
    const double half = 0.5 * (dark + light);
    // The crossing nearest the middle of the search (the edge as ArUco put it).
    std::optional<double> best;
    for (int i = 0; i < steps; ++i) {
      const double a = profile[static_cast<std::size_t>(i)];
      const double b = profile[static_cast<std::size_t>(i) + 1];
      if ((a - half) * (b - half) <= 0 && a != b) {
        const double offset = -options.search_px + (i + (half - a) / (b - a)) * kStep;
        if (!best || std::abs(offset) < std::abs(*best)) {
          best = offset;
        }
      }
    }
    if (best) {
      const Eigen::Vector2d p = centre + *best * normal;
      points.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()));
    }
  }
  if (points.size() < 6 || static_cast<double>(points.size()) < 0.5 * (1 - 2 * options.end_margin) * length / 0.5) {
    return std::nullopt;  // most of the edge hidden or without contrast
  }
  cv::Vec4f line;
  cv::fitLine(points, line, cv::DIST_HUBER, 0, 0.01, 0.01);
  return Line{{line[2], line[3]}, Eigen::Vector2d(line[0], line[1]).normalized()};
}

}  // namespace

std::array<Eigen::Vector2d, 4> refineMarkerCorners(const RgbImage& image, const std::array<Eigen::Vector2d, 4>& corners,
                                                   const MarkerCornerOptions& options) {
  if (image.width <= 1 || image.height <= 1) {
    return corners;
  }
  const cv::Mat rgb(image.height, image.width, CV_8UC3, const_cast<std::uint8_t*>(image.pixels.data()));
  cv::Mat grey8;
  cv::cvtColor(rgb, grey8, cv::COLOR_RGB2GRAY);
  cv::Mat grey;
  grey8.convertTo(grey, CV_32F);
  const Eigen::Vector2d centre = 0.25 * (corners[0] + corners[1] + corners[2] + corners[3]);
  std::array<Eigen::Vector2d, 4> current = corners;
  for (int round = 0; round < options.rounds; ++round) {
    std::array<std::optional<Line>, 4> edges;  // edge k: from corner k to corner k+1
    for (std::size_t k = 0; k < 4; ++k) {
      edges[k] = fitEdge(grey, current[k], current[(k + 1) % 4], centre, options);
    }
    std::array<Eigen::Vector2d, 4> next = current;
    for (std::size_t k = 0; k < 4; ++k) {
      const auto& before = edges[(k + 3) % 4];  // into corner k
      const auto& after = edges[k];             // out of corner k
      if (!before || !after) {
        continue;
      }
      const auto corner = intersect(*before, *after);
      if (corner && (*corner - corners[k]).norm() <= options.max_shift_px) {
        next[k] = *corner;
      }
    }
    current = next;
  }
  return current;
}

std::optional<world::Pose> markerPoseFromCorners(const std::array<Eigen::Vector2d, 4>& corners,
                                                 const camera::Intrinsics& intrinsics, double marker_size) {
  std::vector<cv::Point3d> object;
  for (const Eigen::Vector3d& c : markerCorners(marker_size)) {
    object.emplace_back(c.x(), c.y(), c.z());
  }
  std::vector<cv::Point2d> image;
  for (const Eigen::Vector2d& c : corners) {
    image.emplace_back(c.x(), c.y());
  }
  const cv::Matx33d k(intrinsics.fx, 0, intrinsics.cx, 0, intrinsics.fy, intrinsics.cy, 0, 0, 1);
  const cv::Mat distortion = cv::Mat::zeros(1, 5, CV_64F);
  cv::Mat rvec;
  cv::Mat tvec;
  try {
    if (!cv::solvePnP(object, image, k, distortion, rvec, tvec, false, cv::SOLVEPNP_IPPE_SQUARE)) {
      return std::nullopt;
    }
    cv::solvePnPRefineLM(object, image, k, distortion, rvec, tvec);
  } catch (const cv::Exception&) {
    return std::nullopt;
  }
  cv::Mat r;
  cv::Rodrigues(rvec, r);
  world::Pose pose = world::Pose::Identity();
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      pose.linear()(i, j) = r.at<double>(i, j);
    }
    pose.translation()(i) = tvec.at<double>(i, 0);
  }
  if (!pose.matrix().allFinite() || pose.translation().z() <= 0) {
    return std::nullopt;
  }
  return pose;
}

}  // namespace costar::calibration
