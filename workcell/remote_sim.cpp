#include "workcell/remote_sim.h"

#include <algorithm>
#include <cstring>
#include <optional>
#include <stdexcept>

#include "dds/remote_component.h"
#include "perception/perception_component.h"
#include "perception/pipeline.h"
#include "perception/workspace.h"
#include "workcell/grippers.h"
#include "workcell/sim_cell_description.h"

namespace costar::workcell {
namespace {

std::int64_t nanoseconds(TimePoint t) {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(t.time_since_epoch()).count();
}

TimePoint timePoint(const nlohmann::json& ns) { return TimePoint(std::chrono::nanoseconds(ns.get<std::int64_t>())); }

/// A pose as its 4x4 matrix, row by row (JSON numbers keep a double to the bit).
nlohmann::json poseJson(const world::Pose& pose) {
  nlohmann::json rows = nlohmann::json::array();
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) {
      rows.push_back(pose.matrix()(r, c));
    }
  }
  return rows;
}

world::Pose poseFromJson(const nlohmann::json& rows) {
  world::Pose pose = world::Pose::Identity();
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) {
      pose.matrix()(r, c) = rows.at(static_cast<std::size_t>(r * 4 + c)).get<double>();
    }
  }
  return pose;
}

dds::DriverReply frameReply(const camera::RgbdFrame& frame, const world::Pose& seen_from) {
  dds::DriverReply reply;
  reply.result = {{"stamp_ns", nanoseconds(frame.stamp)},
                  {"camera_pose", poseJson(seen_from)},
                  {"width", frame.rgb.width},
                  {"height", frame.rgb.height}};
  reply.floats.reserve(frame.points.size() * 3);
  for (const Eigen::Vector3f& point : frame.points) {
    reply.floats.insert(reply.floats.end(), {point.x(), point.y(), point.z()});
  }
  reply.bytes = frame.rgb.pixels;
  return reply;
}

/// The gripper's fingers in the executor's simulator.
class RemoteGripperDriver final : public gripper::GripperDriver {
 public:
  RemoteGripperDriver(dds::SimulatorLink& link, double stroke) : link_(link), stroke_(stroke) {}
  gripper::FingerReading read() const override {
    const nlohmann::json reading = link_.call("gripper", "read", nlohmann::json::object()).result;
    return {reading.at("opening").get<double>(), reading.at("opening_speed").get<double>(),
            reading.at("force").get<double>(), reading.at("contact").get<bool>(), timePoint(reading.at("stamp_ns"))};
  }
  void command(double opening, double speed, double force) override {
    link_.call("gripper", "command", {{"opening", opening}, {"speed", speed}, {"force", force}});
  }
  /// The simulator's (read back from its finger servo); before the first run, the stroke of
  /// the gripper's description (the component's description is made before any executor joins).
  double maxOpening() const override {
    if (!link_.hasExecutor()) {
      return stroke_;
    }
    return link_.call("gripper", "max_opening", nlohmann::json::object()).result.get<double>();
  }

 private:
  dds::SimulatorLink& link_;
  double stroke_;
};

/// A 3-finger adaptive gripper's fingers and scissor axis in the executor's simulator.
class RemoteAdaptiveGripperDriver final : public gripper::AdaptiveGripperDriver {
 public:
  explicit RemoteAdaptiveGripperDriver(dds::SimulatorLink& link) : link_(link) {}
  gripper::AdaptiveGripperReading read() const override {
    const nlohmann::json json = link_.call("adaptive_gripper", "read", nlohmann::json::object()).result;
    gripper::AdaptiveGripperReading reading;
    for (std::size_t i = 0; i < reading.fingers.size(); ++i) {
      const nlohmann::json& finger = json.at("fingers").at(i);
      reading.fingers[i] = {finger.at("position").get<double>(), finger.at("speed").get<double>(),
                            finger.at("force").get<double>(), finger.at("contact").get<bool>()};
    }
    const std::string mode = json.at("mode").get<std::string>();
    const std::optional<gripper::GripperMode> known = gripper::modeFromString(mode);
    if (!known) {
      throw std::runtime_error("adaptive_gripper read: unknown mode '" + mode + "'");
    }
    reading.mode = *known;
    reading.mode_reached = json.at("mode_reached").get<bool>();
    reading.stamp = timePoint(json.at("stamp_ns"));
    return reading;
  }
  void commandFingers(const std::array<double, gripper::kFingerCount>& positions, double speed, double force) override {
    link_.call("adaptive_gripper", "command_fingers", {{"positions", positions}, {"speed", speed}, {"force", force}});
  }
  void commandMode(gripper::GripperMode mode) override {
    link_.call("adaptive_gripper", "command_mode", {{"mode", gripper::toString(mode)}});
  }

