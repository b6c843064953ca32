// The perception component end to end on the simulated workcell: DetectObjects captures
// frames across polls at the camera's rate, then reports the objects. Ground truth is read
// here only to check the answers.

#include "perception/perception_component.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iostream>

#include "sim/drivers.h"
#include "sim/simulation.h"

namespace costar::perception {
namespace {

using component::OperationState;

sim::Scene threeParts() {
  return sim::parseScene(R"({"seed": 3, "parts": [
      {"class": "node", "color": "red", "at": [0.45, -0.2, 20]},
      {"class": "node", "color": "blue", "at": [0.6, 0.15, -35]},
      {"class": "link", "color": "wood", "at": [0.5, 0.0, 70]}]})",
                         "component test");
}

class PerceptionComponentTest : public ::testing::Test {
 protected:
  void SetUp() override {
    simulation_ = sim::Simulation::create(threeParts());
    simulation_->attach(clock_);
    camera_ = std::make_unique<sim::SimRgbdCamera>(*simulation_, 11);
    PerceptionConfig config;
    config.frames = 5;
    component_ = std::make_unique<PerceptionComponent>(*camera_, clock_, config);
  }

  /// Runs DetectObjects as the executor would: poll, advance 10 ms, poll...
  component::OperationResult detect(int* polls = nullptr) {
    const component::OperationId id = component_->start("DetectObjects", {{"frames", 5}});
    for (int i = 1; i < 1000; ++i) {
      component::OperationResult result = component_->poll(id);
      if (result.state != OperationState::kRunning) {
        if (polls != nullptr) {
          *polls = i;
        }
        return result;
      }
      clock_.advanceBy(std::chrono::milliseconds(10));
    }
    return component::OperationResult::failure("did not finish");
  }

  SimClock clock_;
  std::unique_ptr<sim::Simulation> simulation_;
  std::unique_ptr<sim::SimRgbdCamera> camera_;
  std::unique_ptr<PerceptionComponent> component_;
};

TEST_F(PerceptionComponentTest, DescribesDetectObjectsAsAKnowledgeOperation) {
  const auto& description = component_->description();
  EXPECT_EQ(description.name, "perception");
  EXPECT_EQ(description.type, "CostarPerception");
  const component::OperationSpec* detect_objects = description.operation("DetectObjects");
  ASSERT_NE(detect_objects, nullptr);
  EXPECT_EQ(detect_objects->kind, component::OperationKind::kKnowledge);
  ASSERT_NE(detect_objects->param("frames"), nullptr);
  ASSERT_EQ(description.predicates.size(), 2u);
  EXPECT_EQ(description.predicates[0].name, "is_a");
  EXPECT_EQ(description.predicates[0].arity, 2u);
}

TEST_F(PerceptionComponentTest, DetectsThePartsAndReportsThemAsSymbols) {
  const TimePoint start = clock_.now();
  int polls = 0;
  const component::OperationResult result = detect(&polls);
  ASSERT_EQ(result.state, OperationState::kSuccess) << result.reason;
  // Five frames at 30 Hz: at least four frame periods of simulated time.
  EXPECT_GE(clock_.now() - start, std::chrono::milliseconds(133));
  EXPECT_GT(polls, 10);
  ASSERT_EQ(result.data.at("objects").size(), 3u);
  EXPECT_EQ(result.data.at("new").size(), 3u);

  const world::Report report = component_->report();
  world::WorldState world;
  world.update("perception", report);
  // Every part, within 5 mm and 5 degrees (symmetry-aware), as a frame in the world.
  for (const sim::PartState& part : simulation_->parts()) {
    const world::Symbol* best = nullptr;
    double distance = 1e9;
    for (const world::Symbol* symbol : world.symbols()) {
      if (symbol->frame() == nullptr) {
        continue;
      }
      const double d = (symbol->frame()->pose.translation() - part.pose.translation()).norm();
      if (d < distance) {
        distance = d;
        best = symbol;
      }
    }
    ASSERT_NE(best, nullptr);
    EXPECT_LT(distance, 0.005) << part.name;
    EXPECT_EQ(best->frame()->parent, "world");
    EXPECT_EQ(best->name.substr(0, part.object_class.size()), part.object_class);
    const std::vector<std::string> args = {best->name, part.object_class};
    EXPECT_TRUE(world.holds("is_a", args));
    const std::vector<std::string> visible = {best->name};
    EXPECT_TRUE(world.holds("visible", visible));
  }
  ASSERT_NE(world.symbol("node"), nullptr);
  EXPECT_EQ(world.symbol("node")->kind(), world::SymbolKind::kObjectClass);
  ASSERT_NE(world.symbol("link"), nullptr);
  ASSERT_TRUE(component_->lastResult().has_value());
  EXPECT_GT(component_->lastResult()->times.total, 0.0);
}

