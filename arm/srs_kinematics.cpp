#include "arm/srs_kinematics.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <numbers>
#include <stdexcept>
#include <utility>

#include "core/files.h"
#include "core/json_file.h"

namespace costar::arm {

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kTwoPi = 2.0 * std::numbers::pi;
// Poses this far outside the reachable shell (m) are solved on its boundary.
constexpr double kReachTolerance = 1e-10;
// |sin| of joint 2 or 6 below which the aligned joints (1 and 3, 5 and 7) are treated as one.
constexpr double kAlignedThreshold = 1e-8;
// |q4| below which the two elbow branches are the same.
constexpr double kStraightThreshold = 1e-12;
// Step of the arm-angle sweep when `acceptable` rejects a solution.
constexpr double kSweepStep = 2.0 * kPi / 180.0;

double wrap(double angle) {
  if (angle > -kPi && angle <= kPi) {
    return angle;
  }
  double wrapped = std::remainder(angle, kTwoPi);
  return wrapped <= -kPi ? wrapped + kTwoPi : wrapped;
}

double clampUnit(double value) { return std::clamp(value, -1.0, 1.0); }

Eigen::Matrix3d rotZ(double angle) { return Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitZ()).toRotationMatrix(); }
Eigen::Matrix3d rotY(double angle) { return Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitY()).toRotationMatrix(); }

Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

/// A matrix that depends on the arm angle as A sin(psi) + B cos(psi) + C.
struct Sinusoid {
  Eigen::Matrix3d a, b, c;
  double at(int i, int j, double s, double co) const { return a(i, j) * s + b(i, j) * co + c(i, j); }
  Eigen::Matrix3d at(double s, double co) const { return a * s + b * co + c; }
};

/// Angles of R = Rz(first) Ry(middle) Rz(last) on the branch sign(middle) = `sign`. When the
/// middle angle is 0 or pi (the outer axes aligned) the first takes `preferred_first`; returns
/// true then (both branches are the same).
bool zyz(const Sinusoid& r, double s, double co, int sign, double preferred_first, double& first, double& middle,
         double& last) {
  const double c_mid = clampUnit(r.at(2, 2, s, co));
  middle = sign * std::acos(c_mid);
  if (std::sqrt(std::max(0.0, 1.0 - c_mid * c_mid)) < kAlignedThreshold) {
    first = preferred_first;
    const double m00 = r.at(0, 0, s, co);
    const double m10 = r.at(1, 0, s, co);
    // Middle 0: R = Rz(first + last); middle pi: R(0,0) = -cos(first - last), R(1,0) = sin(last - first).
    last = wrap(c_mid > 0 ? std::atan2(m10, m00) - first : first + std::atan2(m10, -m00));
    return true;
  }
  first = std::atan2(sign * r.at(1, 2, s, co), sign * r.at(0, 2, s, co));
  last = std::atan2(sign * r.at(2, 1, s, co), -sign * r.at(2, 0, s, co));
  return false;
}

/// A list of at most N values on the stack (inverseNearest() does not allocate): at most
/// 6 joints x 2 limits x 2 roots = 24 arm angles per elbow branch, and as many intervals.
template <typename T, std::size_t N>
class FixedList {
 public:
  void push_back(const T& value) { items_[size_++] = value; }
  template <typename... Args>
  void emplace_back(Args&&... args) {
    items_[size_++] = T{std::forward<Args>(args)...};
  }
  void clear() { size_ = 0; }
  std::size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }
  const T& operator[](std::size_t i) const { return items_[i]; }
  const T& front() const { return items_[0]; }
  T* begin() { return items_.data(); }
  T* end() { return items_.data() + size_; }
  const T* begin() const { return items_.data(); }
  const T* end() const { return items_.data() + size_; }

 private:
  std::array<T, N> items_{};
  std::size_t size_ = 0;
};
using Roots = FixedList<double, 32>;

/// Roots psi of a sin(psi) + b cos(psi) + c = 0, appended to `roots`.
void addRoots(double a, double b, double c, Roots& roots) {
  const double r = std::hypot(a, b);
  if (r < 1e-14) {
    return;
  }
  const double x = -c / r;
  if (std::abs(x) > 1.0) {
    return;
  }
  const double phi = std::atan2(a, b);
  const double delta = std::acos(x);
  roots.push_back(wrap(phi + delta));
  roots.push_back(wrap(phi - delta));
}

/// Where the hinge angle atan2(g n, g d) (n, d entries of `r`) crosses `limit` (or limit +/- pi).
void addHingeRoots(const Sinusoid& r, int ni, int nj, int di, int dj, double d_sign, double limit, Roots& roots) {
  const double sl = std::sin(limit);
  const double cl = std::cos(limit);
  addRoots(sl * d_sign * r.a(di, dj) - cl * r.a(ni, nj), sl * d_sign * r.b(di, dj) - cl * r.b(ni, nj),
           sl * d_sign * r.c(di, dj) - cl * r.c(ni, nj), roots);
}

