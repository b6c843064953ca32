// The robot description files (format costar-robot-description/1): the UR5's and the iiwa's
// load as their makers' numbers, and bad files are refused naming the file, the field and the
// problem.

#include "arm/robot_description.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <numbers>
#include <random>
#include <string>
#include <utility>

#include "arm/chain_kinematics.h"
#include "arm/test/published_arms.h"
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
  EXPECT_EQ(ur5.solver, "ur");
  ASSERT_EQ(ur5.jointCount(), 6);
  EXPECT_EQ(ur5.joint_names.front(), "shoulder_pan_joint");
  EXPECT_EQ(ur5.joint_names.back(), "wrist_3_joint");
  EXPECT_EQ(ur5.joint_labels.back(), "wrist 3");
  // The data sheet's limits (published::ur5Limits(), the maker's numbers kept for tests), to rounding
  // of the degrees the file is written in.
  const JointLimits limits = published::ur5Limits();
  for (int j = 0; j < 6; ++j) {
    EXPECT_NEAR(ur5.limits.min_position[j], limits.min_position[j], 1e-12) << j;
    EXPECT_NEAR(ur5.limits.max_position[j], limits.max_position[j], 1e-12) << j;
    EXPECT_NEAR(ur5.limits.max_velocity[j], limits.max_velocity[j], 1e-12) << j;
    EXPECT_NEAR(ur5.limits.max_acceleration[j], limits.max_acceleration[j], 1e-12) << j;
  }
  const JointVector home = {0.0, -2.3, 1.9, -std::numbers::pi / 2 + 0.4, -std::numbers::pi / 2, 0.0};
  for (int j = 0; j < 6; ++j) {
    EXPECT_NEAR(ur5.home[j], home[j], 1e-12) << j;
  }
  EXPECT_EQ(ur5.urdf_tool_link, "tool0");
  EXPECT_EQ(ur5.gripper_links, (std::vector<std::string>{"tool0", "wrist_3_link", "fingers"}));
  EXPECT_EQ(ur5.base_link, "base_link");
  EXPECT_EQ(ur5.first_moving_link, "shoulder_link");
  EXPECT_TRUE(std::filesystem::is_regular_file(ur5.mjcf)) << ur5.mjcf;
  EXPECT_TRUE(std::filesystem::is_regular_file(ur5.urdf)) << ur5.urdf;
}

