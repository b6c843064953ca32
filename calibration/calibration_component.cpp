#include "calibration/calibration_component.h"

#include <cmath>
#include <cstdio>

#include "calibration/marker_corners.h"
#include "calibration/view_planner.h"
#include "perception/aruco_marker.h"

namespace costar::calibration {

using component::OperationResult;
using component::ParamSpec;
using component::ValueType;

namespace {

constexpr double kDeg = M_PI / 180.0;

double round(double value, double step) { return std::round(value / step) * step; }

nlohmann::json poseSummary(const world::Pose& pose) {
  const Eigen::Vector3d t = pose.translation();
  const Eigen::Vector3d rpy = world::rpyOf(pose.linear()) / kDeg;
  return {{"xyz", {round(t.x(), 1e-5), round(t.y(), 1e-5), round(t.z(), 1e-5)}},
          {"rpy_deg", {round(rpy.x(), 1e-3), round(rpy.y(), 1e-3), round(rpy.z(), 1e-3)}}};
}

nlohmann::json residualSummary(const Residuals& r) {
  return {{"reprojection_rms_px", round(r.reprojection_rms_px, 1e-3)},
          {"reprojection_max_px", round(r.reprojection_max_px, 1e-3)},
          {"aruco_rotation_deg", round(r.rotation_deg, 1e-3)},
          {"aruco_translation_mm", round(r.translation_m * 1000, 1e-2)}};
}

}  // namespace

/// One calibration: shows the marker to the camera from the chosen poses, one after the other
/// (move, rest, take a frame, find the marker), then solves, moves the arm back to where it
/// started, and accepts the result or keeps the previous calibration.
class CalibrationRun final : public component::RunningOperation {
 public:
  CalibrationRun(CalibrationComponent& component, bool marker_stage, int views, HandEyeMethod method, bool refine,
                 double speed)
      : c_(component),
        marker_stage_(marker_stage),
        refine_(refine),
        wanted_(views),
        method_(method),
        speed_(speed),
        started_(component.clock_.now()),
        start_joints_(component.motion_.joints()) {
    if (const auto& area = component.config_.keep_out) {
      // The parts' area is an obstacle of every plan of this run.
      scene_.obstacles.push_back({kKeepOutObstacle, world::Pose(Eigen::Translation3d(area->center())), area->sizes()});
      keeping_out_ = true;
      if (const auto contact = c_.motion_.collision(start_joints_, scene_);
          contact && contact->other == kKeepOutObstacle) {
        release();
        done_ = OperationResult::failure(
            operation() + ": the arm is in the table's part area (" + contact->str() +
            "), where it cannot move without the risk of pushing a part: move it up first (e.g. Home); the previous "
            "calibration is kept");
        return;
      }
    }
    const CellCalibration now = component.calibration();
    marker_in_flange_ = marker_stage ? component.config_.marker_in_flange_guess : *now.marker_in_flange;
    aim_camera_ = component.cameraPose();
    ViewPlanOptions plan;
    plan.region_min = component.config_.region_min;
    plan.region_max = component.config_.region_max;
    plan.seed = component.config_.seed;
    if (marker_stage) {
      plan.tilt_deg = component.config_.tilt_deg;
      plan.roll_deg = component.config_.roll_deg;
      plan.min_separation_deg = component.config_.min_view_separation_deg;
    } else {
      plan.facing_roll_deg = component.config_.camera_roll_deg;
    }
    candidates_ = candidateMarkerPoses(aim_camera_, plan, 4 * views + 8);
  }

  ~CalibrationRun() override { release(); }