/// `value` or a 2*pi-equivalent within [lower, upper], the one closest to `seed`; false if none.
bool intoLimits(double value, double seed, double lower, double upper, double& out) {
  bool found = false;
  double best_distance = 0.0;
  // Near the seed first: the equivalent closest to the seed, then the neighbours.
  const double base = value + kTwoPi * std::round((seed - value) / kTwoPi);
  for (int k = -2; k <= 2; ++k) {
    const double candidate = base + k * kTwoPi;
    if (candidate < lower || candidate > upper) {
      continue;
    }
    const double distance = std::abs(candidate - seed);
    if (!found || distance < best_distance) {
      found = true;
      best_distance = distance;
      out = candidate;
    }
  }
  return found;
}

/// Whether `value` or a 2*pi-equivalent lies within [lower, upper].
bool hasEquivalentWithin(double value, double lower, double upper) {
  if (value >= lower && value <= upper) {
    return true;
  }
  const double lowest_above = value + kTwoPi * std::ceil((lower - value) / kTwoPi);
  return lowest_above <= upper;
}

std::runtime_error descriptionError(const std::filesystem::path& file, const std::string& field,
                                    const std::string& problem) {
  return std::runtime_error(file.string() + ": " + field + ": " + problem);
}

}  // namespace

// ----------------------------------------------------------------------------------------------
// The description file

SrsArmDescription readSrsArmDescription(const std::filesystem::path& file) {
  const std::string text_of_file = readFile(file, "robot description");
  nlohmann::json root;
  try {
    root = core::parseJson(text_of_file);
  } catch (const core::JsonSyntaxError& error) {
    throw std::runtime_error(file.string() + ": not valid JSON: " + error.what());
  } catch (const std::runtime_error& error) {
    throw std::runtime_error(file.string() + ": " + error.what());
  }
  auto number = [&](const nlohmann::json& object, const char* key, const std::string& field) {
    if (!object.is_object() || !object.contains(key) || !object[key].is_number()) {
      throw descriptionError(file, field + "." + key, "missing or not a number");
    }
    return object[key].get<double>();
  };
  auto vec3 = [&](const nlohmann::json& object, const char* key, const std::string& field, bool optional) {
    if (!object.contains(key) && optional) {
      return Eigen::Vector3d::Zero().eval();
    }
    const nlohmann::json& value = object.contains(key) ? object[key] : nlohmann::json();
    if (!value.is_array() || value.size() != 3 || !value[0].is_number() || !value[1].is_number() ||
        !value[2].is_number()) {
      throw descriptionError(file, field + "." + key, "must be 3 numbers");
    }
    return Eigen::Vector3d(value[0].get<double>(), value[1].get<double>(), value[2].get<double>());
  };
  auto text = [&](const nlohmann::json& object, const char* key, const std::string& field) {
    if (!object.is_object() || !object.contains(key) || !object[key].is_string()) {
      throw descriptionError(file, field.empty() ? key : field + "." + key, "missing or not a string");
    }
    return object[key].get<std::string>();
  };

  SrsArmDescription description;
  description.name = text(root, "name", "");
  description.base_link = text(root, "base_link", "");
  const nlohmann::json& joints = root.contains("joints") ? root["joints"] : nlohmann::json();
  if (!joints.is_array() || joints.size() != 7) {
    throw descriptionError(file, "joints", "an S-R-S arm needs exactly 7 joints");
  }
  // Canonical axes z, y, z, y, z, y, z; link frames along z without rotation.
  std::array<double, 7> offsets{};
  for (int i = 0; i < 7; ++i) {
    const std::string field = "joints[" + std::to_string(i) + "]";
    const nlohmann::json& joint = joints[i];
    description.joint_names[i] = text(joint, "name", field);
    const Eigen::Vector3d origin = vec3(joint, "origin", field, false);
    const Eigen::Vector3d rpy = vec3(joint, "rpy", field, true);
    if (origin.head<2>().norm() > 1e-12 || rpy.norm() > 1e-12) {
      throw descriptionError(file, field + ".origin",
                             "the analytic S-R-S solver needs every joint origin on the z axis of its parent "
                             "link, without rotation");
    }
    // A link of zero length puts a joint on the one before it; 10 m is beyond any arm.
    if (origin.z() == 0.0 || std::abs(origin.z()) > 10.0) {
      throw descriptionError(file, field + ".origin",
                             origin.z() == 0.0 ? "[0, 0, 0] puts this joint on the one before it: a link of zero length"
                                               : "a link longer than 10 m");
    }
    offsets[i] = origin.z();
    const Eigen::Vector3d axis = vec3(joint, "axis", field, false);
    const Eigen::Vector3d canonical = i % 2 == 0 ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d::UnitY();
    if ((axis - canonical).norm() < 1e-12) {
      description.geometry.axis_sign[i] = 1;
    } else if ((axis + canonical).norm() < 1e-12) {
      description.geometry.axis_sign[i] = -1;
    } else {
      throw descriptionError(file, field + ".axis",
                             std::string("must be ") + (i % 2 == 0 ? "[0, 0, +/-1]" : "[0, +/-1, 0]") +
                                 " for an S-R-S arm (axes z y z y z y z)");
    }
    constexpr double kDegree = kPi / 180.0;
    description.limits.lower[i] = number(joint, "lower_deg", field) * kDegree;
    description.limits.upper[i] = number(joint, "upper_deg", field) * kDegree;
    if (!(description.limits.lower[i] < description.limits.upper[i])) {
      throw descriptionError(file, field, "lower_deg must be below upper_deg");
    }
    description.max_velocity[i] = number(joint, "velocity_deg_s", field) * kDegree;
    description.max_effort[i] = number(joint, "effort_nm", field);
  }
  description.geometry.base_to_shoulder = offsets[0] + offsets[1];
  description.geometry.shoulder_to_elbow = offsets[2] + offsets[3];
  description.geometry.elbow_to_wrist = offsets[4] + offsets[5];

  const nlohmann::json& tool = root.contains("tool") ? root["tool"] : nlohmann::json();
  if (!tool.is_object()) {
    throw descriptionError(file, "tool", "missing or not an object");
  }
  description.tool_frame = text(tool, "name", "tool");
  const Eigen::Vector3d tool_origin = vec3(tool, "origin", "tool", false);
  const Eigen::Vector3d tool_rpy = vec3(tool, "rpy", "tool", true);
  description.geometry.wrist_to_flange = world::Pose(Eigen::Translation3d(0.0, 0.0, offsets[6])) *
                                         world::poseFromXyzRpy(tool_origin.x(), tool_origin.y(), tool_origin.z(),
                                                               tool_rpy.x(), tool_rpy.y(), tool_rpy.z());

  const nlohmann::json& home = root.contains("home_deg") ? root["home_deg"] : nlohmann::json();
  if (!home.is_array() || home.size() != 7) {
    throw descriptionError(file, "home_deg", "must be 7 numbers");
  }
  for (int i = 0; i < 7; ++i) {
    if (!home[i].is_number()) {
      throw descriptionError(file, "home_deg[" + std::to_string(i) + "]", "not a number");
    }
    description.home[i] = home[i].get<double>() * kPi / 180.0;
  }
  if (!description.limits.contains(description.home)) {
    throw descriptionError(file, "home_deg", "outside the joint limits");
  }
  try {
    SrsKinematics check(description.geometry);
  } catch (const std::invalid_argument& error) {
    throw descriptionError(file, "joints", error.what());
  }
  return description;
}

