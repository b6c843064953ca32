// The waypoint file: what a person may write in it, and the errors for everything else (issue
// 10: duplicate names, zero quaternions and unreadable files were accepted or misreported).

#include "arm/waypoints.h"

#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>

namespace costar::arm {
namespace {

class WaypointFile : public ::testing::Test {
 protected:
  void SetUp() override {
    folder_ = std::filesystem::temp_directory_path() /
              ("costar_waypoint_file_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    std::filesystem::remove_all(folder_);
    std::filesystem::create_directories(folder_);
  }
  void TearDown() override { std::filesystem::remove_all(folder_); }

  std::filesystem::path write(const std::string& content) {
    const auto file = folder_ / "waypoints.json";
    std::ofstream(file) << content;
    return file;
  }

  /// The error loading `content` gives, without the "waypoint file 'PATH': " prefix.
  std::string problem(const std::string& content, int joint_count = 6) {
    const auto file = write(content);
    const std::string prefix = "waypoint file '" + file.string() + "': ";
    try {
      WaypointStore store(file, /*persist=*/true, joint_count);
    } catch (const std::runtime_error& e) {
      const std::string message = e.what();
      return message.rfind(prefix, 0) == 0 ? message.substr(prefix.size()) : "(no file named) " + message;
    }
    return "no error";
  }

  std::filesystem::path folder_;
};

TEST_F(WaypointFile, AValidFileLoads) {
  const WaypointStore store(write(R"({"waypoints": [
      {"name": "above", "frame": "table_center", "position": [0.1, 0.2, 0.3], "orientation": [0, 1, 0, 0]},
      {"name": "home", "joints": [0, -2.3, 1.9, -1.17, -1.57, 0]}]})"));
  ASSERT_EQ(store.all().size(), 2u);
  EXPECT_EQ(store.find("above")->frame, "table_center");
  EXPECT_TRUE(store.find("above")->pose.translation().isApprox(Eigen::Vector3d(0.1, 0.2, 0.3)));
  EXPECT_TRUE(store.find("above")->pose.linear().isApprox(Eigen::Vector3d(1, -1, -1).asDiagonal().toDenseMatrix()));
  EXPECT_EQ(store.find("home")->kind, Waypoint::Kind::kJoints);
  EXPECT_EQ(store.find("home")->joints[1], -2.3);
}

TEST_F(WaypointFile, DuplicateNamesAreAnError) {
  EXPECT_EQ(problem(R"({"waypoints": [{"name": "a", "joints": [0, 0, 0, 0, 0, 0]},
                                      {"name": "b", "joints": [0, 0, 0, 0, 0, 0]},
                                      {"name": "a", "joints": [1, 0, 0, 0, 0, 0]}]})"),
            "waypoints[2].name: 'a' is taken already (by waypoints[0]); names must differ");
}

TEST_F(WaypointFile, AZeroOrNonUnitQuaternionIsAnErrorNamingTheField) {
  // It used to be normalized to nan and fail much later, as "forearm_link would touch table".
  EXPECT_EQ(problem(R"({"waypoints": [{"name": "p", "position": [0.4, 0, 0.2], "orientation": [0, 0, 0, 0]}]})"),
            "waypoints[0].orientation: must be a unit quaternion [w, x, y, z], not [0,0,0,0] (length 0)");
  EXPECT_EQ(problem(R"({"waypoints": [{"name": "p", "position": [0.4, 0, 0.2], "orientation": [2, 0, 0, 0]}]})"),
            "waypoints[0].orientation: must be a unit quaternion [w, x, y, z], not [2,0,0,0] (length 2)");
  EXPECT_EQ(problem(R"({"waypoints": [{"name": "p", "position": [0.4, 0, 0.2], "orientation": [1, 0, 0]}]})"),
            "waypoints[0].orientation: must be a unit quaternion [w, x, y, z], not [1,0,0]");
}

