#include "perception/pipeline.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <stdexcept>
#include <thread>

#include "core/paths.h"
#include "perception/median_filter.h"

namespace costar::perception {

namespace {

/// Leftover points of a class's cluster handed to a neighbouring cluster of another class: at
/// least this many, within this distance (m) of it. The task number that seeds its search is
/// offset by kHandOverTask.
constexpr std::size_t kHandOverPoints = 150;
constexpr double kHandOverTouch = 0.01;
constexpr std::uint32_t kHandOverTask = 1000;
/// Leftover points with no such cluster beside them: at least this many, their lowest resting
/// on another part (lowHeight() above kRaisedSupport), are searched as a cluster of each other
/// class.
constexpr std::size_t kHandOverAlonePoints = 400;

/// Appends `indices` of `from` to `into` and their new indices to `cluster`.
void gather(const Cloud& from, const std::vector<int>& indices, Cloud& into, std::vector<int>& cluster) {
  for (const int i : indices) {
    cluster.push_back(static_cast<int>(into.size()));
    into.append(from, static_cast<std::size_t>(i));
  }
}

double since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

PipelineFiles PipelineFiles::under(const std::filesystem::path& root) {
  const std::filesystem::path base = root.empty() ? dataRoot() : root;
  return {base / "data" / "objects", base / "data" / "perception" / "classes.json",
          base / "data" / "perception" / "svm" / "ur5-sim.json", base / "data" / "perception" / "workspace.json"};
}

void measureColors(const std::vector<ObjectModel>& models, const std::vector<Cloud>& class_points,
                   std::vector<Detection>& detections, double margin) {
  for (Detection& detection : detections) {
    detection.color.reset();
    const auto model = std::find_if(models.begin(), models.end(),
                                    [&](const ObjectModel& m) { return m.name() == detection.object_class; });
    const auto m = static_cast<std::size_t>(model - models.begin());
    if (model == models.end() || m >= class_points.size()) {
      continue;
    }
    const Cloud& points = class_points[m];
    if (points.colors.size() != points.size()) {
      continue;
    }
    const Eigen::Isometry3d to_object = detection.pose_in_camera.inverse();
    const double reach = model->radius + margin;
    const Eigen::Vector3d origin = detection.pose_in_camera.translation();
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    int count = 0;
    for (std::size_t i = 0; i < points.size(); ++i) {
      const Eigen::Vector3d p = points.points[i].cast<double>();
      if ((p - origin).squaredNorm() > reach * reach) {
        continue;
      }
      const Eigen::Vector3d q = to_object * p;
      const bool inside = std::any_of(
          model->object_class.boxes.begin(), model->object_class.boxes.end(),
          [&](const world::Box& box) { return ((q - box.center).cwiseAbs() - box.half_size).maxCoeff() <= margin; });
      if (inside) {
        const Rgb& c = points.colors[i];
        sum += Eigen::Vector3d(c[0], c[1], c[2]);
        ++count;
      }
    }
    if (count > 0) {
      detection.color = (sum / (255.0 * count)).cast<float>();
    }
  }
}

/// One ClassPoseEstimator per class and worker thread.
struct Pipeline::Workers {
  std::vector<std::vector<std::unique_ptr<ClassPoseEstimator>>> estimators;  // [thread][model]
};

Pipeline::Pipeline(std::vector<ObjectModel> models, SvmClassifier classifier, PipelineOptions options)
    : models_(std::move(models)),
      classifier_(std::move(classifier)),
      options_(options),
      workers_(std::make_unique<Workers>()) {
  if (models_.empty()) {
    throw std::runtime_error("perception: no object classes");
  }
  if (classifier_.empty()) {
    throw std::runtime_error("perception: the SVM is empty (train one with `costar perception train`)");
  }
  for (const auto& model : models_) {
    const int label = classifier_.labelOf(model.name());
    if (label <= 0) {
      throw std::runtime_error("perception: the SVM was not trained on class '" + model.name() +
                               "' (run `costar perception collect` and `costar perception train`)");
    }
    label_of_model_.push_back(label);
  }
  options_.threads = std::clamp(options_.threads, 1, 8);
  options_.segmentation.features.threads = options_.threads;
  workers_->estimators.resize(static_cast<std::size_t>(options_.threads));
  for (auto& per_thread : workers_->estimators) {
    for (const auto& model : models_) {
      per_thread.push_back(std::make_unique<ClassPoseEstimator>(model, options_.pose));
    }
  }
}

Pipeline::~Pipeline() = default;

std::unique_ptr<Pipeline> Pipeline::load(const PipelineFiles& files, PipelineOptions options) {
  std::vector<ObjectModel> models = loadObjectModels(files.objects_dir, files.classes_file);
  SvmClassifier classifier = SvmClassifier::load(files.svm_file);
  return std::make_unique<Pipeline>(std::move(models), std::move(classifier), options);
}

const ObjectModel* Pipeline::model(const std::string& name) const {
  for (const auto& model : models_) {
    if (model.name() == name) {
      return &model;
    }
  }
  return nullptr;
}

PipelineResult Pipeline::detect(std::span<const camera::RgbdFrame> frames) {
  if (frames.empty()) {
    throw std::invalid_argument("DetectObjects needs at least one frame");
  }
  const auto start = std::chrono::steady_clock::now();
  const camera::RgbdFrame& last = frames.back();
  const std::vector<std::uint8_t> mask = workspaceMask(frames, options_.workspace);
  auto filtered = std::make_shared<camera::RgbdFrame>(medianFrame(frames, mask, options_.threads));
  // The depth check needs the surroundings too (the table around an object): outside the
  // mask, the last frame's own readings.
  camera::RgbdFrame reference = *filtered;
  for (std::size_t pixel = 0; pixel < mask.size(); ++pixel) {
    if (mask[pixel] == 0) {
      reference.points[pixel] = last.points[pixel];
    }
  }
  const double median = since(start);
  PipelineResult result = detectFiltered(*filtered, &reference);
  result.filtered = std::move(filtered);
  result.times.median = median;
  result.times.total = since(start);
  return result;
}

PipelineResult Pipeline::detectFiltered(const camera::RgbdFrame& frame, const camera::RgbdFrame* depth_reference) {
  const camera::RgbdFrame& reference = depth_reference != nullptr ? *depth_reference : frame;
  PipelineResult result;
  auto start = std::chrono::steady_clock::now();
  const auto begin = start;
  WorkspaceCloud workspace = cropWorkspace(frame, options_.workspace);
  result.times.crop = since(start);
  result.workspace_points = static_cast<int>(workspace.cloud.size());

  start = std::chrono::steady_clock::now();
  estimateNormals(frame, workspace.cloud, options_.normal_window, static_cast<float>(options_.normal_max_distance));
  result.times.normals = since(start);

  SegmentationResult segmentation = segmentPoints(workspace.cloud, classifier_, options_.segmentation);
  if (options_.segmentation.grow_reach > 0.0) {
    const auto grow_start = std::chrono::steady_clock::now();
    segmentation.labels =
        growLabels(workspace.cloud, frame.intrinsics.width, frame.intrinsics.height, std::move(segmentation.labels),
                   options_.segmentation.grow_step, options_.segmentation.grow_reach);
    segmentation.classification_seconds += since(grow_start);
  }
  result.times.features = segmentation.feature_seconds;
  result.times.classification = segmentation.classification_seconds;
  for (const int label : classifier_.labels()) {
    const auto count = std::count(segmentation.labels.begin(), segmentation.labels.end(), label);
    result.points_per_label.emplace_back(label, static_cast<int>(count));
  }

  // Stage 4: one task per (class, cluster), biggest first over the worker threads.
  start = std::chrono::steady_clock::now();
  std::vector<Cloud> class_points(models_.size());
  for (std::size_t i = 0; i < workspace.cloud.size(); ++i) {
    for (std::size_t m = 0; m < models_.size(); ++m) {
      if (segmentation.labels[i] == label_of_model_[m]) {
        class_points[m].append(workspace.cloud, i);
      }
    }
  }
  struct Task {
    std::size_t model = 0;
    std::uint32_t index = 0;  // cluster number within the class: seeds the task
    std::vector<int> cluster;
    std::vector<Detection> found;
    ClassPoseEstimator::Timing timing;
  };
  std::vector<Task> tasks;
  for (std::size_t m = 0; m < models_.size(); ++m) {
    const auto clusters = workers_->estimators[0][m]->clusters(class_points[m], frame.intrinsics);
    for (std::size_t c = 0; c < clusters.size(); ++c) {
      tasks.push_back({m, static_cast<std::uint32_t>(c), clusters[c], {}, {}});
    }
  }
  std::vector<std::size_t> order(tasks.size());
  for (std::size_t i = 0; i < order.size(); ++i) {
    order[i] = i;
  }
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return tasks[a].cluster.size() > tasks[b].cluster.size(); });
  for (auto& per_thread : workers_->estimators) {
    for (auto& estimator : per_thread) {
      estimator->setSupportPlane(workspace.plane);
    }
  }
  std::atomic<std::size_t> next{0};
  const auto work = [&](std::size_t thread) {
    for (std::size_t i = next++; i < order.size(); i = next++) {
      Task& task = tasks[order[i]];
      task.found = workers_->estimators[thread][task.model]->estimateCluster(class_points[task.model], task.cluster,
                                                                             reference, task.index, &task.timing);
    }
  };
  {
    const std::size_t threads =
        std::min<std::size_t>(workers_->estimators.size(), std::max<std::size_t>(1, tasks.size()));
    std::vector<std::thread> helpers;
    for (std::size_t t = 1; t < threads; ++t) {
      helpers.emplace_back(work, t);
    }
    work(0);
    for (auto& helper : helpers) {
      helper.join();
    }
  }
  // A cluster's points that its class's detections leave unexplained, lying against a cluster
  // of another class where nothing was found, may be that class's: a grey link lying across a
  // node, seen side-on, is mostly labelled node, and its own few points fit no link. That class
  // looks again at its cluster with those points added.
  {
    const double touch = kHandOverTouch * kHandOverTouch;
    const std::size_t task_count = tasks.size();
    std::vector<Task> added;
    for (std::size_t a = 0; a < task_count; ++a) {
      const std::vector<int> leftover = workers_->estimators[0][tasks[a].model]->unexplainedPoints(
          class_points[tasks[a].model], tasks[a].cluster, tasks[a].found);
      if (leftover.size() < kHandOverPoints) {
        continue;
      }
      const Cloud& from = class_points[tasks[a].model];
      bool handed = false;
      for (std::size_t b = 0; b < task_count; ++b) {
        Task& other = tasks[b];
        if (other.model == tasks[a].model || !other.found.empty()) {
          continue;
        }
        const Cloud& own = class_points[other.model];
        const bool touching = std::any_of(leftover.begin(), leftover.end(), [&](int i) {
          const Eigen::Vector3f& p = from.points[static_cast<std::size_t>(i)];
          return std::any_of(other.cluster.begin(), other.cluster.end(), [&](int j) {
            return (own.points[static_cast<std::size_t>(j)] - p).squaredNorm() <= touch;
          });
        });
        if (!touching) {
          continue;
        }
        Cloud joined;
        std::vector<int> cluster;
        gather(own, other.cluster, joined, cluster);
        gather(from, leftover, joined, cluster);
        other.found = workers_->estimators[0][other.model]->estimateCluster(joined, cluster, reference,
                                                                            other.index + kHandOverTask, &other.timing);
        handed = true;
      }
      // No such cluster beside them: a whole part lying on another may have been labelled the
      // other's class. Many leftover points, all well above the table, are searched as a cluster
      // of each other class.
      if (handed || leftover.size() < kHandOverAlonePoints ||
          lowHeight(from, leftover, workspace.plane) < kRaisedSupport) {
        continue;
      }
      Cloud alone;
      std::vector<int> cluster;
      gather(from, leftover, alone, cluster);
      for (std::size_t m = 0; m < models_.size(); ++m) {
        if (m == tasks[a].model) {
          continue;
        }
        Task task{m, tasks[a].index + 2 * kHandOverTask, {}, {}, {}};
        task.found = workers_->estimators[0][m]->estimateCluster(alone, cluster, reference, task.index, &task.timing);
        if (!task.found.empty()) {
          added.push_back(std::move(task));
        }
      }
    }
    for (Task& task : added) {
      tasks.push_back(std::move(task));
    }
  }
  // Touching parts of a class: each refined on its own points; then levelled where it rests.
  // The classes are independent: one per worker thread (each thread's own estimators).
  std::vector<std::vector<Detection>> of_class(models_.size());
  for (const Task& task : tasks) {
    of_class[task.model].insert(of_class[task.model].end(), task.found.begin(), task.found.end());
  }
  {
    const std::size_t threads = std::min(workers_->estimators.size(), models_.size());
    const auto refine = [&](std::size_t thread) {
      for (std::size_t m = thread; m < models_.size(); m += threads) {
        workers_->estimators[thread][m]->refineTouching(class_points[m], of_class[m], reference);
        workers_->estimators[thread][m]->levelResting(of_class[m], reference);
      }
    };
    std::vector<std::thread> helpers;
    for (std::size_t t = 1; t < threads; ++t) {
      helpers.emplace_back(refine, t);
    }
    refine(0);
    for (auto& helper : helpers) {
      helper.join();
    }
  }
  std::vector<Detection> found;
  for (const auto& detections : of_class) {
    found.insert(found.end(), detections.begin(), detections.end());
  }
  for (const Task& task : tasks) {
    result.times.recognition += task.timing.recognition;
    result.times.refinement += task.timing.refinement;
    result.pose_runs += task.timing.runs;
    result.pose_candidates += task.timing.candidates;
    result.pose_checked += task.timing.checked;
  }
  result.pose_clusters = static_cast<int>(tasks.size());
  found = mergeDetections(std::move(found), models_);
  // Clusters where nothing was found: a part hidden under another but for its sides (a node
  // under the link put across it) still holds that one up.
  std::vector<std::vector<Eigen::Vector3f>> unfound;
  for (const Task& task : tasks) {
    if (task.found.empty()) {
      std::vector<Eigen::Vector3f>& points = unfound.emplace_back();
      points.reserve(task.cluster.size());
      for (const int i : task.cluster) {
        points.push_back(class_points[task.model].points[static_cast<std::size_t>(i)]);
      }
    }
  }
  found = keepSupported(found, models_, workspace.plane, options_.support_tolerance, unfound);
  // Class order, then best first.
  std::stable_sort(found.begin(), found.end(), [this](const Detection& a, const Detection& b) {
    const auto index = [this](const std::string& name) {
      for (std::size_t m = 0; m < models_.size(); ++m) {
        if (models_[m].name() == name) {
          return m;
        }
      }
      return models_.size();
    };
    return index(a.object_class) < index(b.object_class);
  });
  measureColors(models_, class_points, found, options_.color_margin);
  for (Detection& detection : found) {
    detection.pose = frame.camera_pose * detection.pose_in_camera;
  }
  result.detections = std::move(found);
  result.workspace = std::move(workspace.cloud);
  result.labels = segmentation.labels;
  result.times.pose = since(start);
  result.times.total = since(begin);
  return result;
}

}  // namespace costar::perception