// ----------------------------------------------------------------------------------------------
// Kinematics

namespace {

/// Everything about one target pose that does not depend on the arm angle, in canonical angles.
struct PoseTerms {
  // Per elbow branch (q4 > 0, q4 < 0): q4, and the shoulder rotation R03(psi) and wrist rotation
  // R47(psi) as sinusoids of psi. One branch only when the elbow is straight.
  int elbow_branches = 0;
  std::array<double, 2> q4{};
  std::array<Sinusoid, 2> shoulder;
  std::array<Sinusoid, 2> wrist;
};

/// Shoulder rotation R03 in the reference plane (joint 3 = 0) for the wrist at `shoulder_to_wrist`
/// with elbow angle q4 (canonical).
Eigen::Matrix3d referenceShoulder(const Eigen::Vector3d& shoulder_to_wrist, double q4, double upper, double lower) {
  const double r = std::hypot(shoulder_to_wrist.x(), shoulder_to_wrist.y());
  const double q1 = r > 1e-12 ? std::atan2(shoulder_to_wrist.y(), shoulder_to_wrist.x()) : 0.0;
  const double beta = std::atan2(r, shoulder_to_wrist.z());
  const double phi = std::atan2(lower * std::sin(q4), upper + lower * std::cos(q4));
  return rotZ(q1) * rotY(beta - phi);
}

/// The terms of `flange`; false when it is not finite or out of reach.
bool poseTerms(const SrsGeometry& geometry, const world::Pose& flange_to_wrist, const world::Pose& flange,
               PoseTerms& terms) {
  if (!flange.matrix().allFinite()) {
    return false;
  }
  const world::Pose wrist_pose = flange * flange_to_wrist;
  const Eigen::Matrix3d r07 = wrist_pose.linear();
  const Eigen::Vector3d shoulder_to_wrist =
      wrist_pose.translation() - Eigen::Vector3d(0.0, 0.0, geometry.base_to_shoulder);
  const double upper = geometry.shoulder_to_elbow;
  const double lower = geometry.elbow_to_wrist;
  const double distance = shoulder_to_wrist.norm();
  if (distance > upper + lower + kReachTolerance || distance < std::abs(upper - lower) - kReachTolerance ||
      distance == 0.0) {
    return false;
  }
  const double elbow =
      std::acos(clampUnit((distance * distance - upper * upper - lower * lower) / (2.0 * upper * lower)));
  terms.elbow_branches = elbow < kStraightThreshold ? 1 : 2;
  const Eigen::Vector3d u = shoulder_to_wrist / distance;
  const Eigen::Matrix3d ux = skew(u);
  const Eigen::Matrix3d uut = u * u.transpose();
  for (int k = 0; k < terms.elbow_branches; ++k) {
    const double q4 = k == 0 ? elbow : -elbow;
    terms.q4[k] = q4;
    // R03(psi) = Rot(u, psi) R03_ref = ux R03_ref sin(psi) - ux^2 R03_ref cos(psi) + u u^T R03_ref.
    const Eigen::Matrix3d reference = referenceShoulder(shoulder_to_wrist, q4, upper, lower);
    Sinusoid& shoulder = terms.shoulder[k];
    shoulder.a = ux * reference;
    shoulder.b = -ux * ux * reference;
    shoulder.c = uut * reference;
    // R47(psi) = R34^T R03(psi)^T R07.
    const Eigen::Matrix3d r34t = rotY(q4).transpose();
    Sinusoid& wrist = terms.wrist[k];
    wrist.a = r34t * shoulder.a.transpose() * r07;
    wrist.b = r34t * shoulder.b.transpose() * r07;
    wrist.c = r34t * shoulder.c.transpose() * r07;
  }
  return true;
}

/// One solution in canonical angles on branch (elbow k, sign of q2, sign of q6). Sets the
/// flags when the shoulder or wrist pair is aligned (the opposite sign gives the same solution).
Joints7 solveBranch(const PoseTerms& terms, int k, double psi, int sign2, int sign6, const Joints7& preferred,
                    bool& shoulder_aligned, bool& wrist_aligned) {
  const double s = std::sin(psi);
  const double c = std::cos(psi);
  Joints7 q;
  shoulder_aligned = zyz(terms.shoulder[k], s, c, sign2, preferred[0], q[0], q[1], q[2]);
  q[3] = terms.q4[k];
  wrist_aligned = zyz(terms.wrist[k], s, c, sign6, preferred[4], q[4], q[5], q[6]);
  return q;
}

/// An interval [begin, end] of arm angles (end may exceed pi), and the branches on which every
/// joint is within limits there: bit 2 * (sign2 < 0) + (sign6 < 0).
struct ArmAngleInterval {
  double begin = 0.0;
  double end = 0.0;
  unsigned feasible_on = 0;
};
using Intervals = FixedList<ArmAngleInterval, 32>;

/// inverseNearest()'s search, in canonical angles.
class NearestSearch {
 public:
  NearestSearch(const PoseTerms& terms, const Joints7& seed, const Joints7& lower, const Joints7& upper,
                const std::function<bool(const Joints7&)>& accept)
      : terms_(terms), seed_(seed), lower_(lower), upper_(upper), accept_(accept) {}