// Each part's colour as DetectObjects sees it (the mean of its points in the colour image)
// against its material in the simulator: near it, and nearer to it than to the class's other
// colours. The image is lit (ambient, head light, key and fill lights), so the seen colour is
// brighter than the material on the lit faces and darker in shade (measured: red node 0.83,
// 0.11, 0.11 for 0.8, 0.1, 0.1; blue 0.11, 0.28, 0.82 for 0.1, 0.25, 0.8; wood link 0.83, 0.62,
// 0.36 for 0.72, 0.52, 0.3); the tolerance allows that.
TEST_F(PerceptionComponentTest, ReportsEachPartsColourNearItsMaterial) {
  const component::OperationResult result = detect();
  ASSERT_EQ(result.state, OperationState::kSuccess) << result.reason;
  world::WorldState world;
  world.update("perception", component_->report());
  for (const sim::PartState& part : simulation_->parts()) {
    const world::Symbol* best = nullptr;
    double distance = 1e9;
    for (const world::Symbol* symbol : world.symbols()) {
      if (symbol->frame() != nullptr &&
          (symbol->frame()->pose.translation() - part.pose.translation()).norm() < distance) {
        distance = (symbol->frame()->pose.translation() - part.pose.translation()).norm();
        best = symbol;
      }
    }
    ASSERT_NE(best, nullptr);
    ASSERT_TRUE(best->color.has_value()) << part.name << ": no colour reported";
    const ObjectModel* model = component_->pipeline().model(part.object_class);
    ASSERT_NE(model, nullptr);
    const Eigen::Vector3d material = model->object_class.color(part.color);
    const Eigen::Vector3d seen = *best->color;
    std::cout << part.name << " (" << part.color << "): seen " << seen.transpose() << ", material "
              << material.transpose() << "\n";
    EXPECT_LT((seen - material).cwiseAbs().maxCoeff(), 0.15)
        << part.name << " (" << part.color << "): seen " << seen.transpose() << ", material " << material.transpose();
    std::string nearest;
    double nearest_distance = 1e9;
    for (const auto& [name, rgb] : model->object_class.colors) {
      if ((rgb - seen).norm() < nearest_distance) {
        nearest_distance = (rgb - seen).norm();
        nearest = name;
      }
    }
    EXPECT_EQ(nearest, part.color) << part.name << ": seen " << seen.transpose();
    // The operation's result carries it too.
    bool in_result = false;
    for (const auto& object : result.data.at("objects")) {
      if (object.at("name") == best->name) {
        in_result = object.contains("color") && object.at("color").size() == 3 &&
                    std::abs(object.at("color")[0].get<double>() - seen.x()) < 1e-3;
      }
    }
    EXPECT_TRUE(in_result) << best->name << ": " << result.data.at("objects").dump();
  }
}

