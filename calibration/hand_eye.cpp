#include "calibration/hand_eye.h"

#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>

#include <unsupported/Eigen/NonLinearOptimization>
#include <unsupported/Eigen/NumericalDiff>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <cstdio>

namespace costar::calibration {

namespace {

constexpr double kDeg = M_PI / 180.0;

std::string format(const char* pattern, double a, double b = 0.0) {
  char text[400];
  std::snprintf(text, sizeof text, pattern, a, b);
  return text;
}

cv::Mat rotationToCv(const Eigen::Matrix3d& r) {
  cv::Mat m(3, 3, CV_64F);
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      m.at<double>(i, j) = r(i, j);
    }
  }
  return m;
}

cv::Mat vectorToCv(const Eigen::Vector3d& t) {
  cv::Mat m(3, 1, CV_64F);
  for (int i = 0; i < 3; ++i) {
    m.at<double>(i, 0) = t(i);
  }
  return m;
}

world::Pose fromCv(const cv::Mat& r, const cv::Mat& t) {
  world::Pose pose = world::Pose::Identity();
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      pose.linear()(i, j) = r.at<double>(i, j);
    }
    pose.translation()(i) = t.at<double>(i, 0);
  }
  return pose;
}

/// A pose moved by a 6-vector (rotation vector, translation) applied on the left.
world::Pose perturbed(const world::Pose& pose, const Eigen::Matrix<double, 6, 1>& delta) {
  const Eigen::Vector3d w = delta.head<3>();
  const double angle = w.norm();
  world::Pose step = world::Pose::Identity();
  if (angle > 1e-15) {
    step.linear() = Eigen::AngleAxisd(angle, w / angle).toRotationMatrix();
  }
  step.translation() = delta.tail<3>();
  return step * pose;
}

Eigen::Vector2d project(const camera::Intrinsics& in, const Eigen::Vector3d& p) {
  return {in.fx * p.x() / p.z() + in.cx, in.fy * p.y() / p.z() + in.cy};
}

double median(std::vector<double> values) {
  if (values.empty()) {
    return 0.0;
  }
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  return values[values.size() / 2];
}

/// The marker in the flange averaged over the views, given the camera: X = F_i^-1 Y B_i.
world::Pose averageMarkerInFlange(const std::vector<MarkerView>& views, const world::Pose& camera_in_world) {
  Eigen::Matrix4d quaternions = Eigen::Matrix4d::Zero();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  for (const auto& view : views) {
    const world::Pose x = view.flange_in_world.inverse() * camera_in_world * view.marker_in_camera;
    const Eigen::Quaterniond q(x.linear());
    const Eigen::Vector4d v = q.coeffs();
    quaternions += v * v.transpose();
    translation += x.translation();
  }
  // The average rotation: the quaternion with the largest eigenvalue of sum q q^T.
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d> solver(quaternions);
  const Eigen::Vector4d best = solver.eigenvectors().col(3);
  world::Pose x = world::Pose::Identity();
  x.linear() = Eigen::Quaterniond(best(3), best(0), best(1), best(2)).normalized().toRotationMatrix();
  x.translation() = translation / static_cast<double>(views.size());
  return x;
}

/// Joint refinement of X and Y on the corners' reprojection error (Levenberg-Marquardt).
struct ReprojectionFunctor {
  using Scalar = double;
  using InputType = Eigen::VectorXd;
  using ValueType = Eigen::VectorXd;
  using JacobianType = Eigen::MatrixXd;
  enum { InputsAtCompileTime = Eigen::Dynamic, ValuesAtCompileTime = Eigen::Dynamic };

  const std::vector<MarkerView>* views;
  camera::Intrinsics intrinsics;
  std::array<Eigen::Vector3d, 4> corners;
  world::Pose x0;
  world::Pose y0;
  bool solve_marker = true;  // false: Y only