  /// The seed's arm angle for this pose on elbow branch k: the one at which the shoulder and
  /// wrist rotations R03 and R47 are nearest the seed's (the largest sum of traces of
  /// R_seed^T R(psi), a sinusoid of psi). For a seed that solves the pose it is the seed's own
  /// arm angle; unlike comparing arm-angle values, it does not jump where the reference plane
  /// turns quickly (the wrist centre near joint 1's axis).
  double seedArmAngle(int k) const {
    const Eigen::Matrix3d r03 = rotZ(seed_[0]) * rotY(seed_[1]) * rotZ(seed_[2]);
    const Eigen::Matrix3d r47 = rotZ(seed_[4]) * rotY(seed_[5]) * rotZ(seed_[6]);
    const double alpha = r03.cwiseProduct(terms_.shoulder[k].a).sum() + r47.cwiseProduct(terms_.wrist[k].a).sum();
    const double beta = r03.cwiseProduct(terms_.shoulder[k].b).sum() + r47.cwiseProduct(terms_.wrist[k].b).sum();
    return std::atan2(alpha, beta);
  }

  /// The solution on a branch at `psi`, mapped into the limits near the seed; false when a joint
  /// cannot be, or the caller does not accept it.
  bool solve(int k, int sign2, int sign6, double psi, Joints7& out) const {
    bool shoulder_aligned = false;
    bool wrist_aligned = false;
    const Joints7 q = solveBranch(terms_, k, psi, sign2, sign6, seed_, shoulder_aligned, wrist_aligned);
    for (int i = 0; i < 7; ++i) {
      if (!intoLimits(q[i], seed_[i], lower_[i], upper_[i], out[i])) {
        return false;
      }
    }
    return accept_(out);
  }