// measureColors alone: the mean of the class's points inside a detection's boxes (grown by the
// margin), not of its neighbours' points, nor of points of another class.
TEST(MeasureColors, AveragesThePointsInsideEachDetection) {
  world::ObjectClass bar;
  bar.name = "bar";
  bar.boxes = {{Eigen::Vector3d::Zero(), Eigen::Vector3d(0.05, 0.01, 0.01)}};
  ClassParameters parameters;
  const std::vector<ObjectModel> models = {buildObjectModel(bar, parameters)};
  Detection a;
  a.object_class = "bar";
  a.pose_in_camera = world::poseFromXyzRpy(0.0, 0.0, 1.0, 0.0, 0.0, M_PI / 2);  // turned: along the camera's y
  Detection b = a;
  b.pose_in_camera = world::poseFromXyzRpy(0.2, 0.0, 1.0, 0.0, 0.0, 0.0);
  Detection unknown = a;
  unknown.object_class = "gear";
  std::vector<Cloud> points(1);
  const auto add = [&](const Eigen::Vector3d& p, Rgb color) {
    points[0].points.push_back(p.cast<float>());
    points[0].colors.push_back(color);
  };
  // On a's top face along its (turned) length: two colours; one point 3 mm outside its box
  // (within the 4 mm margin), one 1 cm outside (not a's); b's points all green.
  add({0.0, -0.04, 0.99}, {200, 0, 0});
  add({0.0, 0.04, 0.99}, {100, 0, 0});
  add({0.013, 0.0, 1.0}, {150, 0, 0});
  add({0.02, 0.0, 1.0}, {0, 0, 255});
  add({0.2, 0.0, 0.99}, {0, 255, 0});
  add({0.24, 0.0, 0.99}, {0, 255, 0});
  std::vector<Detection> detections = {a, b, unknown};
  measureColors(models, points, detections, 0.004);
  ASSERT_TRUE(detections[0].color.has_value());
  EXPECT_NEAR(detections[0].color->x(), 150.0 / 255.0, 1e-6);
  EXPECT_NEAR(detections[0].color->y(), 0.0, 1e-6);
  EXPECT_NEAR(detections[0].color->z(), 0.0, 1e-6);
  ASSERT_TRUE(detections[1].color.has_value());
  EXPECT_NEAR(detections[1].color->y(), 1.0, 1e-6);
  EXPECT_NEAR(detections[1].color->x(), 0.0, 1e-6);
  EXPECT_FALSE(detections[2].color.has_value());
  // No colours in the cloud: no colour reported.
  points[0].colors.clear();
  measureColors(models, points, detections, 0.004);
  EXPECT_FALSE(detections[0].color.has_value());
}

TEST_F(PerceptionComponentTest, KeepsNamesAcrossDetections) {
  ASSERT_EQ(detect().state, OperationState::kSuccess);
  const std::vector<TrackedObject> first = component_->objects();
  const component::OperationResult again = detect();
  ASSERT_EQ(again.state, OperationState::kSuccess);
  EXPECT_TRUE(again.data.at("new").empty());
  EXPECT_TRUE(again.data.at("dropped").empty());
  const std::vector<TrackedObject> second = component_->objects();
  ASSERT_EQ(second.size(), first.size());
  for (const auto& object : second) {
    const auto same =
        std::find_if(first.begin(), first.end(), [&](const TrackedObject& o) { return o.name == object.name; });
    ASSERT_NE(same, first.end()) << object.name;
    EXPECT_LT((same->pose.translation() - object.pose.translation()).norm(), 0.004);  // fresh noise
  }
}

TEST_F(PerceptionComponentTest, CanBeCancelledWhileCapturing) {
  const component::OperationId id = component_->start("DetectObjects", {{"frames", 5}});
  clock_.advanceBy(std::chrono::milliseconds(40));
  EXPECT_EQ(component_->poll(id).state, OperationState::kRunning);
  component_->cancel(id);
  EXPECT_TRUE(component_->objects().empty());
  EXPECT_EQ(detect().state, OperationState::kSuccess);
}

