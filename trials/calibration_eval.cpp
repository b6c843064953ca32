#include "trials/calibration_eval.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

#include "core/paths.h"
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
  cell.scene = options.scene.empty() ? dataRoot() / "sim/scenes/assembly.json" : options.scene;
  cell.seed = seed;
  cell.memory_only = true;
  cell.camera_move = workcell::WorkcellOptions::CameraMove{options.camera_move_m, options.camera_turn_deg, {}};
  return workcell::makeWorkcell(cell);
}

void runSample(const CalibrationEvalOptions& options, int setup, const std::string& method, CalibrationSample& s) {
  const std::uint64_t seed = options.seed + static_cast<std::uint64_t>(setup);
  const auto cell = makeCell(options, seed);
  sim::Simulation& simulation = *cell->simulation();
  const world::Pose truth = simulation.rgbdPose();
  const world::Pose drawn = simulation.rgbdNominalPose();
  s.camera_before_mm = (drawn.translation() - truth.translation()).norm() * 1000;
  s.camera_before_deg = world::rotationAngle(drawn, truth) / kDeg;
  const Duration limit = std::chrono::seconds(300);
  if (!method.empty()) {
    const component::OperationResult marker = workcell::runOperation(
        *cell, "CalibrateMarker", {{"method", component::Value(method)}, {"refine", component::Value(options.refine)}},
        limit);
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
  const component::OperationResult camera = workcell::runOperation(*cell, "Calibrate", {}, limit);
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
                    {"reprojection_rms_px", s.reprojection_rms_px}});
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
  return out;
}

}  // namespace costar::trials
