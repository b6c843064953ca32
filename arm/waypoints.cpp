#include "arm/waypoints.h"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <nlohmann/json.hpp>
#include <numbers>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "core/files.h"
#include "core/json_file.h"

namespace costar::arm {

std::string checkWaypointName(const std::string& name) {
  if (name.empty() || name.size() > 64) {
    return "a waypoint name has 1 to 64 characters";
  }
  for (const char c : name) {
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_' && c != '-') {
      return "waypoint name '" + name + "' may contain only letters, digits, '_' and '-'";
    }
  }
  return {};
}

namespace {

nlohmann::json toJson(const Waypoint& waypoint) {
  nlohmann::json json = {{"name", waypoint.name}};
  if (waypoint.kind == Waypoint::Kind::kJoints) {
    json["joints"] = std::vector<double>(waypoint.joints.begin(), waypoint.joints.end());
  } else {
    const Eigen::Quaterniond q(waypoint.pose.linear());
    const Eigen::Vector3d& p = waypoint.pose.translation();
    json["frame"] = waypoint.frame;
    json["position"] = {p.x(), p.y(), p.z()};
    json["orientation"] = {q.w(), q.x(), q.y(), q.z()};
  }
  return json;
}

using nlohmann::json;

/// A problem with one field of the file: "waypoints[2].orientation: ...".
[[noreturn]] void fail(const std::string& field, const std::string& problem) {
  throw std::runtime_error(field + ": " + problem);
}

std::string shown(const json& value) {
  std::string text = value.dump();
  return text.size() <= 60 ? text : text.substr(0, 57) + "...";
}

std::vector<double> numbers(const json& value, const std::string& field, std::size_t size, const std::string& what) {
  if (!value.is_array() || value.size() != size) {
    fail(field, "must be " + what + ", not " + shown(value));
  }
  std::vector<double> out;
  for (std::size_t i = 0; i < size; ++i) {
    if (!value[i].is_number() || !std::isfinite(value[i].get<double>())) {
      fail(field + "[" + std::to_string(i) + "]", "must be a finite number, not " + shown(value[i]));
    }
    out.push_back(value[i].get<double>());
  }
  return out;
}

/// Sizes no cell has (1e308 was read as a joint angle or a position): refused at load.
constexpr double kMaxJointAngle = 4 * std::numbers::pi;
constexpr double kMaxDistance = 10.0;

/// "[I]: must be WHAT, not VALUE" for the first of `values` beyond `limit` in size; "" when none is.
std::string rangeProblem(const double* values, std::size_t count, double limit, const std::string& what) {
  for (std::size_t i = 0; i < count; ++i) {
    if (!(std::abs(values[i]) <= limit)) {
      char text[160];
      std::snprintf(text, sizeof text, "[%zu]: must be %s, not %g", i, what.c_str(), values[i]);
      return text;
    }
  }
  return {};
}

constexpr const char* kJointRange = "an angle from -4 pi to 4 pi rad (two turns either way)";
constexpr const char* kPositionRange = "from -10 to 10 m (no cell is larger)";

void inRange(const std::vector<double>& values, const std::string& field, double limit, const std::string& what) {
  if (const std::string problem = rangeProblem(values.data(), values.size(), limit, what); !problem.empty()) {
    const std::size_t colon = problem.find(':');
    fail(field + problem.substr(0, colon), problem.substr(colon + 2));
  }
}

std::string stringField(const json& value, const std::string& field) {
  if (!value.is_string()) {
    fail(field, "must be a string, not " + shown(value));
  }
  return value.get<std::string>();
}

Waypoint fromJson(const json& item, const std::string& field, int joint_count) {
  if (!item.is_object()) {
    fail(field, "must be an object {\"name\": ..., ...}, not " + shown(item));
  }
  for (const auto& [key, value] : item.items()) {
    if (key != "name" && key != "joints" && key != "frame" && key != "position" && key != "orientation") {
      fail(field + "." + key, "unknown field (known: name, joints, frame, position, orientation)");
    }
  }
  Waypoint waypoint;
  if (!item.contains("name")) {
    fail(field + ".name", "missing");
  }
  waypoint.name = stringField(item.at("name"), field + ".name");
  if (const std::string problem = checkWaypointName(waypoint.name); !problem.empty()) {
    fail(field + ".name", problem);
  }
  if (item.contains("joints")) {
    for (const char* key : {"frame", "position", "orientation"}) {
      if (item.contains(key)) {
        fail(field,
             "has both \"joints\" (a joint configuration) and \"" + std::string(key) + "\" (of a pose); give one");
      }
    }
    waypoint.kind = Waypoint::Kind::kJoints;
    const json& list = item.at("joints");
    const std::size_t count = joint_count > 0 ? static_cast<std::size_t>(joint_count)
                              : list.is_array() && !list.empty() && list.size() <= kMaxJoints ? list.size()
                                                                                              : 0;
    const std::string expected = joint_count > 0 ? std::to_string(joint_count) + " angles (radians)"
                                                 : "1 to " + std::to_string(kMaxJoints) + " angles (radians)";
    if (count == 0) {
      fail(field + ".joints", "must be " + expected + ", not " + shown(list));
    }
    const auto joints = numbers(list, field + ".joints", count, expected);
    inRange(joints, field + ".joints", kMaxJointAngle, kJointRange);
    waypoint.joints = JointVector(static_cast<int>(joints.size()));
    std::copy(joints.begin(), joints.end(), waypoint.joints.begin());
    return waypoint;
  }
  waypoint.kind = Waypoint::Kind::kPose;
  for (const char* key : {"position", "orientation"}) {
    if (!item.contains(key)) {
      fail(field + "." + key,
           "missing (a waypoint has \"joints\", or \"position\" [x, y, z] and \"orientation\" [w, x, y, z])");
    }
  }
  if (item.contains("frame")) {
    waypoint.frame = stringField(item.at("frame"), field + ".frame");
    if (waypoint.frame.empty()) {
      fail(field + ".frame", "must name a frame (\"world\", or a frame symbol such as \"table_center\")");
    }
  }
  const auto p = numbers(item.at("position"), field + ".position", 3, "[x, y, z] (m)");
  inRange(p, field + ".position", kMaxDistance, kPositionRange);
  const auto q = numbers(item.at("orientation"), field + ".orientation", 4, "a unit quaternion [w, x, y, z]");
  const Eigen::Quaterniond rotation(q[0], q[1], q[2], q[3]);
  // A zero quaternion is no rotation at all (normalizing it gives nan); one far from unit
  // length is a typing error more likely than a rotation.
  if (std::abs(rotation.norm() - 1.0) > 0.01) {
    std::ostringstream norm;
    norm << rotation.norm();
    fail(field + ".orientation", "must be a unit quaternion [w, x, y, z], not " + shown(item.at("orientation")) +
                                     " (length " + norm.str() + ")");
  }
  waypoint.pose = world::Pose::Identity();
  waypoint.pose.translation() = Eigen::Vector3d(p[0], p[1], p[2]);
  waypoint.pose.linear() = rotation.normalized().toRotationMatrix();
  return waypoint;
}

nlohmann::json trajectoryToJson(const RecordedTrajectory& trajectory) {
  nlohmann::json poses = nlohmann::json::array();
  for (const world::Pose& pose : trajectory.poses) {
    const Eigen::Quaterniond q(pose.linear());
    const Eigen::Vector3d& p = pose.translation();
    poses.push_back({p.x(), p.y(), p.z(), q.w(), q.x(), q.y(), q.z()});
  }
  return {{"name", trajectory.name}, {"frame", trajectory.frame}, {"times", trajectory.times}, {"poses", poses}};
}

RecordedTrajectory trajectoryFromJson(const json& item, const std::string& field) {
  if (!item.is_object()) {
    fail(field,
         "must be an object {\"name\": ..., \"frame\": ..., \"times\": [...], \"poses\": [...]}, not " + shown(item));
  }
  for (const auto& [key, value] : item.items()) {
    if (key != "name" && key != "frame" && key != "times" && key != "poses") {
      fail(field + "." + key, "unknown field (known: name, frame, times, poses)");
    }
  }
  for (const char* key : {"name", "frame", "times", "poses"}) {
    if (!item.contains(key)) {
      fail(field + "." + key, "missing");
    }
  }
  RecordedTrajectory trajectory;
  trajectory.name = stringField(item.at("name"), field + ".name");
  trajectory.frame = stringField(item.at("frame"), field + ".frame");
  const json& times = item.at("times");
  const json& poses = item.at("poses");
  if (!times.is_array() || !poses.is_array()) {
    fail(field, "times and poses must be lists");
  }
  trajectory.times = numbers(times, field + ".times", times.size(), "a list of seconds");
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const std::string at = field + ".poses[" + std::to_string(i) + "]";
    const auto v = numbers(poses[i], at, 7, "[x, y, z, qw, qx, qy, qz] (m, a unit quaternion)");
    const Eigen::Quaterniond q(v[3], v[4], v[5], v[6]);
    if (std::abs(q.norm() - 1.0) > 0.01) {
      fail(at, "its quaternion must have unit length");
    }
    world::Pose pose = world::Pose::Identity();
    pose.translation() = Eigen::Vector3d(v[0], v[1], v[2]);
    pose.linear() = q.normalized().toRotationMatrix();
    trajectory.poses.push_back(pose);
  }
  if (const std::string problem = checkRecordedTrajectory(trajectory); !problem.empty()) {
    fail(field + "." + problem.substr(0, problem.find(':')), problem.substr(problem.find(':') + 2));
  }
  return trajectory;
}