  int inputs() const { return solve_marker ? 12 : 6; }
  int values() const { return static_cast<int>(views->size()) * 8; }

  void posesOf(const Eigen::VectorXd& p, world::Pose& x, world::Pose& y) const {
    y = perturbed(y0, p.head<6>());
    x = solve_marker ? perturbed(x0, p.segment<6>(6)) : x0;
  }

  int operator()(const Eigen::VectorXd& p, Eigen::VectorXd& residual) const {
    world::Pose x;
    world::Pose y;
    posesOf(p, x, y);
    const world::Pose world_to_camera = y.inverse();
    int r = 0;
    for (const auto& view : *views) {
      const world::Pose marker_in_camera = world_to_camera * view.flange_in_world * x;
      for (int k = 0; k < 4; ++k) {
        const Eigen::Vector3d c = marker_in_camera * corners[static_cast<std::size_t>(k)];
        const Eigen::Vector2d e = c.z() > 1e-6 ? project(intrinsics, c) - view.corners[static_cast<std::size_t>(k)]
                                               : Eigen::Vector2d(1e3, 1e3);
        residual(r++) = e.x();
        residual(r++) = e.y();
      }
    }
    return 0;
  }
};

void refine(const std::vector<MarkerView>& views, const camera::Intrinsics& intrinsics, double marker_size,
            world::Pose& marker_in_flange, world::Pose& camera_in_world, bool solve_marker) {
  ReprojectionFunctor functor{&views,           intrinsics,      markerCorners(marker_size),
                              marker_in_flange, camera_in_world, solve_marker};
  Eigen::NumericalDiff<ReprojectionFunctor> numeric(functor, 1e-7);
  Eigen::LevenbergMarquardt<Eigen::NumericalDiff<ReprojectionFunctor>, double> solver(numeric);
  solver.parameters.maxfev = 4000;
  solver.parameters.xtol = 1e-12;
  solver.parameters.ftol = 1e-12;
  Eigen::VectorXd p = Eigen::VectorXd::Zero(functor.inputs());
  solver.minimize(p);
  functor.posesOf(p, marker_in_flange, camera_in_world);
}

/// Largest rotation angle between any two views' flange orientations (degrees), and how far
/// from parallel the relative rotation axes are (smallest singular value of their stack).
std::pair<double, double> rotationSpread(const std::vector<MarkerView>& views) {
  double largest = 0.0;
  std::vector<Eigen::Vector3d> axes;
  for (std::size_t i = 0; i < views.size(); ++i) {
    for (std::size_t j = i + 1; j < views.size(); ++j) {
      const Eigen::AngleAxisd relative(views[i].flange_in_world.linear().transpose() *
                                       views[j].flange_in_world.linear());
      largest = std::max(largest, relative.angle() / kDeg);
      if (relative.angle() > 5 * kDeg) {
        axes.push_back(views[i].flange_in_world.linear() * relative.axis());
      }
    }
  }
  double spread = 0.0;
  if (axes.size() >= 2) {
    Eigen::MatrixXd stack(static_cast<Eigen::Index>(axes.size()), 3);
    for (std::size_t i = 0; i < axes.size(); ++i) {
      stack.row(static_cast<Eigen::Index>(i)) = axes[i].transpose();
    }
    const Eigen::JacobiSVD<Eigen::MatrixXd> svd(stack);
    spread = svd.singularValues()(1) / svd.singularValues()(0);
  }
  return {largest, spread};
}

/// Corner RMS (pixels) of each view with X and Y.
std::vector<double> viewErrors(const std::vector<MarkerView>& views, const camera::Intrinsics& intrinsics,
                               const world::Pose& marker_in_flange, const world::Pose& camera_in_world,
                               double marker_size);