TEST_F(PerceptionComponentTest, APartMissedBrieflyKeepsItsNameAndIsReportedOnlyWhileSeen) {
  ASSERT_EQ(detect().state, OperationState::kSuccess);
  const sim::PartState red = simulation_->parts()[0];
  const auto name_near = [this](const Eigen::Vector3d& at) {
    for (const auto& object : component_->objects()) {
      if ((object.pose.translation() - at).norm() < 0.01) {
        return object.name;
      }
    }
    return std::string();
  };
  const std::string name = name_near(red.pose.translation());
  ASSERT_FALSE(name.empty());
  const auto is_a_count = [this] {
    world::WorldState world;
    world.update("perception", component_->report());
    return world.predicates("is_a").size();
  };
  ASSERT_EQ(is_a_count(), 3u);

  // Out of view for keep_for (2) detections: remembered, reported as a frame only.
  const world::Pose away(Eigen::Translation3d(0.4, -1.2, 0.026));
  for (int i = 0; i < 2; ++i) {
    simulation_->movePart(red.name, away);
    ASSERT_EQ(detect().state, OperationState::kSuccess);
    EXPECT_EQ(component_->objects().size(), 3u);
    EXPECT_EQ(is_a_count(), 2u);
    world::WorldState world;
    world.update("perception", component_->report());
    ASSERT_NE(world.symbol(name), nullptr);
    EXPECT_FALSE(world.holds("visible", std::vector<std::string>{name}));
  }
  // Back where it was: the same name, seen again.
  simulation_->movePart(red.name, red.pose);
  ASSERT_EQ(detect().state, OperationState::kSuccess);
  EXPECT_EQ(name_near(red.pose.translation()), name);
  EXPECT_EQ(is_a_count(), 3u);
  // Away for three detections: dropped at the third.
  for (int i = 0; i < 3; ++i) {
    simulation_->movePart(red.name, away);
    ASSERT_EQ(detect().state, OperationState::kSuccess);
  }
  EXPECT_EQ(component_->objects().size(), 2u);
}

/// A camera whose frames show no table (it looks at the sky).
class BlindCamera final : public camera::RgbdCamera {
 public:
  std::string name() const override { return "blind"; }
  const camera::Intrinsics& intrinsics() const override { return intrinsics_; }
  Duration framePeriod() const override { return std::chrono::milliseconds(33); }
  camera::RgbdFrame capture() override {
    camera::RgbdFrame frame;
    frame.intrinsics = intrinsics_;
    frame.points.assign(static_cast<std::size_t>(intrinsics_.width) * intrinsics_.height,
                        Eigen::Vector3f::Constant(std::numeric_limits<float>::quiet_NaN()));
    frame.rgb = RgbImage(intrinsics_.width, intrinsics_.height);
    frame.stamp = TimePoint(std::chrono::milliseconds(33 * ++frames_));  // a new frame each time
    return frame;
  }

 private:
  camera::Intrinsics intrinsics_ = camera::Intrinsics::fromHorizontalFov(64, 48, 1.0);
  int frames_ = 0;
};

TEST(PerceptionComponent, FailsWithAReasonWhenTheTableIsNotInView) {
  SimClock clock;
  BlindCamera camera;
  PerceptionConfig config;
  config.frames = 2;
  PerceptionComponent component(camera, clock, config);
  const component::OperationId id = component.start("DetectObjects", {{"frames", 2}});
  component::OperationResult result;
  for (int i = 0; i < 100; ++i) {
    result = component.poll(id);
    if (result.state != OperationState::kRunning) {
      break;
    }
    clock.advanceBy(std::chrono::milliseconds(10));
  }
  EXPECT_EQ(result.state, OperationState::kFailure);
  EXPECT_NE(result.reason.find("table"), std::string::npos) << result.reason;
}

TEST(PerceptionComponent, RefusesMissingDataFiles) {
  SimClock clock;
  BlindCamera camera;
  PerceptionConfig config;
  config.files.svm_file = "/nonexistent/svm_model.json";
  EXPECT_THROW(PerceptionComponent(camera, clock, config), std::runtime_error);
}