  /// The arm angles of elbow branch k at which joints 1-3 and 5-7 are within limits, found from
  /// the angles at which each meets a limit (each joint angle is a sinusoid, or the arctangent
  /// of a ratio of sinusoids, of psi).
  void feasibleIntervals(int k, Intervals& intervals) const {
    const Sinusoid& sh = terms_.shoulder[k];
    const Sinusoid& wr = terms_.wrist[k];
    Roots roots;
    for (double limit : {lower_[0], upper_[0]}) addHingeRoots(sh, 1, 2, 0, 2, 1.0, limit, roots);
    for (double limit : {lower_[2], upper_[2]}) addHingeRoots(sh, 2, 1, 2, 0, -1.0, limit, roots);
    for (double limit : {lower_[4], upper_[4]}) addHingeRoots(wr, 1, 2, 0, 2, 1.0, limit, roots);
    for (double limit : {lower_[6], upper_[6]}) addHingeRoots(wr, 2, 1, 2, 0, -1.0, limit, roots);
    for (double limit : {lower_[1], upper_[1]}) addRoots(sh.a(2, 2), sh.b(2, 2), sh.c(2, 2) - std::cos(limit), roots);
    for (double limit : {lower_[5], upper_[5]}) addRoots(wr.a(2, 2), wr.b(2, 2), wr.c(2, 2) - std::cos(limit), roots);
    std::sort(roots.begin(), roots.end());
    if (roots.empty()) {
      roots.push_back(-kPi);  // the whole circle, one interval
    }
    // Feasibility is constant between consecutive roots: test each interval's middle, the
    // shoulder (joints 1-3, by the sign of joint 2) apart from the wrist (joints 5-7, by the
    // sign of joint 6).
    intervals.clear();
    for (std::size_t i = 0; i < roots.size(); ++i) {
      const double begin = roots[i];
      const double end = i + 1 < roots.size() ? roots[i + 1] : roots.front() + kTwoPi;
      if (end - begin < 1e-12) {
        continue;
      }
      const double middle = 0.5 * (begin + end);
      const double s = std::sin(middle);
      const double c = std::cos(middle);
      unsigned shoulder_ok = 0;
      unsigned wrist_ok = 0;
      for (unsigned b = 0; b < 2; ++b) {
        const int sign = b == 0 ? 1 : -1;
        double first = 0.0, middle_angle = 0.0, last = 0.0;
        zyz(sh, s, c, sign, seed_[0], first, middle_angle, last);
        if (within(first, 0) && within(middle_angle, 1) && within(last, 2)) shoulder_ok |= 1u << b;
        zyz(wr, s, c, sign, seed_[4], first, middle_angle, last);
        if (within(first, 4) && within(middle_angle, 5) && within(last, 6)) wrist_ok |= 1u << b;
      }
      unsigned feasible_on = 0;
      for (unsigned b2 = 0; b2 < 2; ++b2) {
        for (unsigned b6 = 0; b6 < 2; ++b6) {
          if ((shoulder_ok >> b2 & 1u) && (wrist_ok >> b6 & 1u)) feasible_on |= 1u << (2 * b2 + b6);
        }
      }
      if (feasible_on != 0) {
        intervals.push_back(ArmAngleInterval{begin, end, feasible_on});
      }
    }
  }

  /// On one branch: the feasible arm angle nearest `psi_seed`, then (if the caller rejects that
  /// solution) feasible arm angles in widening steps around it.
  bool nearestOnBranch(int k, int sign2, int sign6, double psi_seed, const Intervals& intervals, Joints7& out) const {
    const unsigned bit = 1u << (2 * (sign2 < 0) + (sign6 < 0));
    double psi_best = 0.0;
    double middle_best = 0.0;
    double gap_best = kTwoPi + 1.0;
    for (const ArmAngleInterval& interval : intervals) {
      if (!(interval.feasible_on & bit)) {
        continue;
      }
      const double width = interval.end - interval.begin;
      const double margin = std::min(1e-6, 0.5 * width);
      double offset = wrap(psi_seed - interval.begin);  // where the seed's angle lies from the start
      if (offset < 0.0) offset += kTwoPi;
      double psi = 0.0;
      double gap = 0.0;
      if (offset <= width) {
        psi = interval.begin + std::clamp(offset, margin, width - margin);
      } else {
        const double to_end = offset - width;
        const double to_begin = kTwoPi - offset;
        psi = to_end < to_begin ? interval.end - margin : interval.begin + margin;
        gap = std::min(to_end, to_begin);
      }
      if (gap < gap_best) {
        gap_best = gap;
        psi_best = psi;
        middle_best = 0.5 * (interval.begin + interval.end);
      }
    }
    if (gap_best > kTwoPi) {
      return false;  // no feasible arm angle on this branch
    }
    // The nearest arm angle, or (should rounding put it a hair outside) its interval's middle.
    if (solve(k, sign2, sign6, psi_best, out) || solve(k, sign2, sign6, middle_best, out)) {
      return true;
    }
    for (int step = 1; step * kSweepStep <= kPi; ++step) {
      for (int direction : {1, -1}) {
        const double psi = wrap(psi_best + direction * step * kSweepStep);
        const bool inside = std::any_of(intervals.begin(), intervals.end(), [&](const ArmAngleInterval& interval) {
          double offset = wrap(psi - interval.begin);
          if (offset < 0.0) offset += kTwoPi;
          return (interval.feasible_on & bit) && offset <= interval.end - interval.begin;
        });
        if (inside && solve(k, sign2, sign6, psi, out)) {
          return true;
        }
      }
    }
    return false;
  }

