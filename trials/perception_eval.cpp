#include "trials/perception_eval.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <random>
#include <sstream>
#include <stdexcept>
#include <tuple>

#include "core/clock.h"
#include "core/files.h"
#include "core/json_file.h"
#include "perception/canonical_orientation.h"
#include "perception/drawing.h"
#include "perception/perception_component.h"
#include "perception/pipeline.h"
#include "perception/pose_estimation.h"
#include "perception/svm_classifier.h"
#include "perception/workspace.h"
#include "sim/drivers.h"
#include "sim/scene.h"
#include "sim/simulation.h"
#include "trials/perception_scenes.h"
#include "workcell/cell_simulation.h"

namespace costar::trials {

namespace {

constexpr double kRotationTolerance = kPoseToleranceDeg * M_PI / 180.0;

double millis(double seconds) { return seconds * 1000.0; }
double round3(double value) { return std::round(value * 1000.0) / 1000.0; }

std::string formatted(const char* format, auto... values) {
  char text[256];
  std::snprintf(text, sizeof text, format, values...);
  return text;
}

const world::ObjectClass& classNamed(const std::vector<world::ObjectClass>& classes, const std::string& name) {
  for (const auto& object_class : classes) {
    if (object_class.name == name) {
      return object_class;
    }
  }
  throw std::runtime_error("unknown object class '" + name + "'");
}

/// A camera whose simulation can be swapped (a push re-creates the scene).
class SwitchableCamera final : public camera::RgbdCamera {
 public:
  void use(sim::Simulation& simulation, std::uint64_t seed) {
    camera_ = std::make_unique<sim::SimRgbdCamera>(simulation, seed);
  }
  std::string name() const override { return camera_->name(); }
  const camera::Intrinsics& intrinsics() const override { return camera_->intrinsics(); }
  Duration framePeriod() const override { return camera_->framePeriod(); }
  camera::RgbdFrame capture() override { return camera_->capture(); }
  camera::RgbdFrame captureDepth() override { return camera_->captureDepth(); }

 private:
  std::unique_ptr<sim::SimRgbdCamera> camera_;
};

/// A clock that reads the current simulation's SimClock.
class SwitchableClock final : public Clock {
 public:
  void use(SimClock& clock) { clock_ = &clock; }
  TimePoint now() const override { return clock_->now(); }
  void sleepUntil(TimePoint t) override { clock_->sleepUntil(t); }
  bool simulated() const override { return true; }