/// The views to keep: all but those fitting worse than outlier_factor x the median view (and
/// outlier_floor_px), the worst first, at most a quarter of them, never below `fewest`.
std::vector<MarkerView> inliers(const std::vector<MarkerView>& views, const std::vector<double>& errors,
                                const SolveOptions& options, int fewest) {
  if (options.outlier_factor <= 0 || views.size() < 4) {
    return views;
  }
  const double limit = std::max(options.outlier_factor * median(errors), options.outlier_floor_px);
  std::vector<std::size_t> order(views.size());
  for (std::size_t i = 0; i < order.size(); ++i) {
    order[i] = i;
  }
  std::sort(order.begin(), order.end(), [&errors](std::size_t a, std::size_t b) { return errors[a] > errors[b]; });
  const std::size_t most = std::min(views.size() / 4, views.size() - static_cast<std::size_t>(std::max(fewest, 0)));
  std::vector<bool> drop(views.size(), false);
  for (std::size_t n = 0; n < most && errors[order[n]] > limit; ++n) {
    drop[order[n]] = true;
  }
  std::vector<MarkerView> kept;
  for (std::size_t i = 0; i < views.size(); ++i) {
    if (!drop[i]) {
      kept.push_back(views[i]);
    }
  }
  return kept;
}

}  // namespace

std::array<Eigen::Vector3d, 4> markerCorners(double s) {
  const double h = s / 2;
  return {Eigen::Vector3d(-h, h, 0), Eigen::Vector3d(h, h, 0), Eigen::Vector3d(h, -h, 0), Eigen::Vector3d(-h, -h, 0)};
}

std::string methodName(HandEyeMethod method) {
  switch (method) {
    case HandEyeMethod::kDaniilidis:
      return "daniilidis";
    case HandEyeMethod::kTsai:
      return "tsai";
    case HandEyeMethod::kPark:
      return "park";
    case HandEyeMethod::kHoraud:
      return "horaud";
    case HandEyeMethod::kAndreff:
      return "andreff";
    case HandEyeMethod::kShah:
      return "shah";
    case HandEyeMethod::kLi:
      return "li";
  }
  return "?";
}

std::vector<HandEyeMethod> allMethods() {
  return {HandEyeMethod::kDaniilidis, HandEyeMethod::kTsai, HandEyeMethod::kPark, HandEyeMethod::kHoraud,
          HandEyeMethod::kAndreff,    HandEyeMethod::kShah, HandEyeMethod::kLi};
}

HandEyeMethod methodFromName(const std::string& name) {
  std::string known;
  for (const HandEyeMethod method : allMethods()) {
    if (methodName(method) == name) {
      return method;
    }
    known += (known.empty() ? "" : ", ") + methodName(method);
  }
  throw std::invalid_argument("unknown hand-eye method '" + name + "' (known: " + known + ")");
}

Residuals residualsOf(const std::vector<MarkerView>& views, const camera::Intrinsics& intrinsics,
                      const world::Pose& marker_in_flange, const world::Pose& camera_in_world, double marker_size) {
  Residuals residuals;
  const auto corners = markerCorners(marker_size);
  double sum = 0.0;
  int count = 0;
  std::vector<double> rotations;
  std::vector<double> translations;
  for (const auto& view : views) {
    const world::Pose predicted = camera_in_world.inverse() * view.flange_in_world * marker_in_flange;
    for (std::size_t k = 0; k < 4; ++k) {
      const Eigen::Vector3d c = predicted * corners[k];
      const double e = c.z() > 1e-6 ? (project(intrinsics, c) - view.corners[k]).norm() : 1e3;
      sum += e * e;
      residuals.reprojection_max_px = std::max(residuals.reprojection_max_px, e);
      ++count;
    }
    rotations.push_back(world::rotationAngle(predicted, view.marker_in_camera) / kDeg);
    translations.push_back((predicted.translation() - view.marker_in_camera.translation()).norm());
  }
  residuals.reprojection_rms_px = count > 0 ? std::sqrt(sum / count) : 0.0;
  residuals.rotation_deg = median(rotations);
  residuals.translation_m = median(translations);
  return residuals;
}

