#include "perception/training_data.h"

#include <algorithm>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "core/files.h"
#include "core/json_file.h"
#include "perception/clustering.h"
#include "perception/features.h"

namespace costar::perception {

namespace {

void appendRows(TrainingSet& set, const Eigen::MatrixXf& rows, const std::vector<int>& which, int label) {
  if (which.empty()) {
    return;
  }
  const Eigen::Index start = set.features.rows();
  if (set.features.cols() == 0) {
    set.features.resize(0, kFeatureCount);
  }
  set.features.conservativeResize(start + static_cast<Eigen::Index>(which.size()), kFeatureCount);
  for (std::size_t i = 0; i < which.size(); ++i) {
    set.features.row(start + static_cast<Eigen::Index>(i)) = rows.row(which[i]);
    set.labels.push_back(label);
  }
}

}  // namespace

ExamplesAdded addTrainingExamples(const camera::RgbdFrame& frame, const PipelineOptions& options, int label,
                                  bool add_table, TrainingSet& set, double max_extent) {
  ExamplesAdded added;
  WorkspaceCloud workspace = cropWorkspace(frame, options.workspace);
  if (workspace.cloud.size() >= 10) {
    estimateNormals(frame, workspace.cloud, options.normal_window, static_cast<float>(options.normal_max_distance));
    const VoxelFeatures voxels = computeFeatures(workspace.cloud, options.segmentation.features);
    const auto clusters = euclideanClusters(workspace.cloud.points, 0.01, 60);
    // Cluster of each point (-1: none), then of each voxel by its first point's.
    std::vector<int> cluster_of(workspace.cloud.size(), -1);
    for (std::size_t c = 0; c < clusters.size(); ++c) {
      Eigen::AlignedBox3f box;
      for (const int i : clusters[c]) {
        box.extend(workspace.cloud.points[static_cast<std::size_t>(i)]);
      }
      if (label != 0 && box.sizes().norm() > max_extent) {
        continue;  // several objects, or something else
      }
      ++added.examples;
      for (const int i : clusters[c]) {
        cluster_of[static_cast<std::size_t>(i)] = static_cast<int>(c);
      }
    }
    std::vector<int> rows;
    std::vector<bool> taken(voxels.voxels.size(), false);
    for (std::size_t i = 0; i < workspace.cloud.size(); ++i) {
      const int v = voxels.voxel_of_point[i];
      if (cluster_of[i] >= 0 && !taken[static_cast<std::size_t>(v)]) {
        taken[static_cast<std::size_t>(v)] = true;
        rows.push_back(v);
      }
    }
    appendRows(set, voxels.features, rows, label);
    added.voxels += static_cast<int>(rows.size());
  }
  if (add_table) {
    PipelineOptions table_options = options;
    table_options.workspace.min_height = -0.01;
    table_options.workspace.max_height = 0.004;
    WorkspaceCloud table = cropWorkspace(frame, table_options.workspace);
    if (table.cloud.size() >= 10) {
      estimateNormals(frame, table.cloud, options.normal_window, static_cast<float>(options.normal_max_distance));
      const VoxelFeatures voxels = computeFeatures(table.cloud, options.segmentation.features);
      std::vector<int> rows;
      for (std::size_t v = 0; v < voxels.voxels.size(); v += 8) {
        rows.push_back(static_cast<int>(v));
      }
      appendRows(set, voxels.features, rows, 0);
      added.voxels += static_cast<int>(rows.size());
      ++added.examples;
    }
  }
  return added;
}

ExamplesAdded addLabelledExamples(const camera::RgbdFrame& frame, const PipelineOptions& options,
                                  const std::function<int(const Eigen::Vector3d& world_point)>& label_of,
                                  TrainingSet& set, int min_points) {
  ExamplesAdded added;
  WorkspaceCloud workspace = cropWorkspace(frame, options.workspace);
  if (workspace.cloud.size() < 10) {
    return added;
  }
  estimateNormals(frame, workspace.cloud, options.normal_window, static_cast<float>(options.normal_max_distance));
  const VoxelFeatures voxels = computeFeatures(workspace.cloud, options.segmentation.features);
  // Per voxel, how many of its points carry each label.
  std::vector<std::map<int, int>> votes(voxels.voxels.size());
  for (std::size_t i = 0; i < workspace.cloud.size(); ++i) {
    const Eigen::Vector3d world_point = frame.camera_pose * workspace.cloud.points[i].cast<double>();
    ++votes[static_cast<std::size_t>(voxels.voxel_of_point[i])][label_of(world_point)];
  }
  std::map<int, std::vector<int>> rows;  // per label
  for (std::size_t v = 0; v < votes.size(); ++v) {
    const auto best = std::max_element(votes[v].begin(), votes[v].end(),
                                       [](const auto& a, const auto& b) { return a.second < b.second; });
    if (best != votes[v].end() && best->first >= 0 && best->second >= min_points) {
      rows[best->first].push_back(static_cast<int>(v));
    }
  }
  for (const auto& [label, which] : rows) {
    appendRows(set, voxels.features, which, label);
    added.voxels += static_cast<int>(which.size());
    ++added.examples;
  }
  return added;
}

void saveTrainingSet(const TrainingSet& set, const std::filesystem::path& folder) {
  std::filesystem::create_directories(folder);
  nlohmann::json json;
  json["format"] = "costar-perception-examples-1";
  json["rows"] = set.labels.size();
  json["features"] = kFeatureCount;
  json["feature_layout"] =
      "33 FPFH bins / 100, then r/(r+g+b), g/(r+g+b), value, saturation, saturation*cos(hue), "
      "saturation*sin(hue)";
  for (const auto& [label, name] : set.names) {
    json["names"][std::to_string(label)] = name;
    json["counts"][name] = std::count(set.labels.begin(), set.labels.end(), label);
  }
  const Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> rows = set.features;
  writeOutputFile(folder / "features.f32",
                  std::string_view(reinterpret_cast<const char*>(rows.data()), rows.size() * sizeof(float)));
  writeOutputFile(folder / "labels.i32",
                  std::string_view(reinterpret_cast<const char*>(set.labels.data()), set.labels.size() * sizeof(int)));
  writeOutputFile(folder / "dataset.json", json.dump(2) + "\n");  // last: it describes the other two
}

TrainingSet loadTrainingSet(const std::filesystem::path& folder) {
  TrainingSet set;
  std::ifstream header(folder / "dataset.json");
  if (!header) {
    throw std::runtime_error("no training examples in '" + folder.string() +
                             "' (collect them with `costar perception collect`)");
  }
  try {
    const nlohmann::json json = core::readJsonFile(folder / "dataset.json");
    if (json.value("format", "") != "costar-perception-examples-1") {
      throw std::runtime_error("unknown format");
    }
    const auto rows = json.at("rows").get<std::size_t>();
    const int features = json.at("features").get<int>();
    if (features != kFeatureCount) {
      throw std::runtime_error("examples have " + std::to_string(features) + " features, this build computes " +
                               std::to_string(kFeatureCount) + ": collect them again");
    }
    const nlohmann::json names = json.at("names");
    for (const auto& [label, name] : names.items()) {
      set.names[std::stoi(label)] = name.get<std::string>();
    }
    Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> data(static_cast<Eigen::Index>(rows),
                                                                               kFeatureCount);
    std::ifstream feature_stream(folder / "features.f32", std::ios::binary);
    feature_stream.read(reinterpret_cast<char*>(data.data()),
                        static_cast<std::streamsize>(data.size() * sizeof(float)));
    set.labels.resize(rows);
    std::ifstream label_stream(folder / "labels.i32", std::ios::binary);
    label_stream.read(reinterpret_cast<char*>(set.labels.data()), static_cast<std::streamsize>(rows * sizeof(int)));
    if (!feature_stream || !label_stream) {
      throw std::runtime_error("features.f32 or labels.i32 is missing or short");
    }
    set.features = data;
    return set;
  } catch (const std::exception& e) {
    throw std::runtime_error("training examples in '" + folder.string() + "': " + e.what());
  }
}

}  // namespace costar::perception
