// The robot description files: the UR5's loads as the values the code used to hard-code, and
// bad files are refused naming the file, the field and the problem.

#include "arm/robot_description.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <numbers>
#include <random>

#include "arm/ur5_kinematics.h"
#include "core/files.h"
#include "core/paths.h"

namespace costar::arm {
namespace {

using nlohmann::json;

TEST(RobotDescription, TheUr5FileHoldsTheUr5) {
  const RobotDescription ur5 = loadRobotDescription(robotDescriptionFile("ur5"));
  EXPECT_EQ(ur5.name, "ur5");
  EXPECT_EQ(ur5.type, "UR5");
  ASSERT_EQ(ur5.jointCount(), 6);
  EXPECT_EQ(ur5.joint_names.front(), "shoulder_pan_joint");
  EXPECT_EQ(ur5.joint_names.back(), "wrist_3_joint");
  EXPECT_EQ(ur5.joint_labels.back(), "wrist 3");
  // Bit for bit what JointLimits::ur5() and the old hard-coded home were.
  const JointLimits limits = JointLimits::ur5();
  EXPECT_EQ(ur5.limits.min_position, limits.min_position);
  EXPECT_EQ(ur5.limits.max_position, limits.max_position);
  EXPECT_EQ(ur5.limits.max_velocity, limits.max_velocity);
  EXPECT_EQ(ur5.limits.max_acceleration, limits.max_acceleration);
  const JointVector home = {0.0, -2.3, 1.9, -std::numbers::pi / 2 + 0.4, -std::numbers::pi / 2, 0.0};
  EXPECT_EQ(ur5.home, home);
  // No tool of its own: the gripper's tool centre point is the workcell's (workcells/*.json).
  EXPECT_TRUE(ur5.tool_in_flange.isApprox(world::Pose::Identity(), 0.0));
  EXPECT_EQ(ur5.urdf_tool_link, "tool0");
  EXPECT_EQ(ur5.gripper_links, (std::vector<std::string>{"tool0", "wrist_3_link", "fingers"}));
  EXPECT_EQ(ur5.base_link, "base_link");
  EXPECT_TRUE(std::filesystem::is_regular_file(ur5.mjcf));
  EXPECT_TRUE(std::filesystem::is_regular_file(ur5.urdf));
}

TEST(RobotDescription, ItsKinematicsAreTheUrClosedFormWithItsDhTable) {
  const RobotDescription ur5 = loadRobotDescription(robotDescriptionFile("ur5"));
  const std::shared_ptr<const Kinematics> kinematics = makeKinematics(ur5);
  ASSERT_NE(dynamic_cast<const Ur5Kinematics*>(kinematics.get()), nullptr);
  const Ur5Kinematics reference;
  std::mt19937_64 random(3);
  std::uniform_real_distribution<double> angle(-3.0, 3.0);
  for (int trial = 0; trial < 50; ++trial) {
    JointVector q = JointVector::zero(6);
    for (double& value : q) {
      value = angle(random);
    }
    EXPECT_TRUE(kinematics->forward(q).isApprox(reference.forward(q), 0.0)) << "trial " << trial;
  }
  EXPECT_EQ(kinematicsSolvers(), (std::vector<std::string>{"chain", "srs", "ur"}));
}

class BadRobotFile : public ::testing::Test {
 protected:
  void SetUp() override {
    folder_ = std::filesystem::temp_directory_path() /
              ("costar_robot_test_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "_" +
               ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::create_directories(folder_);
    std::ifstream in(robotDescriptionFile("ur5"));
    good_ = json::parse(in);
  }
  void TearDown() override { std::filesystem::remove_all(folder_); }

  /// The error loading `content`, without the "robot description 'PATH': " prefix.
  std::string problem(const std::string& content) {
    const auto file = folder_ / "robot.json";
    std::ofstream(file) << content;
    const std::string prefix = "robot description '" + file.string() + "': ";
    try {
      const RobotDescription robot = loadRobotDescription(file);
      makeKinematics(robot);
    } catch (const std::runtime_error& e) {
      const std::string message = e.what();
      return message.rfind(prefix, 0) == 0 ? message.substr(prefix.size()) : "(no file named) " + message;
    }
    return "no error";
  }
  std::string problem(const json& content) { return problem(content.dump(2)); }

  std::filesystem::path folder_;
  json good_;
};

TEST_F(BadRobotFile, EachProblemNamesItsField) {
  EXPECT_EQ(problem(good_), "no error");
  json j = good_;
  j.erase("home");
  EXPECT_EQ(problem(j), "home: missing");
  j = good_;
  j["home"].push_back(0.0);
  EXPECT_EQ(problem(j),
            "home: must be 6 angles (radians), one per joint, not "
            "[0.0,-2.3,1.9,-1.1707963267948966,-1.5707963267948966,0.0...");
  j = good_;
  j["home"][1] = 7.0;
  EXPECT_EQ(problem(j), "home[1]: is outside joint 2's limits");
  j = good_;
  j["joints"][2]["max_velocity"] = -1;
  EXPECT_EQ(problem(j), "joints[2].max_velocity: must be positive (rad/s), not -1");
  j = good_;
  j["joints"][3]["name"] = "elbow_joint";
  EXPECT_EQ(problem(j), "joints[3].name: 'elbow_joint' is taken already; joint names must differ");
  j = good_;
  j["joints"][0]["min"] = "low";
  EXPECT_EQ(problem(j), "joints[0].min: must be a finite number, not \"low\"");
  j = good_;
  j["gripper_link"] = "tool0";
  EXPECT_EQ(problem(j),
            "gripper_link: unknown field (known: home, joints, kinematics, label, links, models, name, notes, tool, "
            "type)");
  j = good_;
  j["models"]["mjcf"] = "sim/models/no_such_robot.xml";
  EXPECT_EQ(problem(j).rfind("models.mjcf: no such file '", 0), 0u) << problem(j);
  j = good_;
  j["kinematics"]["solver"] = "kuka";
  EXPECT_EQ(problem(j), "kinematics.solver: unknown solver 'kuka' (known: chain, srs, ur)");
  j = good_;
  j["kinematics"]["d"] = {0.1, 0.2};
  EXPECT_EQ(problem(j), "kinematics.d: must be 6 numbers, not 2");
  j = good_;
  j["kinematics"]["alpha"][0] = 0.0;  // not a UR arm: the closed form refuses it
  EXPECT_EQ(problem(j).rfind("Ur5Kinematics: the closed form needs alpha", 0), 0u) << problem(j);
  j = good_;
  j["joints"] = json::array();
  EXPECT_EQ(problem(j), "joints: must be a list of 1 to 8 joints, not []");
  // Issue 27 (found by scripts/hostile_cli.sh): 1e308 reached the closed form as a length.
  j = good_;
  j["kinematics"]["d"][0] = 1e308;
  EXPECT_EQ(problem(j), "kinematics.d[0]: must be from -10 to 10 (m or rad: no arm is 10 m long), not 1e+308");
  EXPECT_EQ(problem(std::string("{\"name\": ")).rfind("not valid JSON: ", 0), 0u);
  EXPECT_EQ(problem(std::string("[1, 2]")),
            "(top level): must be an object {\"name\": ..., \"joints\": [...], ...}, not [1,2]");
}

// The LBR iiwa 14: the runtime reads the file the model generator reads
// (format costar-robot-description/1), degrees turned into radians.
TEST(RobotDescription, TheIiwaFileIsTheGeneratorsFile) {
  const RobotDescription iiwa = loadRobotDescription(robotDescriptionFile("iiwa14"));
  EXPECT_EQ(iiwa.name, "iiwa14");
  EXPECT_EQ(iiwa.type, "LBRiiwa");
  EXPECT_EQ(iiwa.solver, "srs");
  ASSERT_EQ(iiwa.jointCount(), 7);
  EXPECT_EQ(iiwa.joint_names.front(), "iiwa_joint_1");
  EXPECT_EQ(iiwa.joint_labels.back(), "A7");
  constexpr double kDegree = std::numbers::pi / 180.0;
  EXPECT_DOUBLE_EQ(iiwa.limits.max_position[1], 120 * kDegree);
  EXPECT_DOUBLE_EQ(iiwa.limits.min_position[6], -175 * kDegree);
  EXPECT_DOUBLE_EQ(iiwa.limits.max_velocity[3], 75 * kDegree);
  EXPECT_DOUBLE_EQ(iiwa.limits.max_acceleration[0], 200 * kDegree);
  EXPECT_DOUBLE_EQ(iiwa.home[3], -108 * kDegree);
  EXPECT_EQ(iiwa.base_link, "iiwa_link_0");
  EXPECT_EQ(iiwa.first_moving_link, "iiwa_link_1");
  EXPECT_EQ(iiwa.urdf_tool_link, "tool0");
  EXPECT_TRUE(std::filesystem::is_regular_file(iiwa.mjcf)) << iiwa.mjcf;
  EXPECT_TRUE(std::filesystem::is_regular_file(iiwa.urdf)) << iiwa.urdf;
  EXPECT_EQ(makeKinematics(iiwa)->jointCount(), 7);
}

/// A variant of iiwa14.json, loaded as if the models had been generated from it: the test's
/// own generated folder ($COSTAR_GENERATED_DIR) holds the build's models and the variant's
/// fingerprint, so that each check of the file is reached.
class BadIiwaFile : public ::testing::Test {
 protected:
  void SetUp() override {
    folder_ = std::filesystem::temp_directory_path() /
              ("costar_iiwa_test_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "_" +
               ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::create_directories(folder_);
    std::ifstream in(robotDescriptionFile("iiwa14"));
    good_text_.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    good_ = json::parse(good_text_);
    const RobotDescription built = loadRobotDescription(robotDescriptionFile("iiwa14"));
    generated_ = folder_ / "generated" / "robots" / "iiwa14";
    std::filesystem::create_directories(generated_);
    std::filesystem::copy_file(built.mjcf, generated_ / "iiwa14.xml");
    std::filesystem::copy_file(built.urdf, generated_ / "iiwa14.urdf");
    ::setenv("COSTAR_GENERATED_DIR", (folder_ / "generated").c_str(), 1);
  }
  void TearDown() override {
    ::unsetenv("COSTAR_GENERATED_DIR");
    std::filesystem::remove_all(folder_);
  }

  /// The error loading `content` (as iiwa14.json, with models generated from it unless
  /// `regenerated` is false), without the "robot description 'PATH': " prefix.
  std::string problem(const json& content) { return problem(content.dump(2)); }
  std::string problem(const std::string& text, bool regenerated = true) {
    const auto file = folder_ / "iiwa14.json";
    std::ofstream(file) << text;
    if (regenerated) {
      std::ofstream(generated_ / "iiwa14.fingerprint") << fingerprint(text) << "\n";
    }
    const std::string prefix = "robot description '" + file.string() + "': ";
    try {
      makeKinematics(loadRobotDescription(file));
    } catch (const std::runtime_error& e) {
      const std::string message = e.what();
      return message.rfind(prefix, 0) == 0 ? message.substr(prefix.size()) : "(no file named) " + message;
    }
    return "no error";
  }

  std::filesystem::path folder_;
  std::filesystem::path generated_;
  std::string good_text_;  // the file the build's models were generated from, byte for byte
  json good_;
};

TEST_F(BadIiwaFile, EachProblemNamesItsField) {
  EXPECT_EQ(problem(good_text_), "no error");
  json j = good_;
  j["format"] = "costar-robot-description/2";
  EXPECT_EQ(problem(j), "format: must be \"costar-robot-description/1\", not \"costar-robot-description/2\"");
  j = good_;
  j.erase("type");
  EXPECT_EQ(problem(j), "type: missing");
  j = good_;
  j["joints"][2].erase("acceleration_deg_s2");
  EXPECT_EQ(problem(j), "joints[2].acceleration_deg_s2: missing");
  j = good_;
  j["joints"][4]["acceleration_deg_s2"] = 0;
  EXPECT_EQ(problem(j), "joints[4].acceleration_deg_s2: must be positive, not 0");
  j = good_;
  j["joints"][0]["speed"] = 1;
  EXPECT_EQ(problem(j).rfind("joints[0].speed: unknown field (known: ", 0), 0u) << problem(j);
  j = good_;
  j["home_deg"][1] = 150;
  EXPECT_EQ(problem(j), "home_deg[1]: is outside joint 2's limits");
  j = good_;
  j["gripper_links"] = "tool0";
  EXPECT_EQ(problem(j), "gripper_links: must be a list of link names, not \"tool0\"");
  j = good_;
  j["kinematics"]["d"] = {0.1};
  EXPECT_EQ(problem(j), "kinematics.d: solver 'srs' takes no parameters (its geometry comes from the joints)");
  j = good_;
  j["name"] = "iiwa7";  // no model generated for it
  EXPECT_EQ(problem(j).rfind("name: the model generated from this file, '", 0), 0u) << problem(j);
}

// Issue 27: a description edited after the build was applied in part (the runtime read the
// file, the simulator the models generated from the old one). The models carry the fingerprint
// of the file they came from; any other content is refused, naming the file.
TEST_F(BadIiwaFile, AnEditAfterTheBuildIsRefusedUntilTheModelsAreGeneratedAgain) {
  json j = good_;
  j["joints"][1]["upper_deg"] = 100;  // valid, but not what the simulator's model has
  const std::string file = (folder_ / "iiwa14.json").string();
  ASSERT_EQ(problem(good_text_), "no error");
  EXPECT_EQ(problem(j.dump(2), /*regenerated=*/false),
            "(no file named) " + file + " changed after the build: rebuild (cmake --build build)");
  EXPECT_EQ(problem(j.dump(2)), "no error");  // the models generated again from it
  std::filesystem::remove(generated_ / "iiwa14.fingerprint");
  EXPECT_EQ(problem(good_text_, /*regenerated=*/false)
                .rfind("(no file named) " + file +
                           ": the models generated "
                           "from it carry no fingerprint",
                       0),
            0u);
}

TEST_F(BadIiwaFile, AKeyGivenTwiceIsRefused) {
  std::string twice = good_text_;
  twice.insert(twice.find('{') + 1, R"("label": "twice",)");
  EXPECT_EQ(problem(twice), "(top level): key 'label' appears twice (a key may appear once in an object)");
}

TEST(RobotDescription, AMissingFileIsNamed) {
  try {
    loadRobotDescription("/nonexistent/robot.json");
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "cannot read robot description '/nonexistent/robot.json': No such file or directory");
  }
}

}  // namespace
}  // namespace costar::arm
