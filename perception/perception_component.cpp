#include "perception/perception_component.h"

#include <cmath>
#include <cstdio>

namespace costar::perception {

using component::OperationResult;
using component::ParamSpec;
using component::ValueType;

std::shared_ptr<Pipeline> loadPipeline(const PerceptionConfig& config) {
  PipelineOptions options = config.pipeline;
  options.workspace.table_center =
      config.table_center ? *config.table_center : loadTableCenter(config.files.workspace_file);
  return Pipeline::load(config.files, options);
}

namespace {

std::vector<world::ObjectClass> classesOf(const Pipeline& pipeline) {
  std::vector<world::ObjectClass> classes;
  for (const auto& model : pipeline.models()) {
    classes.push_back(model.object_class);
  }
  return classes;
}

nlohmann::json poseJson(const world::Pose& pose) {
  const Eigen::Vector3d p = pose.translation();
  const Eigen::Vector3d rpy = world::rpyOf(pose.linear()) * 180.0 / M_PI;
  const auto round = [](double value, double step) { return std::round(value / step) * step; };
  return {{"xyz", {round(p.x(), 1e-5), round(p.y(), 1e-5), round(p.z(), 1e-5)}},
          {"rpy_deg", {round(rpy.x(), 1e-3), round(rpy.y(), 1e-3), round(rpy.z(), 1e-3)}}};
}

/// RGB in [0, 1], to 3 decimals.
nlohmann::json colorJson(const Eigen::Vector3f& rgb) {
  const auto round = [](float value) { return std::round(value * 1000.0) / 1000.0; };
  return {round(rgb.x()), round(rgb.y()), round(rgb.z())};
}

}  // namespace

/// Captures frames at the camera's rate across polls, then processes them.
class DetectObjectsOperation final : public component::RunningOperation {
 public:
  DetectObjectsOperation(PerceptionComponent& component, int frames) : component_(component), wanted_(frames) {
    capture();
  }

  OperationResult poll() override {
    if (done_) {
      return *done_;
    }
    const TimePoint now = component_.clock_.now();
    if (static_cast<int>(frames_.size()) < wanted_ && now >= next_capture_) {
      capture();
    }
    if (static_cast<int>(frames_.size()) < wanted_) {
      return OperationResult::running();
    }
    try {
      done_ = component_.process(frames_);
    } catch (const std::exception& e) {
      done_ = OperationResult::failure(std::string("DetectObjects: ") + e.what());
    }
    frames_.clear();
    return *done_;
  }

  void cancel() override {
    frames_.clear();
    done_ = OperationResult::failure("DetectObjects was cancelled");
  }

 private:
  void capture() {
    // The pipeline takes colour from the last frame only (the median filter's output).
    const bool last = static_cast<int>(frames_.size()) + 1 >= wanted_;
    camera::RgbdFrame frame = last ? component_.camera_.capture() : component_.camera_.captureDepth();
    // Each frame is checked as it comes, so a broken camera fails the operation at once: a
    // frame without its pixels, without any valid depth, or one the camera sent before (its
    // stream stopped: the stamp does not advance).
    if (!done_) {
      const std::size_t pixels = static_cast<std::size_t>(frame.intrinsics.width) * frame.intrinsics.height;
      if (frame.points.empty() || frame.points.size() != pixels) {
        done_ = OperationResult::failure("DetectObjects: the camera sent an empty frame");
      } else if (!frame.anyValid()) {
        done_ = OperationResult::failure(
            "DetectObjects: the camera sent a frame without any valid depth (is it covered, broken, or not looking "
            "at the table?)");
      } else if (!frames_.empty() && frame.stamp <= frames_.back().stamp) {
        done_ = OperationResult::failure(
            "DetectObjects: the camera stopped sending new frames (the frame's stamp did not advance)");
      }
    }
    if (component_.config_.camera_pose) {
      frame.camera_pose = component_.config_.camera_pose();
    }
    frames_.push_back(std::move(frame));
    next_capture_ = component_.clock_.now() + component_.camera_.framePeriod();
  }