 private:
  dds::SimulatorLink& link_;
};

/// The executor's simulated camera; each frame carries the pose the executor's calibration
/// gives the camera.
class RemoteCamera final : public camera::RgbdCamera {
 public:
  explicit RemoteCamera(dds::SimulatorLink& link) : link_(link) {}
  std::string name() const override { return info().name; }
  const camera::Intrinsics& intrinsics() const override { return info().intrinsics; }
  Duration framePeriod() const override { return info().frame_period; }
  camera::RgbdFrame capture() override { return frame("capture"); }
  camera::RgbdFrame captureDepth() override { return frame("capture_depth"); }
  std::optional<camera::StreamStatus> streamStatus() override {
    const nlohmann::json status = link_.call("camera", "stream_status", nlohmann::json::object()).result;
    if (status.is_null()) {
      return std::nullopt;
    }
    return camera::StreamStatus{timePoint(status.at("stamp_ns")), status.at("points").get<std::size_t>(),
                                status.at("valid").get<std::size_t>()};
  }

 private:
  struct Info {
    std::string name;
    camera::Intrinsics intrinsics;
    Duration frame_period{};
  };
  const Info& info() const {
    if (!info_) {
      const nlohmann::json json = link_.call("camera", "info", nlohmann::json::object()).result;
      Info info;
      info.name = json.at("name").get<std::string>();
      info.intrinsics.width = json.at("width").get<int>();
      info.intrinsics.height = json.at("height").get<int>();
      info.intrinsics.fx = json.at("fx").get<double>();
      info.intrinsics.fy = json.at("fy").get<double>();
      info.intrinsics.cx = json.at("cx").get<double>();
      info.intrinsics.cy = json.at("cy").get<double>();
      info.frame_period = std::chrono::nanoseconds(json.at("frame_period_ns").get<std::int64_t>());
      info_ = std::move(info);
    }
    return *info_;
  }
  camera::RgbdFrame frame(const std::string& method) {
    dds::DriverReply reply = link_.call("camera", method, nlohmann::json::object());
    camera::RgbdFrame frame;
    frame.intrinsics = intrinsics();
    frame.stamp = timePoint(reply.result.at("stamp_ns"));
    frame.camera_pose = poseFromJson(reply.result.at("camera_pose"));
    if (reply.floats.size() % 3 != 0) {
      throw std::runtime_error("camera " + method + ": " + std::to_string(reply.floats.size()) +
                               " coordinates, not 3 per point");
    }
    frame.points.resize(reply.floats.size() / 3);
    for (std::size_t i = 0; i < frame.points.size(); ++i) {
      frame.points[i] = {reply.floats[3 * i], reply.floats[3 * i + 1], reply.floats[3 * i + 2]};
    }
    frame.rgb.width = reply.result.at("width").get<int>();
    frame.rgb.height = reply.result.at("height").get<int>();
    frame.rgb.pixels = std::move(reply.bytes);
    return frame;
  }

  dds::SimulatorLink& link_;
  mutable std::optional<Info> info_;
};

/// The camera, publishing each frame taken as ROS 2 images.
class ImagePublishingCamera final : public camera::RgbdCamera {
 public:
  ImagePublishingCamera(camera::RgbdCamera& inner, dds::RemoteClient& client, std::string frame_id)
      : inner_(inner), client_(client), frame_id_(std::move(frame_id)) {}
  std::string name() const override { return inner_.name(); }
  const camera::Intrinsics& intrinsics() const override { return inner_.intrinsics(); }
  Duration framePeriod() const override { return inner_.framePeriod(); }
  camera::RgbdFrame capture() override { return published(inner_.capture()); }
  camera::RgbdFrame captureDepth() override { return published(inner_.captureDepth()); }
  std::optional<camera::StreamStatus> streamStatus() override { return inner_.streamStatus(); }