 private:
  SimClock* clock_ = nullptr;
};

/// The simulator's parts, with how much of each one's camera-facing surface `frame` shows.
std::vector<TruePart> truthSeenIn(const sim::Simulation& simulation, const camera::RgbdFrame& frame,
                                  const perception::Pipeline& pipeline) {
  std::vector<TruePart> out;
  for (const sim::PartState& part : simulation.parts()) {
    TruePart truth{part.name, part.object_class, part.pose, 0.0};
    if (const perception::ObjectModel* model = pipeline.model(part.object_class)) {
      truth.visible_fraction =
          perception::compareWithDepth(*model, frame.camera_pose.inverse() * part.pose, frame, 0.008).visibleFraction();
    }
    out.push_back(std::move(truth));
  }
  return out;
}

/// The objects the latest detection saw (not those only remembered by keep_for): what is scored.
std::vector<DetectedPart> seenObjects(const perception::PerceptionComponent& component) {
  std::vector<DetectedPart> seen;
  for (const perception::TrackedObject& object : component.objects()) {
    if (object.missed == 0) {
      seen.push_back({object.name, object.object_class, object.pose, object.confidence});
    }
  }
  return seen;
}

/// DetectObjects on the component, stepping simulated time as the executor would.
perception::PipelineResult detectOnce(perception::PerceptionComponent& component, SimClock& clock, int frames) {
  component::ParamMap params;
  params["frames"] = frames;
  const component::OperationId id = component.start("DetectObjects", params);
  for (int tick = 0; tick < 100000; ++tick) {
    const component::OperationResult result = component.poll(id);
    if (result.state == component::OperationState::kSuccess) {
      return *component.lastResult();
    }
    if (result.state == component::OperationState::kFailure) {
      throw std::runtime_error("DetectObjects failed: " + result.reason);
    }
    clock.advanceBy(std::chrono::milliseconds(10));
  }
  throw std::runtime_error("DetectObjects did not finish in 1,000 simulated seconds");
}

std::vector<world::ObjectClass> classesOf(const perception::Pipeline& pipeline) {
  std::vector<world::ObjectClass> classes;
  for (const auto& model : pipeline.models()) {
    classes.push_back(model.object_class);
  }
  return classes;
}

/// The perception configuration of `cell`: its model when it names one.
perception::PerceptionConfig cellConfig(const workcell::CellSimulation& cell) {
  perception::PerceptionConfig config;
  if (!cell.cell.perception_model.empty()) {
    config.files.svm_file = cell.cell.perception_model;
  }
  return config;
}

/// The table where the parts lie (x 0.25..0.75, y -0.45..0.45 m, up to 6 cm high): the
/// pictures' close-up.
perception::WorkspaceOptions pictureArea() {
  perception::WorkspaceOptions area;
  area.table_center = world::Pose(Eigen::Translation3d(0.5, 0.0, 0.0));
  area.half_size_x = 0.25;
  area.half_size_y = 0.45;
  area.max_height = 0.06;
  area.plane_search_band = 0.0;
  return area;
}

world::Box boundingBox(const world::ObjectClass& object_class) {
  return {object_class.bounds().center(), object_class.bounds().sizes() / 2.0};
}

RgbImage pictureOf(const camera::RgbdFrame& frame, const std::vector<DetectedPart>& detected,
                   const std::vector<TruePart>& truth, const Match& match,
                   const std::vector<world::ObjectClass>& classes) {
  std::vector<perception::Overlay> overlays;
  for (std::size_t d = 0; d < detected.size(); ++d) {
    const world::ObjectClass& object_class = classNamed(classes, detected[d].object_class);
    perception::Overlay overlay;
    overlay.pose = detected[d].pose;
    overlay.boxes =
        object_class.boxes.size() == 1 ? object_class.boxes : std::vector<world::Box>{boundingBox(object_class)};
    overlay.label = detected[d].name;
    const int p = match.part_of_detection[d];
    overlay.color = p < 0                                         ? perception::Rgb{255, 140, 0}
                    : match.accurate(static_cast<std::size_t>(p)) ? perception::Rgb{40, 220, 60}
                                                                  : perception::Rgb{230, 30, 30};
    overlay.draw_axes = true;
    overlays.push_back(overlay);
  }
  for (std::size_t p = 0; p < truth.size(); ++p) {
    if (match.detection_of_part[p] >= 0) {
      continue;
    }
    perception::Overlay overlay;
    overlay.pose = truth[p].pose;
    overlay.boxes = {boundingBox(classNamed(classes, truth[p].object_class))};
    overlay.color = {255, 230, 0};
    overlay.label = "missed " + truth[p].name;
    overlays.push_back(overlay);
  }
  return perception::drawOverlaysZoomed(frame.rgb, frame.intrinsics, frame.camera_pose, overlays,
                                        perception::workspaceRegion(frame.intrinsics, frame.camera_pose, pictureArea()),
                                        2.0);
}

/// The SVM's labels over the image: background dark red, the classes in turn blue, green, ...
RgbImage labelPicture(const perception::PipelineResult& result, const perception::Pipeline& pipeline) {
  RgbImage image = result.filtered->rgb;
  for (auto& value : image.pixels) {
    value = static_cast<std::uint8_t>(value / 3);
  }
  const std::vector<perception::Rgb> colors = {{60, 120, 255}, {60, 230, 60}, {255, 230, 0}, {230, 60, 230}};
  for (std::size_t i = 0; i < result.workspace.size(); ++i) {
    perception::Rgb color{160, 20, 20};
    for (std::size_t m = 0; m < pipeline.models().size(); ++m) {
      if (pipeline.classifier().labelOf(pipeline.models()[m].name()) == result.labels[i]) {
        color = colors[m % colors.size()];
      }
    }
    std::uint8_t* p = &image.pixels[static_cast<std::size_t>(result.workspace.pixels[i]) * 3];
    std::copy(color.begin(), color.end(), p);
  }
  const camera::RgbdFrame& frame = *result.filtered;
  return perception::drawOverlaysZoomed(image, frame.intrinsics, frame.camera_pose, {},
                                        perception::workspaceRegion(frame.intrinsics, frame.camera_pose, pictureArea()),
                                        2.0);
}

/// An arm posed over the table is simulated with a shorter settling (the fingers' half second
/// follows: kFingersSettle).
sim::SimulationOptions armOverOptions(sim::SimulationOptions options) {
  options.settle_seconds = 0.5;
  return options;
}
constexpr std::chrono::milliseconds kFingersSettle{600};

/// A scene file `perception detect` can run again. @throws std::runtime_error when it cannot
/// be written.
void writeSceneFile(const std::filesystem::path& file, sim::Scene scene, const std::string& description) {
  scene.description = description;
  writeOutputFile(file, sim::sceneFileText(scene));
}

sim::Footprint footprintOf(const world::ObjectClass& object_class, const world::Pose& pose) {
  return sim::Footprint::of(object_class, pose.translation().x(), pose.translation().y(),
                            world::rpyOf(pose.linear()).z());
}

/// The parts of a simulation as a scene with fixed placements (to re-create it after a push).
sim::Scene sceneOf(const std::vector<sim::PartState>& parts, const std::vector<world::ObjectClass>& classes,
                   const std::string& label) {
  sim::Scene scene;
  scene.label = label;
  scene.min_gap = 0.0;
  for (const auto& part : parts) {
    sim::PartRequest request;
    request.object_class = part.object_class;
    request.color = part.color;
    const double yaw = world::rpyOf(part.pose.linear()).z();
    request.at = Eigen::Vector3d(part.pose.translation().x(), part.pose.translation().y(), yaw * 180.0 / M_PI);
    // A part lying on another (a link across a node, or leaning from it onto the table) starts
    // level just over the parts on the table under it and falls back onto them.
    const world::ObjectClass& object_class = classNamed(classes, part.object_class);
    if (part.pose.translation().z() - object_class.rest_height > 0.01) {
      const sim::Footprint footprint = footprintOf(object_class, part.pose);
      for (const auto& other : parts) {
        const world::ObjectClass& other_class = classNamed(classes, other.object_class);
        if (&other != &part && other.pose.translation().z() - other_class.rest_height <= 0.01 &&
            sim::closerThan(footprint, footprintOf(other_class, other.pose), 0.0)) {
          request.height = std::max(request.height, other_class.bounds().sizes().z() + 0.002);
        }
      }
    }
    scene.parts.push_back(request);
  }
  return scene;
}

/// A small push: one part moved 1-2 cm and turned up to 10 degrees where it touches no other
/// (another part tried every 10 attempts). The index of the pushed part, or none in 60 tries.
std::optional<std::size_t> pushOnePart(std::vector<sim::PartState>& parts,
                                       const std::vector<world::ObjectClass>& classes, std::mt19937_64& random) {
  std::uniform_int_distribution<std::size_t> which(0, parts.size() - 1);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::size_t pushed = which(random);
  for (int attempt = 0; attempt < 60; ++attempt) {
    if (attempt % 10 == 9) {
      pushed = which(random);
    }
    const double distance = 0.01 + 0.01 * unit(random);
    const double direction = 2 * M_PI * unit(random);
    const double turn = (unit(random) - 0.5) * 20.0 * M_PI / 180.0;
    const world::Pose& before = parts[pushed].pose;
    const world::Pose after =
        world::poseFromXyzRpy(before.translation().x() + distance * std::cos(direction),
                              before.translation().y() + distance * std::sin(direction), before.translation().z(), 0, 0,
                              world::rpyOf(before.linear()).z() + turn);
    const sim::Footprint moved = footprintOf(classNamed(classes, parts[pushed].object_class), after);
    bool free = true;
    for (std::size_t o = 0; o < parts.size() && free; ++o) {
      free = o == pushed ||
             !sim::closerThan(moved, footprintOf(classNamed(classes, parts[o].object_class), parts[o].pose), 0.001);
    }
    if (free) {
      parts[pushed].pose = after;
      return pushed;
    }
  }
  return std::nullopt;
}

/// Per part, whether the round gave it the name it got at the first look (parts without one
/// are skipped): calls `checked(part, kept)`.
void checkNames(const std::vector<DetectedPart>& detected, const Match& match, const std::vector<std::string>& names,
                const std::function<void(std::size_t, bool)>& checked) {
  for (std::size_t p = 0; p < names.size() && p < match.detection_of_part.size(); ++p) {
    if (names[p].empty()) {
      continue;
    }
    const int d = match.detection_of_part[p];
    checked(p, d >= 0 && detected[static_cast<std::size_t>(d)].name == names[p]);
  }
}

void recordLatency(PerceptionEvalSummary& summary, const perception::StageTimes& t) {
  const double values[] = {t.median, t.crop,        t.normals,    t.features, t.classification,
                           t.pose,   t.recognition, t.refinement, t.total};
  for (std::size_t i = 0; i < latencyStages().size(); ++i) {
    summary.latency_ms[latencyStages()[i]].push_back(millis(values[i]));
  }
}

nlohmann::json statsJson(const std::vector<double>& values) {
  return {{"median", round3(percentile(values, 50))},
          {"p95", round3(percentile(values, 95))},
          {"max", round3(values.empty() ? 0.0 : *std::max_element(values.begin(), values.end()))}};
}

double fraction(int good, int all) { return all == 0 ? 1.0 : static_cast<double>(good) / all; }

}  // namespace

double percentile(std::vector<double> values, double p) {
  if (values.empty()) {
    return 0.0;
  }
  std::sort(values.begin(), values.end());
  const double at = std::clamp(p, 0.0, 100.0) / 100.0 * static_cast<double>(values.size() - 1);
  const auto low = static_cast<std::size_t>(std::floor(at));
  const std::size_t high = std::min(values.size() - 1, low + 1);
  return values[low] + (values[high] - values[low]) * (at - static_cast<double>(low));
}

const std::vector<std::string>& latencyStages() {
  static const std::vector<std::string> stages = {"median_filter",    "crop_plane",    "normals",
                                                  "features",         "svm",           "pose_wall",
                                                  "objrecransac_cpu", "icp_check_cpu", "total"};
  return stages;
}

bool Match::accurate(std::size_t part) const {
  return detection_of_part.at(part) >= 0 && translation_error[part] <= kPoseToleranceM &&
         rotation_error[part] <= kRotationTolerance;
}

Match matchToTruth(const std::vector<DetectedPart>& detected, const std::vector<TruePart>& truth,
                   const std::vector<world::ObjectClass>& classes) {
  Match match;
  match.detection_of_part.assign(truth.size(), -1);
  match.part_of_detection.assign(detected.size(), -1);
  match.translation_error.assign(truth.size(), 0.0);
  match.rotation_error.assign(truth.size(), 0.0);
  std::vector<std::tuple<double, int, int>> pairs;
  for (std::size_t d = 0; d < detected.size(); ++d) {
    for (std::size_t p = 0; p < truth.size(); ++p) {
      if (detected[d].object_class != truth[p].object_class) {
        continue;
      }
      const double distance = (detected[d].pose.translation() - truth[p].pose.translation()).norm();
      if (distance < 0.025) {
        pairs.emplace_back(distance, static_cast<int>(d), static_cast<int>(p));
      }
    }
  }
  std::sort(pairs.begin(), pairs.end());
  for (const auto& [distance, d, p] : pairs) {
    const auto part = static_cast<std::size_t>(p);
    const auto detection = static_cast<std::size_t>(d);
    if (match.part_of_detection[detection] >= 0 || match.detection_of_part[part] >= 0) {
      continue;
    }
    match.part_of_detection[detection] = p;
    match.detection_of_part[part] = d;
    match.translation_error[part] = distance;
    match.rotation_error[part] = perception::symmetricRotationDistance(
        detected[detection].pose.linear(), truth[part].pose.linear(), classNamed(classes, truth[part].object_class));
  }
  return match;
}

double ClassScore::precision() const { return fraction(detections - false_positives, detections); }
double ClassScore::recall() const { return fraction(visible_found, visible); }
double ClassScore::withinTolerance() const { return fraction(visible_accurate, visible); }

void Scores::add(const std::vector<DetectedPart>& detected, const std::vector<TruePart>& truth, const Match& match,
                 const std::string& where) {
  for (std::size_t p = 0; p < truth.size(); ++p) {
    const TruePart& part = truth[p];
    ClassScore& score = classes[part.object_class];
    if (part.visible_fraction < kVisibleFraction) {
      ++hidden_part_views;
      continue;
    }
    ++score.visible;
    if (match.detection_of_part[p] < 0) {
      const Eigen::Vector3d at = part.pose.translation();
      problems.push_back(formatted("%s: missed %s (%s) at (%.3f, %.3f, %.3f), %.0f %% of it in view", where.c_str(),
                                   part.name.c_str(), part.object_class.c_str(), at.x(), at.y(), at.z(),
                                   100.0 * part.visible_fraction));
      continue;
    }
    ++score.visible_found;
    const double t = match.translation_error[p];
    const double r = match.rotation_error[p];
    score.translation_mm.push_back(t * 1000.0);
    score.rotation_deg.push_back(r * 180.0 / M_PI);
    if (match.accurate(p)) {
      ++score.visible_accurate;
    } else {
      const Eigen::Vector3d offset =
          part.pose.inverse() * detected[static_cast<std::size_t>(match.detection_of_part[p])].pose.translation();
      problems.push_back(
          formatted("%s: %s (%s) found with %.1f mm / %.1f deg error (in its frame: %+.1f %+.1f %+.1f mm)",
                    where.c_str(), part.name.c_str(), part.object_class.c_str(), t * 1000.0, r * 180.0 / M_PI,
                    offset.x() * 1000.0, offset.y() * 1000.0, offset.z() * 1000.0));
    }
  }
  for (std::size_t d = 0; d < detected.size(); ++d) {
    ClassScore& score = classes[detected[d].object_class];
    ++score.detections;
    if (match.part_of_detection[d] < 0) {
      ++score.false_positives;
      const Eigen::Vector3d at = detected[d].pose.translation();
      problems.push_back(formatted("%s: false detection %s at (%.3f, %.3f, %.3f), confidence %.3f", where.c_str(),
                                   detected[d].name.c_str(), at.x(), at.y(), at.z(), detected[d].confidence));
    }
  }
}

int Scores::visiblePartViews() const {
  int visible = 0;
  for (const auto& [name, score] : classes) {
    visible += score.visible;
  }
  return visible;
}

double Scores::foundWithinTolerance() const {
  int accurate = 0;
  for (const auto& [name, score] : classes) {
    accurate += score.visible_accurate;
  }
  return fraction(accurate, visiblePartViews());
}

PerceptionEvalSummary evaluatePerception(const PerceptionEvalOptions& options,
                                         const std::function<void(const SceneReport&)>& progress) {
  const auto started = std::chrono::steady_clock::now();
  const workcell::CellSimulation cell = workcell::cellSimulation(options.workcell);
  const std::shared_ptr<const arm::Kinematics> kinematics = arm::makeKinematics(cell.robot);
  perception::PerceptionConfig config = cellConfig(cell);
  if (!options.model.empty()) {
    config.files.svm_file = options.model;
  }
  const auto pipeline = perception::loadPipeline(config);
  config.frames = options.frames;
  const std::vector<world::ObjectClass> classes = classesOf(*pipeline);
  if (!options.pictures.empty()) {
    std::filesystem::create_directories(options.pictures);
  }
  PerceptionEvalSummary summary;
  summary.options = options;
  Scores& scores = summary.scores;
  std::mt19937_64 random(options.seed);
  for (int s = 0; s < options.scenes; ++s) {
    // 3-6 nodes and 1-3 links (drawn per class in the models' order).
    std::uniform_int_distribution<int> nodes(3, 6);
    std::uniform_int_distribution<int> links(1, 3);
    std::vector<std::pair<std::string, int>> counts;
    for (const auto& object_class : classes) {
      counts.emplace_back(object_class.name, object_class.name == "link" ? links(random) : nodes(random));
    }
    const std::string label = "scene " + std::to_string(s + 1);
    sim::ClutteredScene generated = sim::clutteredScene(classes, counts, options.touching, random, label);
    SceneReport report;
    report.scene = s + 1;
    report.touching_parts = generated.touching_parts;
    summary.parts_placed_touching += generated.touching_parts;
    report.stacked_parts = stackLinksOnNodes(generated.scene, classes, options.stacked, random);
    summary.parts_stacked += report.stacked_parts;

    SwitchableCamera camera;
    SwitchableClock clock;
    auto sim_clock = std::make_unique<SimClock>();
    sim::SimulationOptions sim_options = cell.options;
    std::unique_ptr<sim::Simulation> simulation;
    SceneLook look;
    look.workcell = options.workcell;
    if (options.arm_over > 0.0 && std::uniform_real_distribution<double>(0.0, 1.0)(random) < options.arm_over) {
      ArmOverPose posed;
      simulation =
          armOverTableSimulation(cell, *kinematics, generated.scene, armOverOptions(sim_options), 0.1, random, &posed);
      if (simulation) {
        report.arm_over = true;
        ++summary.scenes_arm_over;
        sim_options.initial_arm = simulation->armPositions();  // the pushes' scenes keep it there
        look.arm_over = posed;
      }
    }
    if (!simulation) {
      simulation = sim::Simulation::create(generated.scene, sim_options);
    }
    simulation->attach(*sim_clock);
    if (report.arm_over) {
      sim_clock->advanceBy(kFingersSettle);
    }
    look.noise_seed = random();
    camera.use(*simulation, look.noise_seed);
    clock.use(*sim_clock);
    perception::PerceptionComponent component(camera, clock, pipeline, config);

    // First look.
    perception::PipelineResult result = detectOnce(component, *sim_clock, options.frames);
    recordLatency(summary, result.times);
    std::vector<TruePart> truth = truthSeenIn(*simulation, *result.filtered, *pipeline);
    summary.parts += static_cast<int>(truth.size());
    report.parts = static_cast<int>(truth.size());
    std::vector<DetectedPart> detected = seenObjects(component);
    const Match first = matchToTruth(detected, truth, classes);
    scores.add(detected, truth, first, label);
    if (!options.pictures.empty()) {
      const std::string stem = formatted("scene_%03d", s + 1);
      writePng(options.pictures / (stem + ".png"), pictureOf(*result.filtered, detected, truth, first, classes));
      writePng(options.pictures / (stem + "_labels.png"), labelPicture(result, *pipeline));
      writeSceneFile(options.pictures / (stem + ".json"), generated.scene,
                     "perception eval --seed " + std::to_string(options.seed) + ", " + label);
      writeOutputFile(options.pictures / (stem + "_look.json"), sceneLookJson(look).dump(2) + "\n");
    }
    std::vector<std::string> names(truth.size());  // after the first look
    for (std::size_t p = 0; p < truth.size(); ++p) {
      report.accurate_first_look += first.accurate(p) ? 1 : 0;
      if (first.detection_of_part[p] >= 0) {
        names[p] = detected[static_cast<std::size_t>(first.detection_of_part[p])].name;
      }
    }

    // Repeats while the parts stay still (the first scene's long run included).
    report.repeats = options.repeats + (s == 0 ? options.long_run : 0);
    for (int r = 0; r < report.repeats; ++r) {
      result = detectOnce(component, *sim_clock, options.frames);
      recordLatency(summary, result.times);
      detected = seenObjects(component);
      const std::string where = label + " repeat " + std::to_string(r + 1);
      const Match match = matchToTruth(detected, truth, classes);
      scores.add(detected, truth, match, where);
      const bool long_run = r >= options.repeats;
      checkNames(detected, match, names, [&](std::size_t p, bool kept) {
        ++report.name_checks;
        report.names_kept += kept ? 1 : 0;
        if (long_run) {
          ++summary.long_run_checks;
          summary.long_run_stable += kept ? 1 : 0;
        }
        if (!kept) {
          scores.problems.push_back(where + ": " + truth[p].name + " lost its name " + names[p]);
        }
      });
    }
    summary.repeat_checks += report.name_checks;
    summary.repeat_stable += report.names_kept;
    if (report.repeats > 0) {
      ++summary.scenes_with_repeats;
      summary.scenes_all_stable += report.names_kept == report.name_checks ? 1 : 0;
    }

    // Small pushes; the others stay.
    for (int push = 0; push < options.pushes && !truth.empty(); ++push) {
      std::vector<sim::PartState> parts = simulation->parts();
      const std::optional<std::size_t> pushed = pushOnePart(parts, classes, random);
      if (!pushed) {
        continue;
      }
      const std::string where = label + " push " + std::to_string(push + 1);
      // One simulation at a time (destroying one ends the EGL display all renderers share).
      simulation.reset();
      sim_clock = std::make_unique<SimClock>();
      const sim::Scene pushed_scene = sceneOf(parts, classes, where);
      if (!options.pictures.empty()) {
        writeSceneFile(options.pictures / formatted("scene_%03d_push_%d.json", s + 1, push + 1), pushed_scene,
                       "perception eval --seed " + std::to_string(options.seed) + ", " + where);
      }
      simulation = sim::Simulation::create(pushed_scene, sim_options);
      simulation->attach(*sim_clock);
      camera.use(*simulation, random());
      clock.use(*sim_clock);
      result = detectOnce(component, *sim_clock, options.frames);
      recordLatency(summary, result.times);
      // The re-created scene names its parts in the same order.
      truth = truthSeenIn(*simulation, *result.filtered, *pipeline);
      detected = seenObjects(component);
      const Match match = matchToTruth(detected, truth, classes);
      scores.add(detected, truth, match, where);
      bool all_kept = true;
      checkNames(detected, match, names, [&](std::size_t p, bool kept) {
        ++summary.push_checks;
        summary.push_stable += kept ? 1 : 0;
        if (p == *pushed) {
          ++summary.pushed_part_checks;
          summary.pushed_part_stable += kept ? 1 : 0;
        }
        if (!kept) {
          all_kept = false;
          scores.problems.push_back(where + ": " + truth[p].name + (p == *pushed ? " (pushed)" : "") +
                                    " lost its name " + names[p]);
        }
      });
      report.pushes_all_names_kept += all_kept ? 1 : 0;
    }
    report.last_detection_ms = millis(result.times.total);
    if (progress) {
      progress(report);
    }
  }
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return summary;
}

nlohmann::json PerceptionEvalSummary::toJson() const {
  nlohmann::json json;
  json["command"] = "costar perception eval --scenes " + std::to_string(options.scenes) + " --seed " +
                    std::to_string(options.seed) + " --repeats " + std::to_string(options.repeats) + " --pushes " +
                    std::to_string(options.pushes) + " --frames " + std::to_string(options.frames) + " -w " +
                    options.workcell + (options.stacked > 0 ? " --stacked " + std::to_string(options.stacked) : "") +
                    (options.arm_over > 0 ? formatted(" --arm-over %g", options.arm_over) : "");
  json["workcell"] = options.workcell;
  json["model"] = options.model.empty() ? "the cell's" : options.model.string();
  json["scenes"] = options.scenes;
  json["parts"] = parts;
  json["parts_placed_touching"] = parts_placed_touching;
  json["parts_stacked"] = parts_stacked;
  json["scenes_arm_over"] = scenes_arm_over;
  int false_detections = 0;
  for (const auto& [name, score] : scores.classes) {
    false_detections += score.false_positives;
  }
  json["false_detections"] = false_detections;
  json["tolerance"] = {{"translation_mm", kPoseToleranceM * 1000.0}, {"rotation_deg", kPoseToleranceDeg}};
  for (const auto& [name, score] : scores.classes) {
    json["classes"][name] = {{"visible", score.visible},
                             {"detections", score.detections},
                             {"false_positives", score.false_positives},
                             {"precision", round3(score.precision())},
                             {"recall", round3(score.recall())},
                             {"found_within_tolerance", round3(score.withinTolerance())},
                             {"translation_error_mm", statsJson(score.translation_mm)},
                             {"rotation_error_deg", statsJson(score.rotation_deg)}};
  }
  json["found_within_tolerance"] = round3(scores.foundWithinTolerance());
  json["visible_part_views"] = scores.visiblePartViews();
  json["hidden_part_views"] = scores.hidden_part_views;
  json["persistence"] = {{"repeats_per_scene", options.repeats},
                         {"still_name_checks", repeat_checks},
                         {"still_names_kept", round3(fraction(repeat_stable, repeat_checks))},
                         {"scenes_all_names_kept", scenes_all_stable},
                         {"long_run_repeats", options.long_run},
                         {"long_run_names_kept", round3(fraction(long_run_stable, long_run_checks))},
                         {"push_name_checks", push_checks},
                         {"push_names_kept", round3(fraction(push_stable, push_checks))},
                         {"pushed_parts_names_kept", round3(fraction(pushed_part_stable, pushed_part_checks))}};
  for (const std::string& stage : latencyStages()) {
    const auto found = latency_ms.find(stage);
    const std::vector<double> values = found == latency_ms.end() ? std::vector<double>{} : found->second;
    json["latency_ms"][stage] = {{"median", round3(percentile(values, 50))}, {"p95", round3(percentile(values, 95))}};
  }
  json["problems"] = scores.problems;
  json["seconds"] = round3(seconds);
  return json;
}

std::string PerceptionEvalSummary::text() const {
  std::ostringstream out;
  int false_detections = 0;
  for (const auto& [name, score] : scores.classes) {
    false_detections += score.false_positives;
  }
  out << formatted(
      "\n%s: %d parts, %d placed touching, %d links across nodes, the arm over the parts in %d of %d "
      "scenes; %d false detections\n",
      options.workcell.c_str(), parts, parts_placed_touching, parts_stacked, scenes_arm_over, options.scenes,
      false_detections);
  out << "\nper class (every DetectObjects of every scene; parts with >= 30 % of their facing surface in view):\n";
  out << formatted("  %-6s %8s %9s %7s %10s %12s %12s %12s %12s\n", "class", "visible", "precision", "recall",
                   "within tol", "t med (mm)", "t p95 (mm)", "r med (deg)", "r p95 (deg)");
  for (const auto& [name, score] : scores.classes) {
    out << formatted("  %-6s %8d %9.4f %7.4f %10.4f %12.2f %12.2f %12.2f %12.2f\n", name.c_str(), score.visible,
                     score.precision(), score.recall(), score.withinTolerance(), percentile(score.translation_mm, 50),
                     percentile(score.translation_mm, 95), percentile(score.rotation_deg, 50),
                     percentile(score.rotation_deg, 95));
  }
  out << formatted(
      "  all    %8d parts seen, %.2f %% found within 5 mm and 5 deg (target >= 99 %%); %d part views "
      "mostly hidden, not counted\n",
      scores.visiblePartViews(), 100.0 * scores.foundWithinTolerance(), scores.hidden_part_views);
  out << "\npersistence:\n";
  out << formatted("  parts still: %d of %d name checks kept the name (%.2f %%); %d of %d scenes kept every name\n",
                   repeat_stable, repeat_checks, 100.0 * fraction(repeat_stable, repeat_checks), scenes_all_stable,
                   scenes_with_repeats);
  if (long_run_checks > 0) {
    out << formatted("  long run (scene 1, %d more repeats): %d of %d name checks kept the name\n", options.long_run,
                     long_run_stable, long_run_checks);
  }
  out << formatted("  after pushes of 1-2 cm / up to 10 deg: %d of %d names kept (pushed parts: %d of %d)\n",
                   push_stable, push_checks, pushed_part_stable, pushed_part_checks);
  const auto total = latency_ms.find("total");
  out << formatted("\nlatency per DetectObjects (%zu runs; frame capture not included; median / p95 ms):\n",
                   total == latency_ms.end() ? std::size_t{0} : total->second.size());
  for (const std::string& stage : latencyStages()) {
    const auto found = latency_ms.find(stage);
    const std::vector<double> values = found == latency_ms.end() ? std::vector<double>{} : found->second;
    out << formatted("  %-18s %8.1f %8.1f\n", stage.c_str(), percentile(values, 50), percentile(values, 95));
  }
  if (!scores.problems.empty()) {
    out << formatted("\nproblems (%zu):\n", scores.problems.size());
    for (std::size_t i = 0; i < scores.problems.size() && i < 40; ++i) {
      out << "  " << scores.problems[i] << "\n";
    }
    if (scores.problems.size() > 40) {
      out << formatted("  ... and %zu more\n", scores.problems.size() - 40);
    }
  }
  return out.str();
}

nlohmann::json sceneLookJson(const SceneLook& look) {
  nlohmann::json json;
  json["workcell"] = look.workcell;
  json["camera_noise_seed"] = look.noise_seed;
  if (look.arm_over) {
    json["arm"] = std::vector<double>(look.arm_over->arm.begin(), look.arm_over->arm.end());
    json["fingers"] = look.arm_over->fingers;
  }
  return json;
}

SceneLook loadSceneLook(const std::filesystem::path& file) {
  const auto fail = [&file](const std::string& field, const std::string& problem) {
    return std::runtime_error("look file '" + file.string() + "': " + field + ": " + problem);
  };
  nlohmann::json json;
  try {
    json = core::readJsonFile(file);
  } catch (const std::exception& e) {
    throw std::runtime_error("look file '" + file.string() + "': " + e.what());
  }
  if (!json.is_object()) {
    throw fail("(top level)", "must be an object");
  }
  for (const auto& [key, value] : json.items()) {
    if (key != "workcell" && key != "camera_noise_seed" && key != "arm" && key != "fingers") {
      throw fail(key, "unknown field (known: workcell, camera_noise_seed, arm, fingers)");
    }
  }
  SceneLook look;
  if (!json.contains("workcell") || !json["workcell"].is_string()) {
    throw fail("workcell", "must be the cell's name");
  }
  look.workcell = json["workcell"].get<std::string>();
  if (!json.contains("camera_noise_seed") || !json["camera_noise_seed"].is_number_unsigned()) {
    throw fail("camera_noise_seed", "must be a whole number from 0");
  }
  look.noise_seed = json["camera_noise_seed"].get<std::uint64_t>();
  if (json.contains("arm") != json.contains("fingers")) {
    throw fail(json.contains("arm") ? "fingers" : "arm", "missing (the arm and its fingers are given together)");
  }
  if (json.contains("arm")) {
    const auto numbers = [&](const std::string& field) {
      const nlohmann::json& values = json[field];
      if (!values.is_array() || values.empty()) {
        throw fail(field, "must be a list of numbers");
      }
      std::vector<double> out;
      for (std::size_t i = 0; i < values.size(); ++i) {
        if (!values[i].is_number() || !std::isfinite(values[i].get<double>())) {
          throw fail(field + "[" + std::to_string(i) + "]", "must be a finite number");
        }
        out.push_back(values[i].get<double>());
      }
      return out;
    };
    ArmOverPose pose;
    const std::vector<double> arm = numbers("arm");
    if (arm.size() > static_cast<std::size_t>(arm::kMaxJoints)) {
      throw fail("arm", "an arm has at most " + std::to_string(arm::kMaxJoints) + " joints, not " +
                            std::to_string(arm.size()));
    }
    pose.arm = sim::ArmJoints(static_cast<int>(arm.size()));
    for (std::size_t j = 0; j < arm.size(); ++j) {
      pose.arm[static_cast<int>(j)] = arm[j];
    }
    pose.fingers = numbers("fingers");
    look.arm_over = pose;
  }
  return look;
}

SceneDetection detectInScene(const std::filesystem::path& scene_file, std::optional<std::uint64_t> seed, int frames,
                             const std::string& workcell, const std::optional<SceneLook>& look) {
  if (look && look->workcell != workcell) {
    throw std::runtime_error("the look was made in cell '" + look->workcell + "', not '" + workcell +
                             "' (run it with -w " + look->workcell + ")");
  }
  const workcell::CellSimulation cell = workcell::cellSimulation(workcell);
  perception::PerceptionConfig config = cellConfig(cell);
  config.frames = frames;
  const auto pipeline = perception::loadPipeline(config);
  const sim::Scene scene = sim::loadScene(scene_file);
  sim::SimulationOptions sim_options = cell.options;
  if (seed || !look) {
    sim_options.placement_seed = seed;
  }
  SimClock clock;
  std::unique_ptr<sim::Simulation> simulation;
  if (look && look->arm_over) {
    try {
      simulation = simulationWithArmOver(scene, armOverOptions(sim_options), *look->arm_over);
    } catch (const std::invalid_argument& e) {
      throw std::runtime_error("the look's arm does not fit cell '" + workcell + "': " + e.what());
    }
  } else {
    simulation = sim::Simulation::create(scene, sim_options);
  }
  simulation->attach(clock);
  if (look && look->arm_over) {
    clock.advanceBy(kFingersSettle);
  }
  sim::SimRgbdCamera camera(*simulation, look ? look->noise_seed : seed.value_or(scene.seed));
  perception::PerceptionComponent component(camera, clock, pipeline, config);
  const perception::PipelineResult result = detectOnce(component, clock, frames);
  const std::vector<world::ObjectClass> classes = classesOf(*pipeline);
  SceneDetection out;
  out.detected = seenObjects(component);
  out.truth = truthSeenIn(*simulation, *result.filtered, *pipeline);
  out.match = matchToTruth(out.detected, out.truth, classes);
  out.milliseconds = millis(result.times.total);
  out.picture = pictureOf(*result.filtered, out.detected, out.truth, out.match, classes);
  return out;
}

}  // namespace costar::trials