 private:
  bool within(double value, int joint) const { return hasEquivalentWithin(value, lower_[joint], upper_[joint]); }

  const PoseTerms& terms_;
  const Joints7& seed_;
  const Joints7& lower_;
  const Joints7& upper_;
  const std::function<bool(const Joints7&)>& accept_;
};

}  // namespace

SrsKinematics::SrsKinematics(SrsGeometry geometry) : geometry_(geometry) {
  for (double length : {geometry_.base_to_shoulder, geometry_.shoulder_to_elbow, geometry_.elbow_to_wrist}) {
    if (!std::isfinite(length) || length < 0.0) {
      throw std::invalid_argument("SrsKinematics: base_to_shoulder must be finite and not negative");
    }
  }
  if (!(geometry_.shoulder_to_elbow > 0.0) || !(geometry_.elbow_to_wrist > 0.0)) {
    throw std::invalid_argument("SrsKinematics: shoulder_to_elbow and elbow_to_wrist must be positive");
  }
  for (int sign : geometry_.axis_sign) {
    if (sign != 1 && sign != -1) {
      throw std::invalid_argument("SrsKinematics: every axis sign must be +1 or -1");
    }
  }
  const Eigen::Matrix3d r = geometry_.wrist_to_flange.linear();
  if (!geometry_.wrist_to_flange.matrix().allFinite() ||
      !(r.transpose() * r).isApprox(Eigen::Matrix3d::Identity(), 1e-9) || r.determinant() < 0.0) {
    throw std::invalid_argument("SrsKinematics: wrist_to_flange must be a finite rigid transform");
  }
  flange_to_wrist_ = geometry_.wrist_to_flange.inverse();
}

Joints7 SrsKinematics::toReal(const Joints7& canonical) const {
  Joints7 real;
  for (int i = 0; i < 7; ++i) {
    real[i] = geometry_.axis_sign[i] * canonical[i];
  }
  return real;
}

Joints7 SrsKinematics::toCanonical(const Joints7& real) const { return toReal(real); }

world::Pose SrsKinematics::forward(const Joints7& q_real) const {
  const Joints7 q = toCanonical(q_real);
  const Eigen::Matrix3d r02 = rotZ(q[0]) * rotY(q[1]);
  const Eigen::Matrix3d r04 = r02 * rotZ(q[2]) * rotY(q[3]);
  const Eigen::Vector3d wrist = Eigen::Vector3d(0, 0, geometry_.base_to_shoulder) +
                                r02.col(2) * geometry_.shoulder_to_elbow + r04.col(2) * geometry_.elbow_to_wrist;
  world::Pose pose = world::Pose::Identity();
  pose.linear() = r04 * rotZ(q[4]) * rotY(q[5]) * rotZ(q[6]);
  pose.translation() = wrist;
  return pose * geometry_.wrist_to_flange;
}

double SrsKinematics::armAngle(const Joints7& q_real) const {
  const Joints7 q = toCanonical(q_real);
  const Eigen::Matrix3d r02 = rotZ(q[0]) * rotY(q[1]);
  const Eigen::Matrix3d r03 = r02 * rotZ(q[2]);
  const Eigen::Vector3d shoulder_to_wrist =
      r02.col(2) * geometry_.shoulder_to_elbow + (r03 * rotY(q[3])).col(2) * geometry_.elbow_to_wrist;
  const Eigen::Vector3d u = shoulder_to_wrist.normalized();
  const Eigen::Matrix3d m =
      r03 *
      referenceShoulder(shoulder_to_wrist, q[3], geometry_.shoulder_to_elbow, geometry_.elbow_to_wrist).transpose();
  // m is a rotation about u by psi: m - m^T = 2 sin(psi) [u]x, trace(m) = 1 + 2 cos(psi).
  const Eigen::Vector3d vee(m(2, 1) - m(1, 2), m(0, 2) - m(2, 0), m(1, 0) - m(0, 1));
  return std::atan2(0.5 * u.dot(vee), 0.5 * (m.trace() - 1.0));
}