// Its joints are UR's DH table, read back exactly, and the closed form is built on it.
TEST(RobotDescription, ItsKinematicsAreTheUrClosedFormWithItsDhTable) {
  const DhParameters published = published::ur5Dh();
  const DhParameters read = dhParametersOf(readChainGeometry(robotDescriptionFile("ur5")));
  for (int i = 0; i < 6; ++i) {
    EXPECT_EQ(read.d[i], published.d[i]) << i;
    EXPECT_EQ(read.a[i], published.a[i]) << i;
    EXPECT_NEAR(read.alpha[i], published.alpha[i], 1e-15) << i;
  }
  const RobotDescription ur5 = loadRobotDescription(robotDescriptionFile("ur5"));
  const std::shared_ptr<const Kinematics> kinematics = makeKinematics(ur5);
  ASSERT_NE(dynamic_cast<const Ur5Kinematics*>(kinematics.get()), nullptr);
  const Ur5Kinematics reference(published, published::ur5Limits());
  std::mt19937_64 random(3);
  std::uniform_real_distribution<double> angle(-3.0, 3.0);
  for (int trial = 0; trial < 50; ++trial) {
    JointVector q = JointVector::zero(6);
    for (double& value : q) {
      value = angle(random);
    }
    EXPECT_TRUE(kinematics->forward(q).isApprox(reference.forward(q), 1e-14)) << "trial " << trial;
  }
  EXPECT_EQ(kinematicsSolvers(), (std::vector<std::string>{"chain", "srs", "ur"}));
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

/// A variant of a robot's description, loaded as if the models had been generated from it: the
/// test's own generated folder ($COSTAR_GENERATED_DIR) holds the build's models and the
/// variant's fingerprint, so that each check of the file is reached.
class GeneratedVariant : public ::testing::Test {
 protected:
  explicit GeneratedVariant(std::string robot) : robot_(std::move(robot)) {}

  void SetUp() override {
    folder_ = std::filesystem::temp_directory_path() /
              ("costar_" + robot_ + "_test_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "_" +
               ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::create_directories(folder_);
    std::ifstream in(robotDescriptionFile(robot_));
    good_text_.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    good_ = json::parse(good_text_);
    const RobotDescription built = loadRobotDescription(robotDescriptionFile(robot_));
    generated_ = folder_ / "generated" / "robots" / robot_;
    std::filesystem::create_directories(generated_);
    std::filesystem::copy_file(built.mjcf, generated_ / (robot_ + ".xml"));
    std::filesystem::copy_file(built.urdf, generated_ / (robot_ + ".urdf"));
    ::setenv("COSTAR_GENERATED_DIR", (folder_ / "generated").c_str(), 1);
  }
  void TearDown() override {
    ::unsetenv("COSTAR_GENERATED_DIR");
    std::filesystem::remove_all(folder_);
  }

  /// The error loading `content` (as NAME.json, with models generated from it unless
  /// `regenerated` is false) and making its kinematics, without the "robot description 'PATH': "
  /// prefix.
  std::string problem(const json& content) { return problem(content.dump(2)); }
  std::string problem(const std::string& text, bool regenerated = true) {
    const auto file = folder_ / (robot_ + ".json");
    std::ofstream(file) << text;
    if (regenerated) {
      std::ofstream(generated_ / (robot_ + ".fingerprint")) << fingerprint(text) << "\n";
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

  std::string robot_;
  std::filesystem::path folder_;
  std::filesystem::path generated_;
  std::string good_text_;  // the file the build's models were generated from, byte for byte
  json good_;
};

class BadIiwaFile : public GeneratedVariant {
 protected:
  BadIiwaFile() : GeneratedVariant("iiwa14") {}
};

class BadUr5File : public GeneratedVariant {
 protected:
  BadUr5File() : GeneratedVariant("ur5") {}
};

TEST_F(BadUr5File, EachProblemNamesItsField) {
  EXPECT_EQ(problem(good_text_), "no error");
  json j = good_;
  j.erase("home_deg");
  EXPECT_EQ(problem(j), "home_deg: missing");
  j = good_;
  j["home_deg"].push_back(0.0);
  EXPECT_EQ(problem(j).rfind("home_deg: must be 6 angles (degrees), one per joint, not [", 0), 0u) << problem(j);
  j = good_;
  j["home_deg"][1] = 400.0;
  EXPECT_EQ(problem(j), "home_deg[1]: is outside joint 2's limits");
  j = good_;
  j["joints"][2]["velocity_deg_s"] = -1;
  EXPECT_EQ(problem(j), "joints[2].velocity_deg_s: must be positive, not -1");
  j = good_;
  j["joints"][3]["name"] = "elbow_joint";
  EXPECT_EQ(problem(j), "joints[3].name: 'elbow_joint' is taken already; joint names must differ");
  j = good_;
  j["joints"][0]["lower_deg"] = "low";
  EXPECT_EQ(problem(j), "joints[0].lower_deg: must be a finite number, not \"low\"");
  j = good_;
  j["gripper_link"] = "tool0";
  EXPECT_EQ(problem(j).rfind("gripper_link: unknown field (known: ", 0), 0u) << problem(j);
  j = good_;
  j.erase("format");  // the UR5's older format, before issue 35
  EXPECT_EQ(problem(j), "format: must be \"costar-robot-description/1\", not missing");
  j = good_;
  j["kinematics"]["solver"] = "kuka";
  EXPECT_EQ(problem(j), "kinematics.solver: unknown solver 'kuka' (known: chain, srs, ur)");
  j = good_;
  j["kinematics"]["d"] = {0.1, 0.2};  // the older format's DH table: the joints are the table now
  EXPECT_EQ(problem(j), "kinematics.d: solver 'ur' takes no parameters (its geometry comes from the joints)");
  j = good_;
  j["joints"] = json::array();
  EXPECT_EQ(problem(j), "joints: must be a list of 1 to 8 joints, not []");
  EXPECT_EQ(problem(std::string("{\"name\": ")).rfind("not valid JSON: ", 0), 0u);
  EXPECT_EQ(problem(std::string("[1, 2]")).rfind("(top level): must be an object", 0), 0u);
}

// The closed form needs the joints in DH form and of the UR structure; anything else is refused
// naming the joint, before an arm moves on wrong kinematics.
TEST_F(BadUr5File, AChainNotInTheUrsDhFormIsRefusedNamingTheJoint) {
  json j = good_;
  j["joints"][1]["rpy"] = {1.5707963267948966, 0.1, 0};
  EXPECT_EQ(problem(j), "joints[1].origin: must be [a, 0, d] turned about x only (rpy [alpha, 0, 0]) in DH form");
  j = good_;
  j["joints"][2]["origin"] = {-0.425, 0.01, 0};
  EXPECT_EQ(problem(j), "joints[2].origin: must be [a, 0, d] turned about x only (rpy [alpha, 0, 0]) in DH form");
  j = good_;
  j["joints"][3]["axis"] = {0, 1, 0};
  EXPECT_EQ(problem(j), "joints[3].axis: must be [0, 0, 1] in DH form");
  j = good_;
  j["joints"][0]["origin"] = {0, 0, 0.1};
  EXPECT_EQ(problem(j).rfind("joints[0].origin: must be [0, 0, 0]", 0), 0u) << problem(j);
  j = good_;
  j["tool"]["origin"] = {0, 0, 1e308};  // issue 27 (scripts/hostile_cli.sh): 1e308 reached the closed form
  EXPECT_EQ(problem(j), "tool.origin: a and d must be from -10 to 10 m (no arm is 10 m long)");
  j = good_;
  j["joints"][1].erase("rpy");  // DH form, but alpha1 = 0 is not a UR arm
  EXPECT_EQ(problem(j).rfind("Ur5Kinematics: the closed form needs alpha", 0), 0u) << problem(j);
}

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