  OperationResult poll() override {
    if (done_) {
      return *done_;
    }
    if (motion_) {
      const OperationResult moved = motion_->poll();
      if (moved.state == component::OperationState::kRunning) {
        return OperationResult::running();
      }
      motion_.reset();
      if (returning_) {
        return finish();
      }
      if (moved.state == component::OperationState::kFailure) {
        skipped_.push_back("view " + std::to_string(tried_) + ": " + moved.reason);
      } else {
        settle_until_ = c_.clock_.now() + c_.config_.settle;
      }
    }
    if (settle_until_ && c_.clock_.now() < *settle_until_) {
      return OperationResult::running();
    }
    if (settle_until_) {
      settle_until_.reset();
      takeView();
    }
    if (static_cast<int>(views_.size()) >= wanted_ || next_ >= candidates_.size() ||
        c_.clock_.now() - started_ > c_.config_.time_budget) {
      solve();
      return goBack();
    }
    startNextMotion();
    return OperationResult::running();
  }

  void cancel() override {
    if (motion_) {
      motion_->cancel();
      motion_.reset();
    }
    release();
    done_ = OperationResult::failure(operation() + " was cancelled; the previous calibration is kept");
  }

 private:
  std::string operation() const { return marker_stage_ ? "CalibrateMarker" : "Calibrate"; }

  /// The run is over: another calibration may start.
  void release() {
    std::lock_guard lock(c_.mutex_);
    c_.running_ = false;
  }

  /// Runs a plan with the arm's FollowJointPath (called `what` in messages).
  std::unique_ptr<component::RunningOperation> follow(const arm::MotionPlan& plan, const std::string& what) {
    return std::make_unique<component::DelegatedOperation>(c_.arm_, std::string(arm::kFollowJointPath),
                                                           arm::followParams(plan, what));
  }

  /// The next candidate the camera would see (by the current estimate) and the arm can reach
  /// without collision; the motion to it starts. With a keep-out, a candidate the arm cannot
  /// reach is tried again higher (lift_step at a time, up to the top of the views' region):
  /// low views are the ones whose fingers would enter the parts' area.
  void startNextMotion() {
    const CalibrationConfig& config = c_.config_;
    const camera::Intrinsics& intrinsics = c_.camera_.intrinsics();
    const world::Pose& tcp_in_flange = config.tcp_in_flange;
    while (next_ < candidates_.size()) {
      const world::Pose candidate = candidates_[next_++];
      bool counted = false;
      for (double lift = 0.0; lift == 0.0 || (keeping_out_ && config.lift_step > 0 &&
                                              candidate.translation().z() + lift <= config.region_max.z() + 1e-9);
           lift += config.lift_step) {
        world::Pose marker = candidate;
        marker.translation().z() += lift;
        if (!markerInView(marker, config.solve.marker_size, aim_camera_, intrinsics, config.image_margin_px,
                          config.max_view_angle_deg)) {
          continue;
        }
        if (!counted) {
          ++tried_;
          counted = true;
        }
        const world::Pose tcp = marker * marker_in_flange_.inverse() * tcp_in_flange;
        const arm::MotionPlan plan = c_.motion_.planToPose(c_.motion_.joints(), tcp, speed_, scene_);
        if (!plan.ok()) {
          continue;
        }
        if (lift > 0.0) {
          ++lifted_;
        }
        motion_ = follow(plan, operation() + " view " + std::to_string(tried_));
        return;
      }
      if (counted) {
        ++unreachable_;
      }
    }
  }

  /// Takes a frame at rest and finds the marker in it.
  void takeView() {
    const camera::RgbdFrame frame = c_.camera_.capture();
    const world::Pose flange = c_.motion_.endpoint() * c_.config_.tcp_in_flange.inverse();
    for (const auto& detection :
         perception::detectArucoMarkers(frame.rgb, frame.intrinsics, c_.config_.solve.marker_size)) {
      if (detection.id != c_.config_.marker_id || detection.corners.size() != 4) {
        continue;
      }
      MarkerView view;
      view.flange_in_world = flange;
      view.marker_in_camera = detection.pose_in_camera;
      for (std::size_t k = 0; k < 4; ++k) {
        view.corners[k] = detection.corners[k];
      }
      if (c_.config_.refine_corners) {
        view.corners = refineMarkerCorners(frame.rgb, view.corners);
        if (const auto pose = markerPoseFromCorners(view.corners, frame.intrinsics, c_.config_.solve.marker_size)) {
          view.marker_in_camera = *pose;
        }
      }
      views_.push_back(view);
      // Aim the next views with what this one says about the camera.
      aim_camera_ = flange * marker_in_flange_ * view.marker_in_camera.inverse();
      return;
    }
    ++not_seen_;
  }