namespace {

std::vector<double> viewErrors(const std::vector<MarkerView>& views, const camera::Intrinsics& intrinsics,
                               const world::Pose& marker_in_flange, const world::Pose& camera_in_world,
                               double marker_size) {
  std::vector<double> errors;
  for (const auto& view : views) {
    errors.push_back(
        residualsOf({view}, intrinsics, marker_in_flange, camera_in_world, marker_size).reprojection_rms_px);
  }
  return errors;
}

}  // namespace

MarkerCalibration solveMarker(const std::vector<MarkerView>& views, const camera::Intrinsics& intrinsics,
                              HandEyeMethod method, bool refine_result, const SolveOptions& options) {
  if (static_cast<int>(views.size()) < options.min_marker_views) {
    throw CalibrationError("marker calibration: " + std::to_string(views.size()) + " view(s) of the marker, at least " +
                           std::to_string(options.min_marker_views) +
                           " needed (is the marker on the gripper in the camera's view?)");
  }
  const auto [largest, axis_spread] = rotationSpread(views);
  if (largest < options.min_rotation_spread_deg) {
    throw CalibrationError(
        format("marker calibration: the views differ by at most %.1f degrees of rotation, at least "
               "%.0f needed: the poses are too similar",
               largest, options.min_rotation_spread_deg));
  }
  if (axis_spread < 0.05) {
    throw CalibrationError(
        "marker calibration: the flange turned about one axis only between the views; the hand-eye problem is "
        "degenerate (turn about at least two different axes)");
  }

  MarkerCalibration result;
  result.method = method;
  result.views = static_cast<int>(views.size());
  std::vector<cv::Mat> r_a;
  std::vector<cv::Mat> t_a;
  std::vector<cv::Mat> r_b;
  std::vector<cv::Mat> t_b;
  try {
    if (method == HandEyeMethod::kShah || method == HandEyeMethod::kLi) {
      // Robot-world form: B_i = Y^-1 F_i X, i.e. world2cam_i = gripper2cam base2gripper_i world2base
      // with "world" the marker, "gripper" our world, "base" the flange.
      for (const auto& view : views) {
        r_a.push_back(rotationToCv(view.marker_in_camera.linear()));
        t_a.push_back(vectorToCv(view.marker_in_camera.translation()));
        r_b.push_back(rotationToCv(view.flange_in_world.linear()));
        t_b.push_back(vectorToCv(view.flange_in_world.translation()));
      }
      cv::Mat r_base2world;
      cv::Mat t_base2world;
      cv::Mat r_gripper2cam;
      cv::Mat t_gripper2cam;
      cv::calibrateRobotWorldHandEye(
          r_a, t_a, r_b, t_b, r_base2world, t_base2world, r_gripper2cam, t_gripper2cam,
          method == HandEyeMethod::kShah ? cv::CALIB_ROBOT_WORLD_HAND_EYE_SHAH : cv::CALIB_ROBOT_WORLD_HAND_EYE_LI);
      result.marker_in_flange = fromCv(r_base2world, t_base2world).inverse();
      result.camera_in_world = fromCv(r_gripper2cam, t_gripper2cam).inverse();
    } else {
      // Eye-to-hand through calibrateHandEye: world->flange poses in the gripper2base slots; the
      // result is then the camera in the world (F_i^-1 Y B_i = X for every view).
      for (const auto& view : views) {
        const world::Pose world_in_flange = view.flange_in_world.inverse();
        r_a.push_back(rotationToCv(world_in_flange.linear()));
        t_a.push_back(vectorToCv(world_in_flange.translation()));
        r_b.push_back(rotationToCv(view.marker_in_camera.linear()));
        t_b.push_back(vectorToCv(view.marker_in_camera.translation()));
      }
      const cv::HandEyeCalibrationMethod cv_method = method == HandEyeMethod::kDaniilidis
                                                         ? cv::CALIB_HAND_EYE_DANIILIDIS
                                                     : method == HandEyeMethod::kTsai   ? cv::CALIB_HAND_EYE_TSAI
                                                     : method == HandEyeMethod::kPark   ? cv::CALIB_HAND_EYE_PARK
                                                     : method == HandEyeMethod::kHoraud ? cv::CALIB_HAND_EYE_HORAUD
                                                                                        : cv::CALIB_HAND_EYE_ANDREFF;
      cv::Mat r;
      cv::Mat t;
      cv::calibrateHandEye(r_a, t_a, r_b, t_b, r, t, cv_method);
      result.camera_in_world = fromCv(r, t);
      result.marker_in_flange = averageMarkerInFlange(views, result.camera_in_world);
    }
  } catch (const cv::Exception& e) {
    throw CalibrationError("marker calibration (" + methodName(method) + "): OpenCV failed: " + e.what());
  }
  if (!result.camera_in_world.matrix().allFinite() || !result.marker_in_flange.matrix().allFinite()) {
    throw CalibrationError("marker calibration (" + methodName(method) + "): the solution is degenerate (not finite)");
  }
  if (refine_result) {
    refine(views, intrinsics, options.marker_size, result.marker_in_flange, result.camera_in_world, true);
    result.refined = true;
    if (options.marker_in_flange_guess) {
      // A second start: the drawings' marker, the camera that fits it best.
      SolveOptions loose = options;
      loose.max_reprojection_rms_px = 1e9;
      loose.min_camera_views = 1;
      loose.min_position_spread = 0.0;
      try {
        world::Pose x = *options.marker_in_flange_guess;
        world::Pose y = solveCamera(views, intrinsics, x, loose).camera_in_world;
        refine(views, intrinsics, options.marker_size, x, y, true);
        const double other = residualsOf(views, intrinsics, x, y, options.marker_size).reprojection_rms_px;
        const double mine =
            residualsOf(views, intrinsics, result.marker_in_flange, result.camera_in_world, options.marker_size)
                .reprojection_rms_px;
        if (other < mine) {
          result.marker_in_flange = x;
          result.camera_in_world = y;
        }
      } catch (const CalibrationError&) {
        // keep the method's start
      }
    }
  }
  std::vector<MarkerView> used = views;
  if (refine_result) {
    // Views that do not fit the others left out, and the refinement run again without them.
    used = inliers(views,
                   viewErrors(views, intrinsics, result.marker_in_flange, result.camera_in_world, options.marker_size),
                   options, options.min_marker_views);
    if (used.size() < views.size()) {
      refine(used, intrinsics, options.marker_size, result.marker_in_flange, result.camera_in_world, true);
    }
  }
  result.views = static_cast<int>(used.size());
  result.rejected = static_cast<int>(views.size() - used.size());
  result.residuals =
      residualsOf(used, intrinsics, result.marker_in_flange, result.camera_in_world, options.marker_size);
  if (result.residuals.reprojection_rms_px > options.max_reprojection_rms_px) {
    throw CalibrationError("marker calibration (" + methodName(method) + ")" +
                           format(": the marker's corners are off by %.2f px (RMS) with the solution, more than %.2f "
                                  "allowed (a view with a wrong detection, or the marker loose on the gripper?)",
                                  result.residuals.reprojection_rms_px, options.max_reprojection_rms_px));
  }
  return result;
}