 private:
  camera::RgbdFrame published(camera::RgbdFrame frame) {
    const auto width = static_cast<std::uint32_t>(frame.intrinsics.width);
    const auto height = static_cast<std::uint32_t>(frame.intrinsics.height);
    dds::ImageSample color;
    if (!frame.rgb.pixels.empty()) {
      color = {frame.stamp,
               frame_id_,
               static_cast<std::uint32_t>(frame.rgb.width),
               static_cast<std::uint32_t>(frame.rgb.height),
               "rgb8",
               static_cast<std::uint32_t>(frame.rgb.width) * 3,
               frame.rgb.pixels};
    }
    dds::ImageSample depth{frame.stamp, frame_id_, width, height, "32FC1", width * 4, {}};
    depth.data.resize(frame.points.size() * sizeof(float));
    for (std::size_t i = 0; i < frame.points.size(); ++i) {
      const float z = frame.points[i].z();
      std::memcpy(depth.data.data() + i * sizeof(float), &z, sizeof(float));
    }
    client_.publishImages(color, depth);
    return frame;
  }

  camera::RgbdCamera& inner_;
  dds::RemoteClient& client_;
  std::string frame_id_;
};

}  // namespace

std::unique_ptr<camera::RgbdCamera> imagePublishingCamera(camera::RgbdCamera& camera, dds::RemoteClient& client,
                                                          std::string frame_id) {
  return std::make_unique<ImagePublishingCamera>(camera, client, std::move(frame_id));
}

const std::vector<std::string>& remotableSimComponents() {
  static const std::vector<std::string> kNames = {"gripper", "perception"};
  return kNames;
}

const std::vector<dds::DriverReading>& simDriverReadings() {
  static const std::vector<dds::DriverReading> kReadings = {{"gripper", "read"},
                                                            {"gripper", "max_opening"},
                                                            {"adaptive_gripper", "read"},
                                                            {"camera", "info"},
                                                            {"camera", "stream_status"}};
  return kReadings;
}

dds::DriverServer simDriverServer(gripper::GripperDriver* gripper, gripper::AdaptiveGripperDriver* adaptive,
                                  camera::RgbdCamera& camera, std::function<world::Pose()> camera_pose) {
  return [gripper, adaptive, &camera, camera_pose = std::move(camera_pose)](
             const std::string& driver, const std::string& method, const nlohmann::json& args) -> dds::DriverReply {
    if (driver == "adaptive_gripper" && adaptive != nullptr) {
      if (method == "read") {
        const gripper::AdaptiveGripperReading reading = adaptive->read();
        nlohmann::json fingers = nlohmann::json::array();
        for (const gripper::AdaptiveFingerReading& finger : reading.fingers) {
          fingers.push_back({{"position", finger.position},
                             {"speed", finger.speed},
                             {"force", finger.force},
                             {"contact", finger.contact}});
        }
        return {{{"fingers", fingers},
                 {"mode", gripper::toString(reading.mode)},
                 {"mode_reached", reading.mode_reached},
                 {"stamp_ns", nanoseconds(reading.stamp)}}};
      }
      if (method == "command_fingers") {
        adaptive->commandFingers(args.at("positions").get<std::array<double, gripper::kFingerCount>>(),
                                 args.at("speed").get<double>(), args.at("force").get<double>());
        return {nlohmann::json::object()};
      }
      if (method == "command_mode") {
        const std::string mode = args.at("mode").get<std::string>();
        const std::optional<gripper::GripperMode> known = gripper::modeFromString(mode);
        if (!known) {
          throw std::invalid_argument("adaptive_gripper command_mode: unknown mode '" + mode + "'");
        }
        adaptive->commandMode(*known);
        return {nlohmann::json::object()};
      }
    }
    if (driver == "gripper" && gripper != nullptr) {
      if (method == "read") {
        const gripper::FingerReading reading = gripper->read();
        return {{{"opening", reading.opening},
                 {"opening_speed", reading.opening_speed},
                 {"force", reading.force},
                 {"contact", reading.contact},
                 {"stamp_ns", nanoseconds(reading.stamp)}}};
      }
      if (method == "command") {
        gripper->command(args.at("opening").get<double>(), args.at("speed").get<double>(),
                         args.at("force").get<double>());
        return {nlohmann::json::object()};
      }
      if (method == "max_opening") {
        return {gripper->maxOpening()};
      }
    }
    if (driver == "camera") {
      if (method == "info") {
        const camera::Intrinsics& in = camera.intrinsics();
        return {{{"name", camera.name()},
                 {"width", in.width},
                 {"height", in.height},
                 {"fx", in.fx},
                 {"fy", in.fy},
                 {"cx", in.cx},
                 {"cy", in.cy},
                 {"frame_period_ns", std::chrono::nanoseconds(camera.framePeriod()).count()}}};
      }
      if (method == "capture" || method == "capture_depth") {
        const camera::RgbdFrame frame = method == "capture" ? camera.capture() : camera.captureDepth();
        return frameReply(frame, camera_pose ? camera_pose() : frame.camera_pose);
      }
      if (method == "stream_status") {
        const std::optional<camera::StreamStatus> status = camera.streamStatus();
        if (!status) {
          return {nullptr};
        }
        return {{{"stamp_ns", nanoseconds(status->stamp)}, {"points", status->points}, {"valid", status->valid}}};
      }
    }
    throw std::invalid_argument("the simulator has no driver call '" + driver + " " + method + "'");
  };
}