  void solve() {
    const camera::Intrinsics& intrinsics = c_.camera_.intrinsics();
    const SolveOptions& options = c_.config_.solve;
    try {
      CellCalibration next = c_.calibration();
      const world::Pose before = c_.cameraPose();
      nlohmann::json data;
      if (marker_stage_) {
        SolveOptions with_guess = options;
        with_guess.marker_in_flange_guess = c_.config_.marker_in_flange_guess;
        const MarkerCalibration result = solveMarker(views_, intrinsics, method_, refine_, with_guess);
        next.marker_in_flange = result.marker_in_flange;
        next.marker_method = methodName(method_) + (refine_ ? "+reprojection" : "");
        next.marker_residuals = result.residuals;
        next.marker_views = result.views;
        next.camera_in_world = result.camera_in_world;
        next.camera_residuals = result.residuals;
        next.camera_views = result.views;
        data["marker_in_flange"] = poseSummary(result.marker_in_flange);
        data["method"] = next.marker_method;
        data["views_rejected"] = result.rejected;
        // The unrefined solution of every method on the same views, for comparison.
        nlohmann::json methods = nlohmann::json::object();
        for (const HandEyeMethod method : allMethods()) {
          try {
            const MarkerCalibration raw = solveMarker(views_, intrinsics, method, false,
                                                      {.marker_size = options.marker_size,
                                                       .min_marker_views = options.min_marker_views,
                                                       .min_rotation_spread_deg = options.min_rotation_spread_deg,
                                                       .max_reprojection_rms_px = 1e9});
            methods[methodName(method)] = {{"marker_in_flange", poseSummary(raw.marker_in_flange)},
                                           {"camera", poseSummary(raw.camera_in_world)},
                                           {"residuals", residualSummary(raw.residuals)}};
          } catch (const std::exception& e) {
            methods[methodName(method)] = {{"error", e.what()}};
          }
        }
        data["methods_unrefined"] = methods;
      } else {
        const CameraCalibration result = solveCamera(views_, intrinsics, marker_in_flange_, options);
        next.camera_in_world = result.camera_in_world;
        next.camera_residuals = result.residuals;
        next.camera_views = result.views;
        data["views_rejected"] = result.rejected;
      }
      data["camera"] = poseSummary(*next.camera_in_world);
      data["camera_moved_mm"] = round((next.camera_in_world->translation() - before.translation()).norm() * 1000, 1e-2);
      data["camera_turned_deg"] = round(world::rotationAngle(*next.camera_in_world, before) / kDeg, 1e-3);
      data["residuals"] = residualSummary(marker_stage_ ? next.marker_residuals : next.camera_residuals);
      data["views"] = views_.size();
      data["poses_tried"] = tried_;
      data["unreachable"] = unreachable_;
      data["lifted"] = lifted_;
      data["marker_not_seen"] = not_seen_;
      if (const std::string problem = c_.accept(next); !problem.empty()) {
        data["warning"] = problem;
      }
      char summary[240];
      std::snprintf(
          summary, sizeof summary,
          "camera moved %.1f mm and turned %.2f deg from the previous calibration; the marker's corners fit to "
          "%.2f px RMS over %zu views",
          data["camera_moved_mm"].get<double>(), data["camera_turned_deg"].get<double>(),
          (marker_stage_ ? next.marker_residuals : next.camera_residuals).reprojection_rms_px, views_.size());
      result_ = OperationResult::success(std::move(data));
      result_.reason = summary;
    } catch (const CalibrationError& e) {
      nlohmann::json data = {{"views", views_.size()},
                             {"poses_tried", tried_},
                             {"unreachable", unreachable_},
                             {"marker_not_seen", not_seen_}};
      if (!skipped_.empty()) {
        data["motion_problems"] = skipped_;
      }
      result_ = OperationResult::failure(std::string(e.what()) + "; the previous calibration is kept", data);
    }
  }