/// The waypoint file's advisory lock, FILE.lock beside it (flock: released when the process
/// dies, so a crashed writer never blocks the others). Held around every read-modify-write.
/// The loop of frames that `start` begins, as "a -> b -> a" (empty when its frames end in the
/// world or another component's frame): a waypoint relative to itself, or to one relative to it,
/// has no pose at all.
std::string frameLoop(const std::map<std::string, Waypoint>& waypoints, const std::string& start) {
  std::string path = start;
  std::string at = start;
  for (std::size_t step = 0; step <= waypoints.size(); ++step) {
    const auto it = waypoints.find(at);
    if (it == waypoints.end() || it->second.kind != Waypoint::Kind::kPose) {
      return {};
    }
    at = it->second.frame;
    path += " -> " + at;
    if (at == start) {
      return path;
    }
  }
  return {};  // a loop further on, not through `start`: found from its own waypoints
}

/// The waypoints whose poses are given relative to waypoint `name`, as "'a', 'b'".
std::string relativeTo(const std::map<std::string, Waypoint>& waypoints, const std::string& name) {
  std::string names;
  for (const auto& [other, waypoint] : waypoints) {
    if (waypoint.kind == Waypoint::Kind::kPose && waypoint.frame == name && other != name) {
      names += (names.empty() ? "'" : ", '") + other + "'";
    }
  }
  return names;
}