/// The simulated camera, or a broken one: frames without pixels, depth all NaN, or a wall
/// in front of the lens (no table in view).
class FaultyCamera final : public camera::RgbdCamera {
 public:
  enum class Fault { kNone, kNoPixels, kAllNaN, kWall };
  explicit FaultyCamera(camera::RgbdCamera& camera) : camera_(camera) {}
  std::string name() const override { return "faulty"; }
  const camera::Intrinsics& intrinsics() const override { return camera_.intrinsics(); }
  Duration framePeriod() const override { return camera_.framePeriod(); }
  camera::RgbdFrame capture() override {
    camera::RgbdFrame frame = camera_.capture();
    switch (fault) {
      case Fault::kNone:
        break;
      case Fault::kNoPixels:
        frame.points.clear();
        frame.rgb = RgbImage();
        break;
      case Fault::kAllNaN:
        std::fill(frame.points.begin(), frame.points.end(),
                  Eigen::Vector3f::Constant(std::numeric_limits<float>::quiet_NaN()));
        break;
      case Fault::kWall:
        for (int v = 0; v < frame.intrinsics.height; ++v) {
          for (int u = 0; u < frame.intrinsics.width; ++u) {
            const Eigen::Vector3f ray((u - frame.intrinsics.cx) / frame.intrinsics.fx,
                                      (v - frame.intrinsics.cy) / frame.intrinsics.fy, 1.0f);
            frame.points[static_cast<std::size_t>(v) * frame.intrinsics.width + u] = 0.3f * ray;
          }
        }
        break;
    }
    return frame;
  }
  Fault fault = Fault::kNone;

 private:
  camera::RgbdCamera& camera_;
};

TEST_F(PerceptionComponentTest, ABrokenFrameFailsWithAReasonAndKeepsTheWorldState) {
  FaultyCamera camera(*camera_);
  PerceptionConfig config;
  config.frames = 3;
  PerceptionComponent component(camera, clock_, config);
  const auto run = [&] {
    const component::OperationId id = component.start("DetectObjects", {{"frames", 3}});
    for (int i = 0; i < 1000; ++i) {
      component::OperationResult result = component.poll(id);
      if (result.state != OperationState::kRunning) {
        return result;
      }
      clock_.advanceBy(std::chrono::milliseconds(10));
    }
    return component::OperationResult::failure("did not finish");
  };
  ASSERT_EQ(run().state, OperationState::kSuccess);
  const std::vector<TrackedObject> before = component.objects();
  ASSERT_EQ(before.size(), 3u);
  for (const auto fault : {FaultyCamera::Fault::kNoPixels, FaultyCamera::Fault::kAllNaN, FaultyCamera::Fault::kWall}) {
    camera.fault = fault;
    const component::OperationResult result = run();
    EXPECT_EQ(result.state, OperationState::kFailure) << static_cast<int>(fault);
    EXPECT_FALSE(result.reason.empty());
    const std::vector<TrackedObject> after = component.objects();
    ASSERT_EQ(after.size(), before.size()) << result.reason;
    for (std::size_t i = 0; i < after.size(); ++i) {
      EXPECT_EQ(after[i].name, before[i].name);
      EXPECT_TRUE(after[i].pose.isApprox(before[i].pose));
    }
    EXPECT_EQ(component.report().symbols.size(), before.size() + 2) << "objects and the two classes";
  }
  // The camera works again: the same names come back.
  camera.fault = FaultyCamera::Fault::kNone;
  ASSERT_EQ(run().state, OperationState::kSuccess);
  for (const auto& object : component.objects()) {
    EXPECT_TRUE(
        std::any_of(before.begin(), before.end(), [&](const TrackedObject& o) { return o.name == object.name; }));
  }
}

TEST(PerceptionComponent, RefusesACorruptSvmOrAnUnknownClassNamingTheFile) {
  SimClock clock;
  BlindCamera camera;
  const auto dir = std::filesystem::temp_directory_path() / "costar_perception_bad_files";
  std::filesystem::create_directories(dir);
  PerceptionConfig config;
  config.files.svm_file = dir / "svm_model.json";
  std::ofstream(config.files.svm_file) << R"({"format": "costar-svm-rbf-1", "labels": [0, 1)";  // cut short
  try {
    PerceptionComponent component(camera, clock, config);
    ADD_FAILURE() << "a corrupt SVM file was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("svm_model.json"), std::string::npos) << e.what();
  }
  config = PerceptionConfig{};
  config.files.classes_file = dir / "classes.json";
  std::ofstream(config.files.classes_file) << R"({"classes": {"gear": {"svm_label": 3}}})";
  try {
    PerceptionComponent component(camera, clock, config);
    ADD_FAILURE() << "an unknown class was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("gear"), std::string::npos) << e.what();
  }
  std::filesystem::remove_all(dir);
}