// A hostile tester taught cyc_b relative to cyc_a, then cyc_a relative to cyc_b: both were saved and
// neither could be reached; deleting or renaming a waypoint another was taught relative to
// orphaned it.
TEST_F(WaypointFile, FramesNeverLoopAndAWaypointUsedAsAFrameIsNotLost) {
  EXPECT_EQ(problem(R"({"waypoints": [
      {"name": "a", "frame": "b", "position": [0, 0, 0.1], "orientation": [1, 0, 0, 0]},
      {"name": "b", "frame": "a", "position": [0, 0, 0.1], "orientation": [1, 0, 0, 0]}]})"),
            "waypoints[0].frame: a loop of frames (a -> b -> a): no pose can be found");
  EXPECT_EQ(problem(R"({"waypoints": [
      {"name": "self", "frame": "self", "position": [0, 0, 0.1], "orientation": [1, 0, 0, 0]}]})"),
            "waypoints[0].frame: a loop of frames (self -> self): no pose can be found");
  WaypointStore store(folder_ / "taught.json", /*persist=*/true, 6);
  Waypoint a;
  a.name = "a";
  a.frame = "table_center";
  store.put(a);
  Waypoint b = a;
  b.name = "b";
  b.frame = "a";
  store.put(b);
  a.frame = "b";
  try {
    store.put(a);
    ADD_FAILURE() << "a loop was saved";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(),
                 "waypoint 'a' would be relative to itself (a -> b -> a); teach it relative to another frame");
  }
  EXPECT_EQ(store.find("a")->frame, "table_center");  // the refused change left the file as it was
  try {
    store.remove("a");
    ADD_FAILURE() << "the frame of b was deleted";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "waypoint 'a' is the frame of 'b': delete or teach those again first");
  }
  store.rename("a", "base");
  EXPECT_EQ(store.find("b")->frame, "base");  // b follows its frame to the new name
  EXPECT_EQ(WaypointStore(folder_ / "taught.json", true, 6).find("b")->frame, "base");
  EXPECT_TRUE(store.remove("b"));
  EXPECT_TRUE(store.remove("base"));
}

TEST_F(WaypointFile, TheJointCountComesFromTheArmOrIsAnyUpToTheCapacity) {
  const std::string seven = R"({"waypoints": [{"name": "j", "joints": [0, 0, 0, 0, 0, 0, 0]}]})";
  EXPECT_EQ(problem(seven, 7), "no error");
  EXPECT_EQ(problem(seven, 0), "no error");  // a reader that knows no robot
  EXPECT_EQ(WaypointStore(write(seven), false).find("j")->joints.size(), 7);
  EXPECT_EQ(problem(R"({"waypoints": [{"name": "j", "joints": [0, 0, 0, 0, 0, 0, 0, 0, 0]}]})", 0),
            "waypoints[0].joints: must be 1 to 8 angles (radians), not [0,0,0,0,0,0,0,0,0]");
  EXPECT_EQ(problem(R"({"waypoints": [{"name": "j", "joints": []}]})", 0),
            "waypoints[0].joints: must be 1 to 8 angles (radians), not []");
  WaypointStore six({}, false, 6);
  Waypoint wrong;
  wrong.name = "w";
  wrong.kind = Waypoint::Kind::kJoints;
  wrong.joints = JointVector::zero(7);
  EXPECT_THROW(six.put(wrong), std::invalid_argument);
}