class FileLock {
 public:
  explicit FileLock(const std::filesystem::path& file) {
    std::filesystem::path lock_file = file;
    lock_file += ".lock";
    fd_ = ::open(lock_file.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd_ < 0) {
      throw std::runtime_error("cannot lock waypoint file '" + file.string() + "': cannot open '" + lock_file.string() +
                               "': " + std::strerror(errno));
    }
    // A writer holds it for one read and one write: a few milliseconds. 10 s is a writer stuck.
    for (int attempt = 0; ::flock(fd_, LOCK_EX | LOCK_NB) != 0; ++attempt) {
      if ((errno != EWOULDBLOCK && errno != EINTR) || attempt == 1000) {
        const std::string problem = errno == EWOULDBLOCK
                                        ? "another process has held its lock '" + lock_file.string() + "' for 10 s"
                                        : std::strerror(errno);
        ::close(fd_);
        throw std::runtime_error("cannot lock waypoint file '" + file.string() + "': " + problem);
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  }
  FileLock(const FileLock&) = delete;
  FileLock& operator=(const FileLock&) = delete;
  ~FileLock() { ::close(fd_); }  // releases the lock

 private:
  int fd_ = -1;
};

}  // namespace

WaypointStore::WaypointStore(std::filesystem::path file, bool persist, int joint_count)
    : file_(std::move(file)), persist_(persist), joint_count_(joint_count) {
  if (joint_count_ < 0 || joint_count_ > kMaxJoints) {
    throw std::invalid_argument("WaypointStore: joint_count must be 0 (any) to " + std::to_string(kMaxJoints) +
                                ", not " + std::to_string(joint_count_));
  }
  if (file_.empty()) {
    return;
  }
  stamp_ = stamp();
  waypoints_ = read();
}

WaypointStore::Stamp WaypointStore::stamp() const {
  struct stat info {};
  if (::stat(file_.c_str(), &info) != 0) {
    return {};
  }
  return {true, static_cast<unsigned long long>(info.st_dev), static_cast<unsigned long long>(info.st_ino),
          static_cast<unsigned long long>(info.st_size),
          static_cast<long long>(info.st_mtim.tv_sec) * 1000000000LL + info.st_mtim.tv_nsec};
}

WaypointStore::Map WaypointStore::read() const {
  const std::string label = "waypoint file '" + file_.string() + "'";
  std::error_code error;
  const bool exists = std::filesystem::exists(file_, error);
  if (error) {  // e.g. a loop of symbolic links, or a folder on the way that is a file
    throw std::runtime_error("cannot read " + label + ": " + error.message());
  }
  if (!exists) {
    return {};
  }
  const std::string text = readFile(file_, "waypoint file");
  Map waypoints;
  try {
    const json document = core::parseJson(text);
    if (!document.is_object() || !document.contains("waypoints") || !document.at("waypoints").is_array()) {
      fail("waypoints", "missing: the file is {\"waypoints\": [...]}");
    }
    for (const auto& [key, value] : document.items()) {
      if (key != "waypoints" && key != "trajectories") {
        fail(key, "unknown field (known: waypoints, trajectories)");
      }
    }
    if (document.contains("trajectories")) {
      const json& trajectories = document.at("trajectories");
      if (!trajectories.is_array()) {
        fail("trajectories", "must be a list [{\"name\": ..., \"frame\": ..., \"times\": [...], \"poses\": [...]}]");
      }
      for (std::size_t i = 0; i < trajectories.size(); ++i) {
        const std::string field = "trajectories[" + std::to_string(i) + "]";
        RecordedTrajectory trajectory = trajectoryFromJson(trajectories[i], field);
        if (waypoints.trajectories.contains(trajectory.name)) {
          fail(field + ".name", "'" + trajectory.name + "' is taken already; names must differ");
        }
        waypoints.trajectories[trajectory.name] = std::move(trajectory);
      }
    }
    const json& list = document.at("waypoints");
    std::map<std::string, std::size_t> index_of;
    for (std::size_t i = 0; i < list.size(); ++i) {
      const std::string field = "waypoints[" + std::to_string(i) + "]";
      Waypoint waypoint = fromJson(list[i], field, joint_count_);
      if (const auto [previous, added] = index_of.emplace(waypoint.name, i); !added) {
        fail(field + ".name", "'" + waypoint.name + "' is taken already (by waypoints[" +
                                  std::to_string(previous->second) + "]); names must differ");
      }
      waypoints.waypoints[waypoint.name] = std::move(waypoint);
    }
    for (std::size_t i = 0; i < list.size(); ++i) {
      const std::string name = list[i].at("name").get<std::string>();
      if (const std::string loop = frameLoop(waypoints.waypoints, name); !loop.empty()) {
        fail("waypoints[" + std::to_string(i) + "].frame", "a loop of frames (" + loop + "): no pose can be found");
      }
    }
  } catch (const std::exception& e) {
    throw std::runtime_error(label + ": " + e.what());
  }
  return waypoints;
}

void WaypointStore::refresh() const {
  if (!watched()) {
    return;
  }
  const Stamp now = stamp();
  if (now == stamp_) {
    return;
  }
  stamp_ = now;
  try {
    waypoints_ = read();
  } catch (const std::exception&) {
    // Being rewritten by hand, or broken: the last good contents stay in use; a change is
    // refused with the file's problem (update reads it again).
  }
}

template <typename Change>
auto WaypointStore::update(Change&& change) {
  std::lock_guard lock(mutex_);
  if (!watched()) {
    return change(waypoints_);
  }
  if (file_.has_parent_path()) {
    std::filesystem::create_directories(file_.parent_path());
  }
  const FileLock file_lock(file_);
  Map current = read();  // the file as it is now: another writer's changes are kept
  const auto result = change(current);
  save(current);
  waypoints_ = std::move(current);
  stamp_ = stamp();
  return result;
}

std::optional<Waypoint> WaypointStore::find(const std::string& name) const {
  std::lock_guard lock(mutex_);
  refresh();
  const auto it = waypoints_.waypoints.find(name);
  return it == waypoints_.waypoints.end() ? std::nullopt : std::optional<Waypoint>(it->second);
}

std::vector<Waypoint> WaypointStore::all() const {
  std::lock_guard lock(mutex_);
  refresh();
  std::vector<Waypoint> all;
  for (const auto& [name, waypoint] : waypoints_.waypoints) {
    all.push_back(waypoint);
  }
  return all;
}

std::optional<RecordedTrajectory> WaypointStore::findTrajectory(const std::string& name) const {
  std::lock_guard lock(mutex_);
  refresh();
  const auto it = waypoints_.trajectories.find(name);
  return it == waypoints_.trajectories.end() ? std::nullopt : std::optional<RecordedTrajectory>(it->second);
}

std::vector<RecordedTrajectory> WaypointStore::trajectories() const {
  std::lock_guard lock(mutex_);
  refresh();
  std::vector<RecordedTrajectory> all;
  for (const auto& [name, trajectory] : waypoints_.trajectories) {
    all.push_back(trajectory);
  }
  return all;
}

void WaypointStore::putTrajectory(const RecordedTrajectory& trajectory) {
  if (const std::string problem = checkRecordedTrajectory(trajectory); !problem.empty()) {
    throw std::invalid_argument("trajectory '" + trajectory.name + "': " + problem);
  }
  update([&trajectory](Map& contents) {
    contents.trajectories[trajectory.name] = trajectory;
    return true;
  });
}

bool WaypointStore::removeTrajectory(const std::string& name) {
  return update([&name](Map& contents) { return contents.trajectories.erase(name) > 0; });
}

void WaypointStore::put(const Waypoint& waypoint) {
  if (const std::string problem = checkWaypointName(waypoint.name); !problem.empty()) {
    throw std::invalid_argument(problem);
  }
  if (waypoint.kind == Waypoint::Kind::kJoints &&
      (waypoint.joints.empty() || (joint_count_ > 0 && waypoint.joints.size() != joint_count_))) {
    throw std::invalid_argument("waypoint '" + waypoint.name + "' has " + std::to_string(waypoint.joints.size()) +
                                " joint angles, the arm " +
                                (joint_count_ > 0 ? std::to_string(joint_count_) : std::string("at least one")));
  }
  // What the file could not be read back with (a put of 1e308 would break it for every reader).
  const std::string problem =
      waypoint.kind == Waypoint::Kind::kJoints
          ? rangeProblem(waypoint.joints.begin(), static_cast<std::size_t>(waypoint.joints.size()), kMaxJointAngle,
                         kJointRange)
          : rangeProblem(waypoint.pose.translation().data(), 3, kMaxDistance, kPositionRange);
  if (!problem.empty()) {
    throw std::invalid_argument("waypoint '" + waypoint.name +
                                "': " + (waypoint.kind == Waypoint::Kind::kJoints ? "joints" : "position") + problem);
  }
  update([&waypoint](Map& contents) {
    contents.waypoints[waypoint.name] = waypoint;
    if (const std::string loop = frameLoop(contents.waypoints, waypoint.name); !loop.empty()) {
      throw std::invalid_argument("waypoint '" + waypoint.name + "' would be relative to itself (" + loop +
                                  "); teach it relative to another frame");
    }
    return true;
  });
}

bool WaypointStore::remove(const std::string& name) {
  return update([&name](Map& contents) {
    if (const std::string users = relativeTo(contents.waypoints, name); !users.empty()) {
      throw std::invalid_argument("waypoint '" + name + "' is the frame of " + users +
                                  ": delete or teach those again first");
    }
    return contents.waypoints.erase(name) > 0;
  });
}

void WaypointStore::rename(const std::string& from, const std::string& to) {
  if (const std::string problem = checkWaypointName(to); !problem.empty()) {
    throw std::invalid_argument(problem);
  }
  update([&from, &to](Map& contents) {
    auto& waypoints = contents.waypoints;
    const auto it = waypoints.find(from);
    if (it == waypoints.end()) {
      throw std::invalid_argument("unknown waypoint '" + from + "'");
    }
    if (waypoints.contains(to)) {
      throw std::invalid_argument("a waypoint named '" + to + "' exists already");
    }
    Waypoint waypoint = it->second;
    waypoints.erase(it);
    waypoint.name = to;
    waypoints[to] = std::move(waypoint);
    // The waypoints taught relative to it follow it to its new name.
    for (auto& [name, other] : waypoints) {
      if (other.kind == Waypoint::Kind::kPose && other.frame == from) {
        other.frame = to;
      }
    }
    return true;
  });
}

void WaypointStore::save(const Map& waypoints) const {
  nlohmann::json json = {{"waypoints", nlohmann::json::array()}};
  for (const auto& [name, waypoint] : waypoints.waypoints) {
    json["waypoints"].push_back(toJson(waypoint));
  }
  if (!waypoints.trajectories.empty()) {
    json["trajectories"] = nlohmann::json::array();
    for (const auto& [name, trajectory] : waypoints.trajectories) {
      json["trajectories"].push_back(trajectoryToJson(trajectory));
    }
  }
  writeFileAtomically(file_, json.dump(2) + "\n");
}

}  // namespace costar::arm