int SrsKinematics::inverse(const world::Pose& flange, double psi, std::array<Joints7, kMaxSolutions>& solutions,
                           const Joints7& preferred) const {
  PoseTerms terms;
  if (!std::isfinite(psi) || !poseTerms(geometry_, flange_to_wrist_, flange, terms)) {
    return 0;
  }
  const Joints7 preferred_canonical = toCanonical(preferred);
  int count = 0;
  for (int k = 0; k < terms.elbow_branches; ++k) {
    for (int sign2 : {1, -1}) {
      for (int sign6 : {1, -1}) {
        bool shoulder_aligned = false;
        bool wrist_aligned = false;
        const Joints7 q =
            solveBranch(terms, k, psi, sign2, sign6, preferred_canonical, shoulder_aligned, wrist_aligned);
        // A merged branch is returned once, from its positive side.
        if ((shoulder_aligned && sign2 < 0) || (wrist_aligned && sign6 < 0)) {
          continue;
        }
        Joints7 real = toReal(q);
        for (int i = 0; i < 7; ++i) {
          real[i] = wrap(real[i]);
        }
        solutions[count++] = real;
      }
    }
  }
  return count;
}

std::vector<Joints7> SrsKinematics::inverse(const world::Pose& flange, double psi) const {
  std::array<Joints7, kMaxSolutions> solutions;
  const int count = inverse(flange, psi, solutions);
  return {solutions.begin(), solutions.begin() + count};
}

std::optional<Joints7> SrsKinematics::inverseNearest(const world::Pose& flange, const Joints7& seed,
                                                     const SrsLimits& limits, const Acceptable& acceptable) const {
  if (!seed.allFinite()) {
    throw std::invalid_argument("SrsKinematics::inverseNearest: the seed has a non-finite joint angle");
  }
  PoseTerms terms;
  if (!poseTerms(geometry_, flange_to_wrist_, flange, terms)) {
    return std::nullopt;
  }
  // Work in canonical angles: seed, limits, and what the caller's predicate sees.
  const Joints7 seed_c = toCanonical(seed);
  Joints7 lower_c;
  Joints7 upper_c;
  for (int i = 0; i < 7; ++i) {
    const bool positive = geometry_.axis_sign[i] > 0;
    lower_c[i] = positive ? limits.lower[i] : -limits.upper[i];
    upper_c[i] = positive ? limits.upper[i] : -limits.lower[i];
  }
  const std::function<bool(const Joints7&)> accept = [&](const Joints7& canonical) {
    return !acceptable || acceptable(toReal(canonical));
  };
  const NearestSearch search(terms, seed_c, lower_c, upper_c, accept);

  // 1. The seed's branch at the seed's arm angle.
  const int seed_elbow = terms.elbow_branches == 2 && seed_c[3] < 0.0 ? 1 : 0;
  const int seed_sign2 = seed_c[1] < 0.0 ? -1 : 1;
  const int seed_sign6 = seed_c[5] < 0.0 ? -1 : 1;
  Joints7 candidate;
  if (search.solve(seed_elbow, seed_sign2, seed_sign6, search.seedArmAngle(seed_elbow), candidate)) {
    return toReal(candidate);
  }

  // 2. Every branch at its feasible arm angle nearest the seed's; the nearest solution wins.
  std::optional<Joints7> best;
  double best_distance = 0.0;
  Intervals intervals;
  for (int k = 0; k < terms.elbow_branches; ++k) {
    double q4_within = 0.0;
    if (!intoLimits(terms.q4[k], seed_c[3], lower_c[3], upper_c[3], q4_within)) {
      continue;  // joint 4 does not depend on the arm angle
    }
    search.feasibleIntervals(k, intervals);
    const double psi_seed = search.seedArmAngle(k);
    for (int sign2 : {1, -1}) {
      for (int sign6 : {1, -1}) {
        if (!search.nearestOnBranch(k, sign2, sign6, psi_seed, intervals, candidate)) {
          continue;
        }
        const double distance = (candidate - seed_c).squaredNorm();
        if (!best || distance < best_distance) {
          best = candidate;
          best_distance = distance;
        }
      }
    }
  }
  if (!best) {
    return std::nullopt;
  }
  return toReal(*best);
}