TEST_F(WaypointFile, TypeAndShapeErrorsNameTheField) {
  EXPECT_EQ(problem(R"({"waypoints": [{"name": "j", "joints": [0, 0, 0, 0, 0]}]})"),
            "waypoints[0].joints: must be 6 angles (radians), not [0,0,0,0,0]");
  EXPECT_EQ(problem(R"({"waypoints": [{"name": "j", "joints": [0, 0, 0, 0, 0, 0, 0]}]})"),
            "waypoints[0].joints: must be 6 angles (radians), not [0,0,0,0,0,0,0]");
  EXPECT_EQ(problem(R"({"waypoints": [{"name": "j", "joints": [0, 0, "1", 0, 0, 0]}]})"),
            "waypoints[0].joints[2]: must be a finite number, not \"1\"");
  EXPECT_EQ(problem(R"({"waypoints": [{"name": "p", "position": [0.4, 0], "orientation": [1, 0, 0, 0]}]})"),
            "waypoints[0].position: must be [x, y, z] (m), not [0.4,0]");
  EXPECT_EQ(problem(R"({"waypoints": [{"name": "p", "orientation": [1, 0, 0, 0]}]})"),
            "waypoints[0].position: missing (a waypoint has \"joints\", or \"position\" [x, y, z] and \"orientation\" "
            "[w, x, y, z])");
  EXPECT_EQ(problem(R"({"waypoints": [{"name": 5, "joints": [0, 0, 0, 0, 0, 0]}]})"),
            "waypoints[0].name: must be a string, not 5");
  EXPECT_EQ(problem(R"({"waypoints": [{"name": "x y", "joints": [0, 0, 0, 0, 0, 0]}]})"),
            "waypoints[0].name: waypoint name 'x y' may contain only letters, digits, '_' and '-'");
  EXPECT_EQ(problem(R"({"waypoints": [{"name": "j", "joints": [0, 0, 0, 0, 0, 0], "frame": "world"}]})"),
            "waypoints[0]: has both \"joints\" (a joint configuration) and \"frame\" (of a pose); give one");
  EXPECT_EQ(problem(R"({"waypoints": [{"name": "j", "joint": [0, 0, 0, 0, 0, 0]}]})"),
            "waypoints[0].joint: unknown field (known: name, joints, frame, position, orientation)");
  EXPECT_EQ(
      problem(R"({"waypoints": [{"name": "p", "frame": 3, "position": [0, 0, 0], "orientation": [1, 0, 0, 0]}]})"),
      "waypoints[0].frame: must be a string, not 3");
  EXPECT_EQ(problem(R"({"waypoints": [7]})"), "waypoints[0]: must be an object {\"name\": ..., ...}, not 7");
  EXPECT_EQ(problem(R"({"points": []})"), "waypoints: missing: the file is {\"waypoints\": [...]}");
  // JSON syntax errors keep nlohmann's line and column.
  EXPECT_NE(problem("{\"waypoints\": [\n  {\"name\": }]}").find("line 2"), std::string::npos);
}