namespace {

/// The camera by one PnP (SQPnP, then Levenberg-Marquardt) over the corners of every view,
/// each corner's world position being F_i X c_k.
world::Pose cameraByPnp(const std::vector<MarkerView>& views, const camera::Intrinsics& intrinsics,
                        const world::Pose& marker_in_flange, double marker_size) {
  const auto corners = markerCorners(marker_size);
  std::vector<cv::Point3d> object;
  std::vector<cv::Point2d> image;
  for (const auto& view : views) {
    const world::Pose marker = view.flange_in_world * marker_in_flange;
    for (std::size_t k = 0; k < 4; ++k) {
      const Eigen::Vector3d p = marker * corners[k];
      object.emplace_back(p.x(), p.y(), p.z());
      image.emplace_back(view.corners[k].x(), view.corners[k].y());
    }
  }
  const cv::Matx33d k(intrinsics.fx, 0, intrinsics.cx, 0, intrinsics.fy, intrinsics.cy, 0, 0, 1);
  const cv::Mat distortion = cv::Mat::zeros(1, 5, CV_64F);
  cv::Mat rvec;
  cv::Mat tvec;
  try {
    if (!cv::solvePnP(object, image, k, distortion, rvec, tvec, false, cv::SOLVEPNP_SQPNP)) {
      throw CalibrationError("Calibrate: no camera pose explains the marker's corners (PnP failed)");
    }
    cv::solvePnPRefineLM(object, image, k, distortion, rvec, tvec);
  } catch (const cv::Exception& e) {
    throw CalibrationError(std::string("Calibrate: OpenCV failed: ") + e.what());
  }
  cv::Mat r;
  cv::Rodrigues(rvec, r);
  const world::Pose camera = fromCv(r, tvec).inverse();  // PnP gives world -> camera
  if (!camera.matrix().allFinite()) {
    throw CalibrationError("Calibrate: the solution is degenerate (not finite)");
  }
  return camera;
}

}  // namespace

