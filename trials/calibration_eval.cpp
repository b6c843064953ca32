#include "trials/calibration_eval.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

#include "core/paths.h"
#include "perception/canonical_orientation.h"
#include "perception/perception_component.h"
#include "sim/simulation.h"
#include "workcell/workcell.h"

namespace costar::trials {

namespace {

constexpr double kDeg = M_PI / 180.0;

/// A pose from a Calibrate result's {"xyz", "rpy_deg"}.
world::Pose poseOf(const nlohmann::json& json) {
  const auto& t = json.at("xyz");
  const auto& r = json.at("rpy_deg");
  return world::poseFromXyzRpy(t.at(0).get<double>(), t.at(1).get<double>(), t.at(2).get<double>(),
                               r.at(0).get<double>() * kDeg, r.at(1).get<double>() * kDeg,
                               r.at(2).get<double>() * kDeg);
}

std::unique_ptr<workcell::Workcell> makeCell(const CalibrationEvalOptions& options, std::uint64_t seed) {
  workcell::WorkcellOptions cell;
  cell.name = options.workcell;
  cell.scene = options.scene.empty() ? dataRoot() / "sim/scenes/assembly.json" : options.scene;
  cell.seed = seed;
  cell.memory_only = true;
  cell.camera_move = workcell::WorkcellOptions::CameraMove{options.camera_move_m, options.camera_turn_deg, {}};
  return workcell::makeWorkcell(cell);
}

/// DetectObjects once in `cell`; the parts found within 5 mm and 5 degrees of their true pose
/// (one detection per part: same class, nearest centre within 2.5 cm; rotation error the
/// smallest over the class's symmetries).
int accurateParts(workcell::Workcell& cell) {
  const component::OperationResult detected =
      workcell::runOperation(cell, "DetectObjects", {}, std::chrono::seconds(30));
  if (detected.state != component::OperationState::kSuccess) {
    return 0;
  }
  auto* perception = dynamic_cast<perception::PerceptionComponent*>(cell.components().provider("DetectObjects"));
  if (perception == nullptr) {
    return 0;
  }
  std::vector<perception::TrackedObject> objects = perception->objects();
  std::erase_if(objects, [](const perception::TrackedObject& o) { return o.missed > 0; });
  std::vector<bool> used(objects.size(), false);
  int accurate = 0;
  for (const sim::PartState& part : cell.simulation()->parts()) {
    int best = -1;
    double nearest = 0.025;
    for (std::size_t d = 0; d < objects.size(); ++d) {
      const double distance = (objects[d].pose.translation() - part.pose.translation()).norm();
      if (!used[d] && objects[d].object_class == part.object_class && distance < nearest) {
        nearest = distance;
        best = static_cast<int>(d);
      }
    }
    if (best < 0) {
      continue;
    }
    used[static_cast<std::size_t>(best)] = true;
    const perception::ObjectModel* model = perception->pipeline().model(part.object_class);
    const double angle =
        model == nullptr ? M_PI
                         : perception::symmetricRotationDistance(objects[static_cast<std::size_t>(best)].pose.linear(),
                                                                 part.pose.linear(), model->object_class);
    if (nearest <= 0.005 && angle <= 5 * kDeg) {
      ++accurate;
    }
  }
  return accurate;
}

void runSample(const CalibrationEvalOptions& options, int setup, const std::string& method, CalibrationSample& s) {
  const std::uint64_t seed = options.seed + static_cast<std::uint64_t>(setup);
  const auto cell = makeCell(options, seed);
  if (cell->simulation() == nullptr) {
    throw std::invalid_argument("workcell '" + options.workcell +
                                "' is not simulated: calibrate eval needs the simulator's true camera pose");
  }
  sim::Simulation& simulation = *cell->simulation();
  const world::Pose truth = simulation.rgbdPose();
  const world::Pose drawn = simulation.rgbdNominalPose();
  s.camera_before_mm = (drawn.translation() - truth.translation()).norm() * 1000;
  s.camera_before_deg = world::rotationAngle(drawn, truth) / kDeg;
  const Duration limit = std::chrono::seconds(300);
  if (!method.empty()) {
    component::ParamMap params{{"method", component::Value(method)}, {"refine", component::Value(options.refine)}};
    if (options.marker_views > 0) {
      params.emplace("views", component::Value(static_cast<long long>(options.marker_views)));
    }
    const component::OperationResult marker = workcell::runOperation(*cell, "CalibrateMarker", params, limit);
    if (marker.state != component::OperationState::kSuccess) {
      s.marker_ok = false;
      s.reason = marker.reason;
      return;
    }
    const world::Pose x = poseOf(marker.data.at("marker_in_flange"));
    const world::Pose x_true = simulation.gripperMarkerInFlange();
    s.marker_mm = (x.translation() - x_true.translation()).norm() * 1000;
    s.marker_deg = world::rotationAngle(x, x_true) / kDeg;
    const world::Pose y = poseOf(marker.data.at("camera"));
    s.stage_a_camera_mm = (y.translation() - truth.translation()).norm() * 1000;
    s.stage_a_camera_deg = world::rotationAngle(y, truth) / kDeg;
    s.marker_simulated_s = marker.data.value("simulated_s", 0.0);
  }
  if (options.perception) {
    s.parts = static_cast<int>(simulation.parts().size());
    s.parts_accurate_before = accurateParts(*cell);
  }
  component::ParamMap camera_params;
  if (options.camera_views > 0) {
    camera_params.emplace("views", component::Value(static_cast<long long>(options.camera_views)));
  }
  const std::vector<sim::PartState> parts_before = simulation.parts();
  const component::OperationResult camera = workcell::runOperation(*cell, "Calibrate", camera_params, limit);
  const std::vector<sim::PartState> parts_after = simulation.parts();
  for (std::size_t i = 0; i < parts_before.size() && i < parts_after.size(); ++i) {
    s.parts_moved_mm = std::max(s.parts_moved_mm,
                                (parts_after[i].pose.translation() - parts_before[i].pose.translation()).norm() * 1000);
  }
  if (camera.state != component::OperationState::kSuccess) {
    s.reason = camera.reason;
    return;
  }
  s.camera_ok = true;
  const world::Pose y = poseOf(camera.data.at("camera"));
  s.camera_mm = (y.translation() - truth.translation()).norm() * 1000;
  s.camera_deg = world::rotationAngle(y, truth) / kDeg;
  s.camera_simulated_s = camera.data.value("simulated_s", 0.0);
  s.reprojection_rms_px = camera.data.at("residuals").value("reprojection_rms_px", 0.0);
  if (options.perception) {
    s.parts_accurate_after = accurateParts(*cell);
  }
}

double median(std::vector<double> v) {
  if (v.empty()) {
    return 0.0;
  }
  std::sort(v.begin(), v.end());
  return v.size() % 2 == 1 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

}  // namespace

CalibrationEvalSummary evaluateCalibration(const CalibrationEvalOptions& options,
                                           const std::function<void(const CalibrationSample&)>& progress) {
  CalibrationEvalSummary summary;
  const std::vector<std::string> methods = options.methods.empty() ? std::vector<std::string>{""} : options.methods;
  for (int setup = 0; setup < options.setups; ++setup) {
    for (const std::string& method : methods) {
      CalibrationSample sample;
      sample.setup = setup;
      sample.method = method;
      try {
        runSample(options, setup, method, sample);
      } catch (const std::exception& e) {
        sample.camera_ok = false;
        sample.reason = e.what();
      }
      if (progress) {
        progress(sample);
      }
      summary.samples.push_back(sample);
    }
  }
  return summary;
}

nlohmann::json CalibrationEvalSummary::toJson() const {
  nlohmann::json list = nlohmann::json::array();
  for (const auto& s : samples) {
    list.push_back({{"setup", s.setup},
                    {"method", s.method.empty() ? "cell" : s.method},
                    {"ok", s.camera_ok},
                    {"reason", s.reason},
                    {"camera_before_mm", s.camera_before_mm},
                    {"camera_before_deg", s.camera_before_deg},
                    {"marker_mm", s.marker_mm},
                    {"marker_deg", s.marker_deg},
                    {"stage_a_camera_mm", s.stage_a_camera_mm},
                    {"stage_a_camera_deg", s.stage_a_camera_deg},
                    {"camera_mm", s.camera_mm},
                    {"camera_deg", s.camera_deg},
                    {"marker_simulated_s", s.marker_simulated_s},
                    {"camera_simulated_s", s.camera_simulated_s},
                    {"reprojection_rms_px", s.reprojection_rms_px},
                    {"parts_moved_mm", s.parts_moved_mm},
                    {"parts", s.parts},
                    {"parts_accurate_before", s.parts_accurate_before},
                    {"parts_accurate_after", s.parts_accurate_after}});
  }
  return {{"samples", list}};
}

std::string CalibrationEvalSummary::text() const {
  std::map<std::string, std::vector<const CalibrationSample*>> by_method;
  for (const auto& s : samples) {
    by_method[s.method.empty() ? "cell" : s.method].push_back(&s);
  }
  std::string out =
      "method       ok     marker X: med mm / deg   stage (a) camera: med mm / deg   Calibrate camera: med mm / deg "
      "(max mm / deg)   sim s: marker / Calibrate (med)\n";
  for (const auto& [method, list] : by_method) {
    std::vector<double> xm, xd, am, ad, cm, cd, ms, cs;
    int ok = 0;
    for (const auto* s : list) {
      if (!s->camera_ok) {
        continue;
      }
      ++ok;
      xm.push_back(s->marker_mm);
      xd.push_back(s->marker_deg);
      am.push_back(s->stage_a_camera_mm);
      ad.push_back(s->stage_a_camera_deg);
      cm.push_back(s->camera_mm);
      cd.push_back(s->camera_deg);
      ms.push_back(s->marker_simulated_s);
      cs.push_back(s->camera_simulated_s);
    }
    const auto largest = [](const std::vector<double>& v) {
      return v.empty() ? 0.0 : *std::max_element(v.begin(), v.end());
    };
    char line[400];
    std::snprintf(
        line, sizeof line,
        "%-12s %2d/%-2zu  %7.2f / %6.3f          %7.2f / %6.3f                %6.2f / %6.3f (%6.2f / %6.3f)        "
        "%5.1f / %5.1f\n",
        method.c_str(), ok, list.size(), median(xm), median(xd), median(am), median(ad), median(cm), median(cd),
        largest(cm), largest(cd), median(ms), median(cs));
    out += line;
  }
  double moved = 0.0;
  int calibrated = 0;
  for (const auto& s : samples) {
    if (s.camera_ok) {
      moved = std::max(moved, s.parts_moved_mm);
      ++calibrated;
    }
  }
  if (calibrated > 0) {
    char line[200];
    std::snprintf(line, sizeof line, "Parts moved while Calibrate ran (true poses): at most %.1f mm over %d run(s)\n",
                  moved, calibrated);
    out += line;
  }
  int parts = 0;
  int before = 0;
  int after = 0;
  for (const auto& s : samples) {
    if (s.camera_ok && s.parts > 0) {
      parts += s.parts;
      before += s.parts_accurate_before;
      after += s.parts_accurate_after;
    }
  }
  if (parts > 0) {
    char line[300];
    std::snprintf(
        line, sizeof line,
        "DetectObjects, parts within 5 mm and 5 deg of the truth: %d/%d (%.1f %%) with the drawn camera pose, "
        "%d/%d (%.1f %%) after Calibrate\n",
        before, parts, 100.0 * before / parts, after, parts, 100.0 * after / parts);
    out += line;
  }
  return out;
}

}  // namespace costar::trials