TEST_F(WaypointFile, AnUnreadableFileIsReportedAsUnreadableNotAsBadJson) {
  const auto message = [](const std::filesystem::path& file) {
    try {
      WaypointStore store(file);
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(message(folder_), "cannot read waypoint file '" + folder_.string() + "': it is a folder");
  const auto loop = folder_ / "loop.json";
  std::filesystem::create_symlink(loop, loop);
  EXPECT_EQ(message(loop), "cannot read waypoint file '" + loop.string() + "': Too many levels of symbolic links");
  // A file that does not exist yet is an empty store (the first waypoint taught creates it).
  EXPECT_TRUE(WaypointStore(folder_ / "new.json").all().empty());
}

Waypoint joints(const std::string& name, double first) {
  Waypoint waypoint;
  waypoint.name = name;
  waypoint.kind = Waypoint::Kind::kJoints;
  waypoint.joints = JointVector::zero(6);
  waypoint.joints[0] = first;
  return waypoint;
}

std::set<std::string> names(const WaypointStore& store) {
  std::set<std::string> out;
  for (const Waypoint& waypoint : store.all()) {
    out.insert(waypoint.name);
  }
  return out;
}

// Issue 27 (found by scripts/hostile_cli.sh): a joint angle or a position of 1e308 was read.
TEST_F(WaypointFile, SizesNoCellHasAreRefused) {
  EXPECT_EQ(problem(R"({"waypoints": [{"name": "j", "joints": [0, 1e308, 0, 0, 0, 0]}]})"),
            "waypoints[0].joints[1]: must be an angle from -4 pi to 4 pi rad (two turns either way), not 1e+308");
  EXPECT_EQ(problem(R"({"waypoints": [{"name": "j", "joints": [0, 0, 0, 0, 0, -13]}]})"),
            "waypoints[0].joints[5]: must be an angle from -4 pi to 4 pi rad (two turns either way), not -13");
  EXPECT_EQ(problem(R"({"waypoints": [{"name": "j", "joints": [0, 0, 0, 0, 0, 12.5]}]})"), "no error");
  EXPECT_EQ(problem(R"({"waypoints": [{"name": "p", "position": [0.4, -1e308, 0], "orientation": [1, 0, 0, 0]}]})"),
            "waypoints[0].position[1]: must be from -10 to 10 m (no cell is larger), not -1e+308");
  // Nor are they written, which would break the file for every reader.
  WaypointStore store(folder_ / "written.json", /*persist=*/true, 6);
  try {
    store.put(joints("far", 1e308));
    ADD_FAILURE() << "put 1e308";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(),
                 "waypoint 'far': joints[0]: must be an angle from -4 pi to 4 pi rad (two turns either way), not "
                 "1e+308");
  }
  EXPECT_FALSE(store.find("far").has_value());
}

// Issue 27: the editor's server and `costar teach` each kept the whole file in memory and wrote
// it back whole, so each deleted what the other had taught, and a reader kept offering a
// waypoint no longer in the file. Two stores of one file stand for the two writers.
TEST_F(WaypointFile, TwoWritersOfOneFileKeepEachOthersChangesAndSeeThem) {
  const auto file = folder_ / "waypoints.json";
  WaypointStore editor(file, /*persist=*/true, 6);
  WaypointStore teach(file, /*persist=*/true, 6);
  editor.put(joints("from_editor", 0.1));
  teach.put(joints("from_teach", 0.2));  // used to write back its own copy: from_editor lost
  EXPECT_EQ(names(WaypointStore(file, false)), (std::set<std::string>{"from_editor", "from_teach"}));
  EXPECT_EQ(names(editor), (std::set<std::string>{"from_editor", "from_teach"}));  // sees the other's
  editor.rename("from_teach", "renamed");
  EXPECT_FALSE(teach.find("from_teach").has_value());  // no longer offered
  EXPECT_EQ(teach.find("renamed")->joints[0], 0.2);
  EXPECT_TRUE(teach.remove("from_editor"));
  EXPECT_FALSE(editor.remove("from_editor"));  // gone from the file: nothing to remove
  EXPECT_THROW(editor.rename("from_editor", "again"), std::invalid_argument);
  EXPECT_EQ(names(editor), (std::set<std::string>{"renamed"}));
  EXPECT_EQ(names(WaypointStore(file, false)), (std::set<std::string>{"renamed"}));
}

TEST_F(WaypointFile, AFileBrokenByHandKeepsTheLastGoodWaypointsAndIsNotOverwritten) {
  const auto file = folder_ / "waypoints.json";
  WaypointStore store(file, /*persist=*/true, 6);
  store.put(joints("kept", 0.3));
  std::ofstream(file) << "{\"waypoints\": [";  // a person's editor, half-way
  EXPECT_EQ(names(store), (std::set<std::string>{"kept"}));
  EXPECT_THROW(store.put(joints("new", 0.4)), std::runtime_error);
  std::ifstream in(file);
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(in), {}), "{\"waypoints\": [");
}

// Two processes teaching, renaming and deleting in one file at once: nothing of either is lost.
TEST_F(WaypointFile, TwoProcessesInterleavingChangesLoseNothing) {
  const auto file = folder_ / "waypoints.json";
  constexpr int kEach = 40;
  const auto work = [&file](const std::string& who) {
    WaypointStore store(file, /*persist=*/true, 6);
    for (int i = 0; i < kEach; ++i) {
      const std::string name = who + "_" + std::to_string(i);
      store.put(joints(name, 0.1 * i));
      if (i % 4 == 1) {
        store.rename(name, name + "_renamed");
      } else if (i % 4 == 2) {
        store.remove(name);
      }
    }
  };
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    try {
      work("child");
    } catch (...) {
      ::_exit(1);
    }
    ::_exit(0);
  }
  work("parent");
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
  std::set<std::string> expected;
  for (const std::string who : {"child", "parent"}) {
    for (int i = 0; i < kEach; ++i) {
      const std::string name = who + "_" + std::to_string(i);
      if (i % 4 == 1) {
        expected.insert(name + "_renamed");
      } else if (i % 4 != 2) {
        expected.insert(name);
      }
    }
  }
  EXPECT_EQ(names(WaypointStore(file, false)), expected);
}

}  // namespace
}  // namespace costar::arm
