#include "perception/aruco_marker.h"

#include <opencv2/aruco.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include <Eigen/Eigenvalues>
#include <Eigen/QR>

namespace costar::perception {

RgbImage arucoMarkerImage(int id, int cell_pixels, int quiet_cells) {
  const cv::Ptr<cv::aruco::Dictionary> dictionary = cv::aruco::getPredefinedDictionary(cv::aruco::DICT_4X4_50);
  cv::Mat marker;
  cv::aruco::drawMarker(dictionary, id, 6 * cell_pixels, marker, 1);
  const int side = (6 + 2 * quiet_cells) * cell_pixels;
  RgbImage image(side, side);
  std::fill(image.pixels.begin(), image.pixels.end(), 255);
  const int offset = quiet_cells * cell_pixels;
  for (int y = 0; y < marker.rows; ++y) {
    for (int x = 0; x < marker.cols; ++x) {
      const std::uint8_t value = marker.at<std::uint8_t>(y, x);
      std::uint8_t* pixel = image.at(x + offset, y + offset);
      pixel[0] = pixel[1] = pixel[2] = value;
    }
  }
  return image;
}

std::vector<MarkerDetection> detectArucoMarkers(const RgbImage& image, const camera::Intrinsics& intrinsics,
                                                double marker_size) {
  std::vector<MarkerDetection> out;
  if (image.width <= 0 || image.height <= 0) {
    return out;
  }
  const cv::Mat rgb(image.height, image.width, CV_8UC3, const_cast<std::uint8_t*>(image.pixels.data()));
  cv::Mat gray;
  cv::cvtColor(rgb, gray, cv::COLOR_RGB2GRAY);
  const cv::Ptr<cv::aruco::Dictionary> dictionary = cv::aruco::getPredefinedDictionary(cv::aruco::DICT_4X4_50);
  const cv::Ptr<cv::aruco::DetectorParameters> parameters = cv::aruco::DetectorParameters::create();
  parameters->cornerRefinementMethod = cv::aruco::CORNER_REFINE_SUBPIX;
  std::vector<std::vector<cv::Point2f>> corners;
  std::vector<int> ids;
  cv::aruco::detectMarkers(gray, dictionary, corners, ids, parameters);
  if (ids.empty()) {
    return out;
  }
  const cv::Matx33d camera_matrix(intrinsics.fx, 0, intrinsics.cx, 0, intrinsics.fy, intrinsics.cy, 0, 0, 1);
  const cv::Mat distortion = cv::Mat::zeros(1, 5, CV_64F);
  std::vector<cv::Vec3d> rotations;
  std::vector<cv::Vec3d> translations;
  cv::aruco::estimatePoseSingleMarkers(corners, static_cast<float>(marker_size), camera_matrix, distortion, rotations,
                                       translations);
  for (std::size_t i = 0; i < ids.size(); ++i) {
    MarkerDetection detection;
    detection.id = ids[i];
    cv::Matx33d r;
    cv::Rodrigues(rotations[i], r);
    Eigen::Matrix3d rotation;
    rotation << r(0, 0), r(0, 1), r(0, 2), r(1, 0), r(1, 1), r(1, 2), r(2, 0), r(2, 1), r(2, 2);
    detection.pose_in_camera.linear() = rotation;
    detection.pose_in_camera.translation() =
        Eigen::Vector3d(translations[i][0], translations[i][1], translations[i][2]);
    for (const auto& corner : corners[i]) {
      detection.corners.emplace_back(corner.x, corner.y);
    }
    out.push_back(detection);
  }
  return out;
}

std::optional<world::Pose> locateWorkspaceCenter(const camera::RgbdFrame& frame, const MarkerOptions& options) {
  for (const auto& marker : detectArucoMarkers(frame.rgb, frame.intrinsics, options.size)) {
    if (marker.id != options.id || marker.corners.size() != 4) {
      continue;
    }
    world::Pose pose = marker.pose_in_camera;
    // The marker's distance from its apparent size is the weak part of a single-marker pose
    // (a 1 % error in the corners is 1 cm at a metre). With depth, take the marker's plane
    // from the depth points inside it and put the centre where the ray through the marker's
    // image centre meets that plane; keep ArUco's in-plane direction.
    const camera::Intrinsics& in = frame.intrinsics;
    if (frame.points.size() == static_cast<std::size_t>(in.width) * in.height) {
      std::vector<cv::Point2f> polygon;
      for (const auto& c : marker.corners) {
        polygon.emplace_back(static_cast<float>(c.x()), static_cast<float>(c.y()));
      }
      const cv::Rect box = cv::boundingRect(polygon);
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      Eigen::Matrix3d outer = Eigen::Matrix3d::Zero();
      int count = 0;
      for (int v = std::max(0, box.y); v < std::min(in.height, box.y + box.height); ++v) {
        for (int u = std::max(0, box.x); u < std::min(in.width, box.x + box.width); ++u) {
          if (cv::pointPolygonTest(polygon, cv::Point2f(static_cast<float>(u), static_cast<float>(v)), false) <= 0 ||
              !frame.valid(u, v)) {
            continue;
          }
          const Eigen::Vector3d p = frame.point(u, v).cast<double>();
          sum += p;
          outer += p * p.transpose();
          ++count;
        }
      }
      if (count >= 30) {
        const Eigen::Vector3d mean = sum / count;
        const Eigen::Matrix3d covariance = outer / count - mean * mean.transpose();
        const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(covariance);
        Eigen::Vector3d normal = solver.eigenvectors().col(0);
        if (normal.dot(mean) > 0) {
          normal = -normal;  // towards the camera: out of the table
        }
        // Image centre of the marker: where its diagonals cross.
        const Eigen::Vector2d a = marker.corners[0];
        const Eigen::Vector2d b = marker.corners[2];
        const Eigen::Vector2d c = marker.corners[1];
        const Eigen::Vector2d d = marker.corners[3];
        Eigen::Matrix2d m;
        m << b - a, c - d;
        if (std::abs(m.determinant()) > 1e-9) {
          const Eigen::Vector2d st = m.colPivHouseholderQr().solve(c - a);
          const Eigen::Vector2d centre = a + st.x() * (b - a);
          const Eigen::Vector3d ray((centre.x() - in.cx) / in.fx, (centre.y() - in.cy) / in.fy, 1.0);
          const double along = normal.dot(mean) / normal.dot(ray);
          Eigen::Vector3d x_axis = pose.linear().col(0);
          x_axis = (x_axis - x_axis.dot(normal) * normal).normalized();
          pose.linear().col(0) = x_axis;
          pose.linear().col(1) = normal.cross(x_axis);
          pose.linear().col(2) = normal;
          pose.translation() = along * ray;
        }
      }
    }
    return frame.camera_pose * pose;
  }
  return std::nullopt;
}

}  // namespace costar::perception