struct RemoteSimComponents::State {
  explicit State(dds::SimulatorLink& simulator) : link(simulator), camera(simulator) {}

  dds::SimulatorLink& link;
  std::vector<std::string> names;
  const GripperModel* gripper_model = nullptr;
  std::optional<RemoteGripperDriver> gripper;
  std::optional<RemoteAdaptiveGripperDriver> adaptive;
  RemoteCamera camera;
  perception::PerceptionConfig perception_config;
  std::shared_ptr<perception::Pipeline> pipeline;
};

RemoteSimComponents::RemoteSimComponents(const std::string& cell_name, const std::vector<std::string>& names,
                                         dds::SimulatorLink& link)
    : state_(std::make_unique<State>(link)) {
  const SimCellDescription cell = loadSimCellDescription(simCellFile(cell_name));
  for (const std::string& name : names) {
    const auto& known = remotableSimComponents();
    if (std::find(known.begin(), known.end(), name) == known.end()) {
      throw std::invalid_argument("component '" + name + "' of " + cell_name +
                                  " cannot run in a host yet (gripper and perception can: the others share the "
                                  "cell's planner, world or simulation)");
    }
    if (name == "gripper") {
      state_->gripper_model = &gripperModel(cell.gripper);
      if (!state_->gripper_model->adaptive.empty()) {
        state_->adaptive.emplace(link);
      } else {
        const std::optional<double> stroke = state_->gripper_model->geometry->stroke();
        if (!stroke) {
          throw std::invalid_argument("the gripper of " + cell_name + " ('" + cell.gripper + "') has no stroke");
        }
        state_->gripper.emplace(link, *stroke);
      }
    }
    if (name == "perception") {
      perception::PerceptionConfig& config = state_->perception_config;
      config.table_center = perception::loadTableCenter(perception::PipelineFiles::under().workspace_file);
      if (!cell.perception_model.empty()) {
        config.files.svm_file = cell.perception_model;
      }
      // The frames come seen from the executor's calibrated camera pose: config.camera_pose stays empty.
      state_->pipeline = perception::loadPipeline(config);
    }
  }
  state_->names = names;
}

RemoteSimComponents::~RemoteSimComponents() = default;

std::vector<std::shared_ptr<component::Component>> RemoteSimComponents::make() {
  State& state = *state_;
  std::vector<std::shared_ptr<component::Component>> made;
  for (const std::string& name : state.names) {
    if (name == "gripper") {
      GripperDrivers drivers;
      drivers.parallel = state.gripper ? &*state.gripper : nullptr;
      drivers.adaptive = state.adaptive ? &*state.adaptive : nullptr;
      made.push_back(state.gripper_model->make_component(drivers, state.link.clock()));
    } else {
      made.push_back(std::make_shared<perception::PerceptionComponent>(state.camera, state.link.clock(), state.pipeline,
                                                                       state.perception_config));
    }
  }
  return made;
}

}  // namespace costar::workcell