CameraCalibration solveCamera(const std::vector<MarkerView>& views, const camera::Intrinsics& intrinsics,
                              const world::Pose& marker_in_flange, const SolveOptions& options) {
  if (static_cast<int>(views.size()) < options.min_camera_views) {
    throw CalibrationError("Calibrate: " + std::to_string(views.size()) +
                           " view(s) of the gripper's marker, at least " + std::to_string(options.min_camera_views) +
                           " needed (is the marker in the camera's view? is the path to it free?)");
  }
  Eigen::Vector3d lowest = Eigen::Vector3d::Constant(1e9);
  Eigen::Vector3d highest = -lowest;
  for (const auto& view : views) {
    const Eigen::Vector3d p = (view.flange_in_world * marker_in_flange).translation();
    lowest = lowest.cwiseMin(p);
    highest = highest.cwiseMax(p);
  }
  if ((highest - lowest).norm() < options.min_position_spread) {
    throw CalibrationError(
        format("Calibrate: the marker's positions span %.3f m, at least %.2f m needed to fix the "
               "camera's orientation",
               (highest - lowest).norm(), options.min_position_spread));
  }
  CameraCalibration result;
  result.camera_in_world = cameraByPnp(views, intrinsics, marker_in_flange, options.marker_size);
  // Views that do not fit the others left out, and the camera found again without them.
  const std::vector<MarkerView> used =
      inliers(views, viewErrors(views, intrinsics, marker_in_flange, result.camera_in_world, options.marker_size),
              options, options.min_camera_views);
  if (used.size() < views.size()) {
    result.camera_in_world = cameraByPnp(used, intrinsics, marker_in_flange, options.marker_size);
  }
  result.views = static_cast<int>(used.size());
  result.rejected = static_cast<int>(views.size() - used.size());
  result.residuals = residualsOf(used, intrinsics, marker_in_flange, result.camera_in_world, options.marker_size);
  if (result.residuals.reprojection_rms_px > options.max_reprojection_rms_px) {
    throw CalibrationError(
        format("Calibrate: the marker's corners are off by %.2f px (RMS) with the new camera pose, "
               "more than %.2f allowed (has the marker moved on the gripper? recalibrate the marker)",
               result.residuals.reprojection_rms_px, options.max_reprojection_rms_px));
  }
  return result;
}

}  // namespace costar::calibration