  PerceptionComponent& component_;
  int wanted_;
  std::vector<camera::RgbdFrame> frames_;
  TimePoint next_capture_{};
  std::optional<OperationResult> done_;
};

PerceptionComponent::PerceptionComponent(camera::RgbdCamera& camera, const Clock& clock, PerceptionConfig config)
    : PerceptionComponent(camera, clock, loadPipeline(config), config) {}

PerceptionComponent::PerceptionComponent(camera::RgbdCamera& camera, const Clock& clock,
                                         std::shared_ptr<Pipeline> pipeline, PerceptionConfig config)
    : camera_(camera),
      clock_(clock),
      config_(std::move(config)),
      pipeline_(std::move(pipeline)),
      persistence_(classesOf(*pipeline_), config_.persistence) {
  component::ComponentDescription description;
  description.name = config_.name;
  description.type = "CostarPerception";
  description.inputs = {"rgbd_frames"};
  description.outputs = {"detections"};
  ParamSpec frames{"frames", ValueType::kInt,
                   "frames to capture at the camera's rate; their per-pixel median is processed",
                   static_cast<long long>(config_.frames)};
  frames.min = 1;
  frames.max = 60;
  component::OperationTable operations;
  operations.add({"DetectObjects",
                  "Looks at the workspace with the RGB-D camera and updates the known objects: a frame symbol per "
                  "object (names kept across detections), is_a(object, class) and visible(object).",
                  {frames},
                  component::OperationKind::kKnowledge},
                 [this](const component::ParamMap& params) {
                   const auto it = params.find("frames");
                   const int count = it != params.end() ? static_cast<int>(it->second.asInt()) : config_.frames;
                   return std::make_unique<DetectObjectsOperation>(*this, std::clamp(count, 1, 60));
                 });
  for (const auto& model : pipeline_->models()) {
    description.symbols.push_back({model.name(), world::SymbolKind::kObjectClass,
                                   "object class " + model.name() + ": " + model.object_class.description});
  }
  description.symbols.push_back({"<class>_<n>", world::SymbolKind::kFrame,
                                 "a detected object's frame in the world (e.g. node_3), canonical orientation"});
  description.predicates = {{"is_a", 2, "is_a(object, class): the detected object is of that class"},
                            {"visible", 1, "visible(object): the latest DetectObjects saw the object"}};
  declare(std::move(description), std::move(operations));
}

OperationResult PerceptionComponent::process(const std::vector<camera::RgbdFrame>& frames) {
  PipelineResult result = pipeline_->detect(frames);
  std::lock_guard lock(mutex_);
  std::vector<std::string> before;
  for (const auto& object : persistence_.objects()) {
    before.push_back(object.name);
  }
  const std::vector<TrackedObject>& objects = persistence_.update(result.detections);
  last_stamp_ = clock_.now();
  nlohmann::json list = nlohmann::json::array();
  nlohmann::json fresh = nlohmann::json::array();
  std::vector<std::string> now;
  for (const auto& object : objects) {
    now.push_back(object.name);
    list.push_back({{"name", object.name},
                    {"class", object.object_class},
                    {"pose", poseJson(object.pose)},
                    {"confidence", std::round(object.confidence * 1000.0) / 1000.0},
                    {"visible", object.missed == 0}});
    if (object.color) {
      list.back()["color"] = colorJson(*object.color);
    }
    if (std::find(before.begin(), before.end(), object.name) == before.end()) {
      fresh.push_back(object.name);
    }
  }
  nlohmann::json dropped = nlohmann::json::array();
  for (const auto& name : before) {
    if (std::find(now.begin(), now.end(), name) == now.end()) {
      dropped.push_back(name);
    }
  }
  const StageTimes& t = result.times;
  const auto ms = [](double seconds) { return std::round(seconds * 1e4) / 10.0; };
  nlohmann::json data = {{"objects", list},
                         {"new", fresh},
                         {"dropped", dropped},
                         {"frames", frames.size()},
                         {"latency_ms",
                          {{"median", ms(t.median)},
                           {"crop", ms(t.crop)},
                           {"normals", ms(t.normals)},
                           {"features", ms(t.features)},
                           {"classification", ms(t.classification)},
                           {"pose", ms(t.pose)},
                           {"total", ms(t.total)}}}};
  last_result_ = std::move(result);
  return OperationResult::success(std::move(data));
}

void PerceptionComponent::checkCamera() const {
  if (config_.camera_max_age <= Duration::zero()) {
    return;
  }
  std::optional<camera::StreamStatus> status;
  try {
    status = camera_.streamStatus();
  } catch (const std::exception& e) {
    throw std::runtime_error(std::string("the camera's stream failed: ") + e.what());
  }
  if (!status) {
    return;  // this camera cannot tell: its frames are checked as they are taken
  }
  if (status->points == 0) {
    throw std::runtime_error("the camera sends empty frames (no pixels)");
  }
  if (status->valid == 0) {
    throw std::runtime_error(
        "the camera sends frames without any valid depth (is it covered, broken, or not looking at the table?)");
  }
  const Duration age = clock_.now() - status->stamp;
  if (age > config_.camera_max_age) {
    char text[160];
    std::snprintf(text, sizeof text, "the camera stopped sending frames: the newest is %.3f s old (limit %.3f s)",
                  toSeconds(age), toSeconds(config_.camera_max_age));
    throw std::runtime_error(text);
  }
}

world::Report PerceptionComponent::report() const {
  checkCamera();
  std::lock_guard lock(mutex_);
  world::Report report;
  for (const auto& model : pipeline_->models()) {
    world::Symbol symbol;
    symbol.name = model.name();
    symbol.stamp = last_stamp_;
    symbol.value = world::ObjectClassValue{model.object_class.description};
    report.symbols.push_back(std::move(symbol));
  }
  for (const auto& object : persistence_.objects()) {
    world::Symbol symbol;
    symbol.name = object.name;
    symbol.stamp = last_stamp_;
    symbol.value = world::FrameValue{"world", object.pose};
    if (object.color) {
      symbol.color = object.color->cast<double>();
    }
    report.symbols.push_back(std::move(symbol));
    if (object.missed == 0) {
      report.predicates.push_back({"is_a", {object.name, object.object_class}, true, ""});
      report.predicates.push_back({"visible", {object.name}, true, ""});
    }
  }
  return report;
}

std::vector<TrackedObject> PerceptionComponent::objects() const {
  std::lock_guard lock(mutex_);
  return persistence_.objects();
}

std::optional<PipelineResult> PerceptionComponent::lastResult() const {
  std::lock_guard lock(mutex_);
  return last_result_;
}

}  // namespace costar::perception