/// A camera whose stream's status the test sets (its frames are BlindCamera's).
class StreamingCamera final : public camera::RgbdCamera {
 public:
  std::string name() const override { return "streaming"; }
  const camera::Intrinsics& intrinsics() const override { return frames_.intrinsics(); }
  Duration framePeriod() const override { return frames_.framePeriod(); }
  camera::RgbdFrame capture() override { return frames_.capture(); }
  std::optional<camera::StreamStatus> streamStatus() override {
    if (unreachable) {
      throw std::runtime_error("USB device disconnected");
    }
    return status;
  }
  std::optional<camera::StreamStatus> status;
  bool unreachable = false;

 private:
  BlindCamera frames_;
};

/// The report's exception (what stops the cell), or "" when it did not throw.
std::string reportError(const PerceptionComponent& component) {
  try {
    component.report();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

TEST(PerceptionComponent, WatchesTheCameraBetweenDetections) {
  SimClock clock;
  StreamingCamera camera;
  PerceptionConfig config;
  config.frames = 2;
  PerceptionComponent component(camera, clock, config);
  EXPECT_EQ(reportError(component), "") << "a camera that cannot tell is judged by its frames only";
  clock.advanceTo(TimePoint(fromSeconds(5.0)));
  camera.status = camera::StreamStatus{TimePoint(fromSeconds(4.9)), 3072, 3000};
  EXPECT_EQ(reportError(component), "");
  // The stream stopped: its newest frame grows old.
  clock.advanceTo(TimePoint(fromSeconds(5.1)));
  EXPECT_EQ(reportError(component), "");  // 0.2 s: the limit
  clock.advanceTo(TimePoint(fromSeconds(5.2)));
  EXPECT_EQ(reportError(component), "the camera stopped sending frames: the newest is 0.300 s old (limit 0.200 s)");
  camera.status->stamp = clock.now();
  camera.status->valid = 0;
  EXPECT_NE(reportError(component).find("without any valid depth"), std::string::npos);
  camera.status->points = 0;
  EXPECT_EQ(reportError(component), "the camera sends empty frames (no pixels)");
  camera.unreachable = true;
  EXPECT_EQ(reportError(component), "the camera's stream failed: USB device disconnected");
  // Healthy again: the report is the component's.
  camera.unreachable = false;
  camera.status = camera::StreamStatus{clock.now(), 3072, 3072};
  EXPECT_EQ(reportError(component), "");
  EXPECT_EQ(component.report().symbols.size(), 2u) << "the two classes";

  // Not watched when asked not to.
  PerceptionConfig unwatched = config;
  unwatched.camera_max_age = Duration::zero();
  PerceptionComponent blind_eye(camera, clock, unwatched);
  camera.status->points = 0;
  EXPECT_EQ(reportError(blind_eye), "");
}

TEST_F(PerceptionComponentTest, TheSimulatedCameraStreamsBetweenDetections) {
  ASSERT_EQ(detect().state, OperationState::kSuccess);
  clock_.advanceBy(std::chrono::seconds(3));
  const std::optional<camera::StreamStatus> status = camera_->streamStatus();
  ASSERT_TRUE(status);
  EXPECT_EQ(status->stamp, clock_.now()) << "rendered on demand, the simulated stream never stalls";
  EXPECT_EQ(status->points, 640u * 480u);
  EXPECT_GT(status->valid, status->points / 2) << "the last frame's valid depth";
  EXPECT_EQ(reportError(*component_), "");
}

}  // namespace
}  // namespace costar::perception