  /// Back to where the arm started.
  OperationResult goBack() {
    returning_ = true;
    const arm::MotionPlan plan = c_.motion_.planToJoints(c_.motion_.joints(), start_joints_, speed_, scene_);
    if (!plan.ok()) {
      return finish();  // already there, or no way back: the result stands either way
    }
    motion_ = follow(plan, operation() + ": back to the start");
    return OperationResult::running();
  }

  OperationResult finish() {
    release();
    if (result_.state == component::OperationState::kSuccess) {
      result_.data["simulated_s"] = round(toSeconds(c_.clock_.now() - started_), 1e-3);
    }
    done_ = result_;
    return *done_;
  }

  CalibrationComponent& c_;
  bool marker_stage_;
  bool refine_;
  int wanted_;
  HandEyeMethod method_;
  double speed_;
  TimePoint started_;
  arm::JointVector start_joints_;
  world::Pose marker_in_flange_ = world::Pose::Identity();
  world::Pose aim_camera_ = world::Pose::Identity();
  std::vector<world::Pose> candidates_;
  std::size_t next_ = 0;
  int tried_ = 0;
  int unreachable_ = 0;
  int lifted_ = 0;
  int not_seen_ = 0;
  std::vector<std::string> skipped_;
  std::vector<MarkerView> views_;
  std::unique_ptr<component::RunningOperation> motion_;
  std::optional<TimePoint> settle_until_;
  bool returning_ = false;
  /// What every motion query of the run sees besides the cell: the keep-out, if any.
  arm::QueryScene scene_;
  bool keeping_out_ = false;
  OperationResult result_;
  std::optional<OperationResult> done_;
};

CalibrationComponent::CalibrationComponent(const arm::MotionService& motion, component::Component& arm,
                                           camera::RgbdCamera& camera, const Clock& clock,
                                           const world::Pose& drawn_camera_pose, CellCalibration initial,
                                           CalibrationConfig config)
    : motion_(motion),
      arm_(arm),
      camera_(camera),
      clock_(clock),
      drawn_camera_pose_(drawn_camera_pose),
      config_(std::move(config)),
      calibration_(std::move(initial)) {
  component::ComponentDescription description;
  description.name = config_.name;
  description.type = "HandEyeCalibration";
  description.inputs = {"rgbd_frames", "joint_states"};
  description.outputs = {"camera_pose"};
  ParamSpec speed{"speed", ValueType::kDouble, "fraction of the arm's top speed", config_.speed};
  speed.min = 0.05;
  speed.max = 1.0;
  ParamSpec camera_views{"views", ValueType::kInt, "views of the marker to take",
                         static_cast<long long>(config_.camera_views)};
  camera_views.min = 3;
  camera_views.max = 20;
  ParamSpec marker_views{"views", ValueType::kInt, "views of the marker to take",
                         static_cast<long long>(config_.marker_views)};
  marker_views.min = 6;
  marker_views.max = 40;
  std::vector<std::string> methods;
  for (const HandEyeMethod method : allMethods()) {
    methods.push_back(methodName(method));
  }
  ParamSpec method{"method", ValueType::kString,
                   "hand-eye method: daniilidis (dual quaternions, the paper's), tsai, park, horaud, andreff, or the "
                   "robot-world shah, li; refined on the corners' reprojection",
                   std::string("daniilidis"), methods};
  ParamSpec refine{"refine", ValueType::kBool,
                   "refine the hand-eye solution on the marker corners' reprojection error (off: the method's own "
                   "solution, for comparison)",
                   true};
  component::OperationTable operations;
  operations.add(
      {"Calibrate",
       "Finds where the camera is: the arm shows the marker on the gripper to the camera from a few poses it chooses; "
       "perception uses the new camera pose at once. Needs the marker calibration (CalibrateMarker, once).",
       {camera_views, speed}},
      [this](const component::ParamMap& params) { return beginCalibration(false, params); });
  operations.add(
      {"CalibrateMarker",
       "Once, after fixing the marker to the gripper: finds where it is on the flange by hand-eye calibration (the arm "
       "shows it to the camera from many poses), and the camera with it.",
       {marker_views, method, refine, speed}},
      [this](const component::ParamMap& params) { return beginCalibration(true, params); });
  description.symbols = {{"camera", world::SymbolKind::kFrame, "the RGB-D camera's optical frame, as calibrated"}};
  description.predicates = {{"camera_calibrated", 0, "the camera's pose comes from a calibration"}};
  declare(std::move(description), std::move(operations));
}

world::Pose CalibrationComponent::cameraPose() const {
  std::lock_guard lock(mutex_);
  return calibration_.camera_in_world.value_or(drawn_camera_pose_);
}

CellCalibration CalibrationComponent::calibration() const {
  std::lock_guard lock(mutex_);
  return calibration_;
}

world::Report CalibrationComponent::report() const {
  std::lock_guard lock(mutex_);
  world::Report report;
  report.symbols.push_back({"camera", "", clock_.now(),
                            world::FrameValue{"world", calibration_.camera_in_world.value_or(drawn_camera_pose_)}});
  if (calibration_.camera_in_world) {
    report.predicates.push_back({"camera_calibrated", {}, true, ""});
  }
  return report;
}

std::string CalibrationComponent::accept(const CellCalibration& next) {
  {
    std::lock_guard lock(mutex_);
    calibration_ = next;
  }
  if (config_.file.empty()) {
    return {};
  }
  try {
    saveCalibration(config_.file, next);
  } catch (const std::exception& e) {
    return std::string("in use, but not saved: ") + e.what();
  }
  return {};
}

std::unique_ptr<component::RunningOperation> CalibrationComponent::beginCalibration(bool marker_stage,
                                                                                    const component::ParamMap& params) {
  const auto failed = [](std::string reason) {
    return std::make_unique<component::FinishedOperation>(OperationResult::failure(std::move(reason)));
  };
  const std::string operation = marker_stage ? "CalibrateMarker" : "Calibrate";
  const auto number = [&params](const char* name, double fallback) {
    const auto it = params.find(name);
    return it == params.end() ? fallback : it->second.asDouble();
  };
  const int views = static_cast<int>(number("views", marker_stage ? config_.marker_views : config_.camera_views));
  const double speed = number("speed", config_.speed);
  const auto refine_it = params.find("refine");
  const bool refine = refine_it == params.end() || refine_it->second.asBool();
  HandEyeMethod method = HandEyeMethod::kDaniilidis;
  if (const auto it = params.find("method"); it != params.end()) {
    try {
      method = methodFromName(it->second.asString());
    } catch (const std::invalid_argument& e) {
      return failed(operation + ": " + e.what());
    }
  }
  {
    std::lock_guard lock(mutex_);
    if (!marker_stage && !calibration_.marker_in_flange) {
      return failed(
          "Calibrate: the marker's place on the gripper is not known yet: run CalibrateMarker once (`costar calibrate "
          "marker`) after fixing the marker to the gripper");
    }
    if (running_) {
      return failed(operation + ": a calibration is already running");
    }
    running_ = true;
  }
  return std::make_unique<CalibrationRun>(*this, marker_stage, views, method, refine, speed);
}

}  // namespace costar::calibration