int SrsKinematics::solutionsWithin(const world::Pose& flange, const Joints7& seed, const SrsLimits& limits,
                                   std::array<Joints7, kMaxNearSolutions>& solutions) const {
  if (!seed.allFinite()) {
    throw std::invalid_argument("SrsKinematics::solutionsWithin: the seed has a non-finite joint angle");
  }
  PoseTerms terms;
  if (!poseTerms(geometry_, flange_to_wrist_, flange, terms)) {
    return 0;
  }
  const Joints7 seed_c = toCanonical(seed);
  Joints7 lower_c;
  Joints7 upper_c;
  for (int i = 0; i < 7; ++i) {
    const bool positive = geometry_.axis_sign[i] > 0;
    lower_c[i] = positive ? limits.lower[i] : -limits.upper[i];
    upper_c[i] = positive ? limits.upper[i] : -limits.lower[i];
  }
  const std::function<bool(const Joints7&)> accept_all = [](const Joints7&) { return true; };
  const NearestSearch search(terms, seed_c, lower_c, upper_c, accept_all);
  int count = 0;
  const auto add = [&](const Joints7& canonical) {
    for (int s = 0; s < count; ++s) {
      if ((solutions[s] - canonical).squaredNorm() < 1e-18) {
        return;
      }
    }
    if (count < kMaxNearSolutions) {
      solutions[count++] = canonical;
    }
  };
  Joints7 candidate;
  const int seed_elbow = terms.elbow_branches == 2 && seed_c[3] < 0.0 ? 1 : 0;
  const int seed_sign2 = seed_c[1] < 0.0 ? -1 : 1;
  const int seed_sign6 = seed_c[5] < 0.0 ? -1 : 1;
  const double seed_psi = search.seedArmAngle(seed_elbow);
  if (search.solve(seed_elbow, seed_sign2, seed_sign6, seed_psi, candidate)) {
    add(candidate);
  }
  Intervals intervals;
  for (int k = 0; k < terms.elbow_branches; ++k) {
    double q4_within = 0.0;
    if (!intoLimits(terms.q4[k], seed_c[3], lower_c[3], upper_c[3], q4_within)) {
      continue;
    }
    search.feasibleIntervals(k, intervals);
    const double psi_seed = search.seedArmAngle(k);
    for (int sign2 : {1, -1}) {
      for (int sign6 : {1, -1}) {
        if (search.nearestOnBranch(k, sign2, sign6, psi_seed, intervals, candidate)) {
          add(candidate);
        }
      }
    }
  }
  for (double degrees : {10.0, 20.0, 40.0, 80.0}) {
    for (int direction : {1, -1}) {
      if (count < kMaxNearSolutions && search.solve(seed_elbow, seed_sign2, seed_sign6,
                                                    wrap(seed_psi + direction * degrees * kPi / 180.0), candidate)) {
        add(candidate);
      }
    }
  }
  for (int s = 0; s < count; ++s) {
    solutions[s] = toReal(solutions[s]);
  }
  return count;
}

namespace {

SrsLimits srsLimits(const JointLimits& limits) {
  if (limits.size() != 7) {
    throw std::invalid_argument("SrsArmKinematics: an S-R-S arm has 7 joints, the limits " +
                                std::to_string(limits.size()));
  }
  SrsLimits out;
  for (int j = 0; j < 7; ++j) {
    out.lower[j] = limits.min_position[j];
    out.upper[j] = limits.max_position[j];
  }
  return out;
}

Joints7 toJoints7(const JointVector& q) {
  Joints7 out;
  for (int j = 0; j < 7; ++j) {
    out[j] = q[j];
  }
  return out;
}

}  // namespace

SrsArmKinematics::SrsArmKinematics(SrsGeometry geometry, JointLimits limits)
    : Kinematics(std::move(limits)), solver_(geometry), srs_limits_(srsLimits(this->limits())) {}

world::Pose SrsArmKinematics::forward(const JointVector& q) const {
  if (q.size() != 7) {
    throw std::invalid_argument("SrsArmKinematics::forward: " + std::to_string(q.size()) + " joints, the arm 7");
  }
  return solver_.forward(toJoints7(q));
}

void SrsArmKinematics::inverse(const world::Pose& flange, const JointVector& seed, IkSolutions& solutions) const {
  solutions.clear();
  if (seed.size() != 7 || !allFinite(seed) || !flange.matrix().allFinite()) {
    return;
  }
  std::array<Joints7, SrsKinematics::kMaxNearSolutions> found;
  const int count = solver_.solutionsWithin(flange, toJoints7(seed), srs_limits_, found);
  for (int s = 0; s < count; ++s) {
    solutions.push_back(JointVector::fromEigen(found[s]));
  }
}

std::optional<JointVector> SrsArmKinematics::inverseNearest(const world::Pose& flange, const JointVector& seed,
                                                            const Acceptable& acceptable) const {
  if (seed.size() != 7) {
    throw std::invalid_argument("SrsArmKinematics::inverseNearest: the seed has " + std::to_string(seed.size()) +
                                " joints, the arm 7");
  }
  if (!allFinite(seed)) {
    throw std::invalid_argument("SrsArmKinematics::inverseNearest: the seed has a non-finite joint angle");
  }
  SrsKinematics::Acceptable accept;
  if (acceptable) {
    accept = [&acceptable](const Joints7& q) { return acceptable(JointVector::fromEigen(q)); };
  }
  const std::optional<Joints7> q = solver_.inverseNearest(flange, toJoints7(seed), srs_limits_, accept);
  if (!q) {
    return std::nullopt;
  }
  return JointVector::fromEigen(*q);
}

}  // namespace costar::arm
