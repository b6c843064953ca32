#include "perception/workspace.h"

#include <pcl/ModelCoefficients.h>
#include <pcl/point_types.h>
#include <pcl/sample_consensus/method_types.h>
#include <pcl/sample_consensus/model_types.h>
#include <pcl/segmentation/sac_segmentation.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "core/files.h"
#include "core/json_file.h"

namespace costar::perception {

world::Pose loadTableCenter(const std::filesystem::path& file) {
  std::ifstream stream(file);
  if (!stream) {
    throw std::runtime_error("cannot open the workspace file '" + file.string() +
                             "' (find the workspace centre with `costar perception collect`)");
  }
  try {
    const nlohmann::json json = core::readJsonFile(file);
    const auto& center = json.at("table_center");
    const auto xyz = center.at("xyz").get<std::vector<double>>();
    const auto rpy = center.value("rpy_deg", std::vector<double>{0, 0, 0});
    if (xyz.size() != 3 || rpy.size() != 3) {
      throw std::runtime_error("xyz and rpy_deg need 3 numbers each");
    }
    const double degrees = M_PI / 180.0;
    return world::poseFromXyzRpy(xyz[0], xyz[1], xyz[2], rpy[0] * degrees, rpy[1] * degrees, rpy[2] * degrees);
  } catch (const std::exception& e) {
    throw std::runtime_error("workspace file '" + file.string() + "': " + e.what());
  }
}

void saveTableCenter(const std::filesystem::path& file, const world::Pose& table_center, const std::string& note) {
  const Eigen::Vector3d rpy = world::rpyOf(table_center.linear()) * 180.0 / M_PI;
  const Eigen::Vector3d xyz = table_center.translation();
  const auto round = [](double value, double step) { return std::round(value / step) * step; };
  nlohmann::json json;
  json["description"] = "The workspace centre (table_center) in the world frame: a frame on the table top, z up.";
  json["table_center"] = {{"xyz", {round(xyz.x(), 1e-5), round(xyz.y(), 1e-5), round(xyz.z(), 1e-5)}},
                          {"rpy_deg", {round(rpy.x(), 1e-3), round(rpy.y(), 1e-3), round(rpy.z(), 1e-3)}}};
  json["source"] = note;
  writeOutputFile(file, json.dump(2) + "\n");
}

PixelRect workspaceRegion(const camera::Intrinsics& intrinsics, const world::Pose& camera_pose,
                          const WorkspaceOptions& options) {
  const world::Pose table_in_camera = camera_pose.inverse() * options.table_center;
  double u_low = std::numeric_limits<double>::max();
  double v_low = u_low;
  double u_high = -u_low;
  double v_high = -u_low;
  for (const double x : {-options.half_size_x, options.half_size_x}) {
    for (const double y : {-options.half_size_y, options.half_size_y}) {
      for (const double z : {-options.plane_search_band, options.max_height}) {
        const Eigen::Vector3d p = table_in_camera * Eigen::Vector3d(x, y, z);
        if (p.z() <= 0.05) {
          return {0, 0, intrinsics.width, intrinsics.height};  // the box reaches behind the camera
        }
        const double u = intrinsics.fx * p.x() / p.z() + intrinsics.cx;
        const double v = intrinsics.fy * p.y() / p.z() + intrinsics.cy;
        u_low = std::min(u_low, u);
        u_high = std::max(u_high, u);
        v_low = std::min(v_low, v);
        v_high = std::max(v_high, v);
      }
    }
  }
  const auto clip = [](double value, int high) {
    return static_cast<int>(std::clamp(value, 0.0, static_cast<double>(high)));
  };
  return {clip(std::floor(u_low) - 2, intrinsics.width), clip(std::floor(v_low) - 2, intrinsics.height),
          clip(std::ceil(u_high) + 3, intrinsics.width), clip(std::ceil(v_high) + 3, intrinsics.height)};
}

std::vector<std::uint8_t> workspaceMask(std::span<const camera::RgbdFrame> frames, const WorkspaceOptions& options,
                                        double margin) {
  if (frames.empty()) {
    throw std::invalid_argument("workspaceMask: no frames");
  }
  const camera::RgbdFrame& frame = frames.back();
  const camera::RgbdFrame& first = frames.front();
  const camera::RgbdFrame& middle = frames[frames.size() / 2];
  const camera::Intrinsics& in = frame.intrinsics;
  const PixelRect region = workspaceRegion(in, frame.camera_pose, options);
  const Eigen::Isometry3f camera_to_table = (options.table_center.inverse() * frame.camera_pose).cast<float>();
  const float hx = static_cast<float>(options.half_size_x);
  const float hy = static_cast<float>(options.half_size_y);
  const float band = static_cast<float>(options.plane_search_band);
  const float low = static_cast<float>(options.min_height - margin);
  const float top = static_cast<float>(options.max_height + margin);
  const int stride = std::max(1, options.plane_fit_stride);
  std::vector<std::uint8_t> seed(static_cast<std::size_t>(in.width) * in.height, 0);
  for (int v = region.v_min; v < region.v_max; ++v) {
    for (int u = region.u_min; u < region.u_max; ++u) {
      const std::size_t pixel = static_cast<std::size_t>(v) * in.width + u;
      const bool grid = u % stride == 0 && v % stride == 0;
      // The median of three of the frames: a rough, cheap estimate.
      std::array<Eigen::Vector3f, 3> samples{first.points[pixel], middle.points[pixel], frame.points[pixel]};
      std::array<float, 3> heights{};
      Eigen::Vector3f q = Eigen::Vector3f::Zero();
      int valid = 0;
      for (const auto& p : samples) {
        if (p.z() == p.z()) {
          q = camera_to_table * p;
          heights[static_cast<std::size_t>(valid++)] = q.z();
        }
      }
      if (valid < 2) {
        seed[pixel] = grid ? 1 : 0;  // few readings: the median decides
        continue;
      }
      // Lower median: the smaller of two, the middle of three.
      const float height = valid == 2 ? std::min(heights[0], heights[1])
                                      : std::max(std::min(heights[0], heights[1]),
                                                 std::min(std::max(heights[0], heights[1]), heights[2]));
      if (std::abs(q.x()) > hx || std::abs(q.y()) > hy || height > top) {
        continue;
      }
      if (height > low) {
        seed[pixel] = 2;  // may be above the table: grown below
      } else if (grid && height > -band) {
        seed[pixel] = 1;
      }
    }
  }
  std::vector<std::uint8_t> mask(seed.size(), 0);
  for (int v = region.v_min; v < region.v_max; ++v) {
    for (int u = region.u_min; u < region.u_max; ++u) {
      const std::size_t pixel = static_cast<std::size_t>(v) * in.width + u;
      if (seed[pixel] == 0) {
        continue;
      }
      mask[pixel] = 1;
      if (seed[pixel] == 2) {
        for (int dv = -1; dv <= 1; ++dv) {
          for (int du = -1; du <= 1; ++du) {
            const int nu = u + du;
            const int nv = v + dv;
            if (nu >= 0 && nv >= 0 && nu < in.width && nv < in.height) {
              mask[static_cast<std::size_t>(nv) * in.width + nu] = 1;
            }
          }
        }
      }
    }
  }
  return mask;
}

WorkspaceCloud cropWorkspace(const camera::RgbdFrame& frame, const WorkspaceOptions& options) {
  const camera::Intrinsics& in = frame.intrinsics;
  const PixelRect region = workspaceRegion(in, frame.camera_pose, options);
  const Eigen::Isometry3f camera_to_table = (options.table_center.inverse() * frame.camera_pose).cast<float>();
  const float hx = static_cast<float>(options.half_size_x);
  const float hy = static_cast<float>(options.half_size_y);
  const float band = static_cast<float>(options.plane_search_band);
  const float top = static_cast<float>(options.max_height + options.plane_search_band);

  // Points in the box, and the candidates of the plane fit.
  std::vector<int> in_box;
  pcl::PointCloud<pcl::PointXYZ>::Ptr candidates(new pcl::PointCloud<pcl::PointXYZ>);
  std::vector<int> candidate_pixels;
  const int stride = std::max(1, options.plane_fit_stride);
  for (int v = region.v_min; v < region.v_max; ++v) {
    for (int u = region.u_min; u < region.u_max; ++u) {
      const int pixel = v * in.width + u;
      const Eigen::Vector3f& p = frame.points[static_cast<std::size_t>(pixel)];
      if (!(p.z() == p.z())) {
        continue;
      }
      const Eigen::Vector3f q = camera_to_table * p;
      if (std::abs(q.x()) > hx || std::abs(q.y()) > hy || q.z() < -band || q.z() > top) {
        continue;
      }
      in_box.push_back(pixel);
      if (std::abs(q.z()) < band && u % stride == 0 && v % stride == 0) {
        candidates->push_back(pcl::PointXYZ(p.x(), p.y(), p.z()));
        candidate_pixels.push_back(pixel);
      }
    }
  }
  if (candidates->size() < 50) {
    throw std::runtime_error("the camera sees no table in the workspace box (" + std::to_string(candidates->size()) +
                             " points near the table_center plane): is table_center right?");
  }

  pcl::SACSegmentation<pcl::PointXYZ> segmentation;  // fixed seed: deterministic
  segmentation.setOptimizeCoefficients(true);
  segmentation.setModelType(pcl::SACMODEL_PLANE);
  segmentation.setMethodType(pcl::SAC_RANSAC);
  segmentation.setMaxIterations(200);
  segmentation.setDistanceThreshold(options.plane_inlier_distance);
  segmentation.setInputCloud(candidates);
  pcl::PointIndices inliers;
  pcl::ModelCoefficients coefficients;
  segmentation.segment(inliers, coefficients);
  if (inliers.indices.size() < 30 || coefficients.values.size() != 4) {
    throw std::runtime_error("no table plane found in the workspace box");
  }
  WorkspaceCloud out;
  Eigen::Vector3d normal(coefficients.values[0], coefficients.values[1], coefficients.values[2]);
  double offset = coefficients.values[3];
  const double norm = normal.norm();
  normal /= norm;
  offset /= norm;
  // Orient the normal out of the table: along table_center's z axis.
  const Eigen::Vector3d table_up = (frame.camera_pose.inverse().linear() * options.table_center.linear()).col(2);
  if (normal.dot(table_up) < 0) {
    normal = -normal;
    offset = -offset;
  }
  out.plane = {normal, offset, static_cast<int>(inliers.indices.size())};
  for (const int i : inliers.indices) {
    const int pixel = candidate_pixels[static_cast<std::size_t>(i)];
    out.table.points.push_back(frame.points[static_cast<std::size_t>(pixel)]);
    const std::uint8_t* c = &frame.rgb.pixels[static_cast<std::size_t>(pixel) * 3];
    out.table.colors.push_back({c[0], c[1], c[2]});
    out.table.pixels.push_back(pixel);
  }

  const bool has_rgb = frame.rgb.width == in.width && frame.rgb.height == in.height;
  for (const int pixel : in_box) {
    const Eigen::Vector3f& p = frame.points[static_cast<std::size_t>(pixel)];
    const double height = out.plane.height(p);
    if (height < options.min_height || height > options.max_height) {
      continue;
    }
    out.cloud.points.push_back(p);
    out.cloud.pixels.push_back(pixel);
    if (has_rgb) {
      const std::uint8_t* c = &frame.rgb.pixels[static_cast<std::size_t>(pixel) * 3];
      out.cloud.colors.push_back({c[0], c[1], c[2]});
    } else {
      out.cloud.colors.push_back({128, 128, 128});
    }
    out.heights.push_back(static_cast<float>(height));
  }
  return out;
}

void estimateNormals(const camera::RgbdFrame& frame, Cloud& cloud, int window_radius, float max_distance) {
  const int width = frame.intrinsics.width;
  const int height = frame.intrinsics.height;
  // Which pixels belong to the cloud.
  std::vector<int> member(static_cast<std::size_t>(width) * height, -1);
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    member[static_cast<std::size_t>(cloud.pixels[i])] = static_cast<int>(i);
  }
  const float max_squared = max_distance * max_distance;
  cloud.normals.resize(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3f& p = cloud.points[i];
    const int u0 = cloud.pixels[i] % width;
    const int v0 = cloud.pixels[i] / width;
    Eigen::Vector3f sum = Eigen::Vector3f::Zero();
    Eigen::Matrix3f outer = Eigen::Matrix3f::Zero();
    int count = 0;
    for (int v = std::max(0, v0 - window_radius); v <= std::min(height - 1, v0 + window_radius); ++v) {
      for (int u = std::max(0, u0 - window_radius); u <= std::min(width - 1, u0 + window_radius); ++u) {
        const int j = member[static_cast<std::size_t>(v) * width + u];
        if (j < 0) {
          continue;
        }
        const Eigen::Vector3f d = cloud.points[static_cast<std::size_t>(j)] - p;
        if (d.squaredNorm() > max_squared) {
          continue;
        }
        sum += d;
        outer += d * d.transpose();
        ++count;
      }
    }
    Eigen::Vector3f normal = -p.normalized();
    if (count >= 5) {
      const Eigen::Vector3f mean = sum / static_cast<float>(count);
      const Eigen::Matrix3f covariance = outer / static_cast<float>(count) - mean * mean.transpose();
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3f> solver;
      solver.computeDirect(covariance);
      normal = solver.eigenvectors().col(0);
      if (normal.dot(p) > 0) {
        normal = -normal;
      }
    }
    cloud.normals[i] = normal.normalized();
  }
}

}  // namespace costar::perception
