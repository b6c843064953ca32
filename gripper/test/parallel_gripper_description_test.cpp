// The parallel grippers' descriptions (robots/grippers/*.json, "kind": "parallel"): what the
// cell reads from them, and bad input refused naming the field.

#include "gripper/parallel_gripper_description.h"

#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <fstream>
#include <nlohmann/json.hpp>

namespace costar::gripper {
namespace {

TEST(ParallelGripperDescription, TheTwoFingerGripperAndTheFrankaHandAreReadFromTheirFiles) {
  const ParallelGripperDescription two = loadParallelGripperDescription(gripperDescriptionFile("parallel-2f"));
  EXPECT_EQ(two.name, "parallel-2f");
  EXPECT_DOUBLE_EQ(two.fingers.max_opening, 0.085);
  ASSERT_EQ(two.fingers.closed.size(), 2u);  // the link, then the pad
  EXPECT_EQ(two.fingers.closed[1].size, Eigen::Vector3d(0.026, 0.008, 0.04));
  EXPECT_EQ(two.tcp, Eigen::Vector3d(0, 0, 0.14));
  EXPECT_DOUBLE_EQ(two.max_force, 120.0);
  // The maker's figures: 0-80 mm stroke, 70 N continuous, the tool centre point 103.4 mm out.
  const ParallelGripperDescription hand = loadParallelGripperDescription(gripperDescriptionFile("franka-hand"));
  EXPECT_DOUBLE_EQ(hand.fingers.max_opening, 0.08);
  EXPECT_DOUBLE_EQ(hand.max_force, 70.0);
  EXPECT_DOUBLE_EQ(hand.tcp.z(), 0.1034);
  EXPECT_EQ(hand.grasps, two.grasps);  // TCP-relative grasps fit any parallel gripper
}

TEST(ParallelGripperDescription, EveryDescribedGripperHasAKindAndTheListComesFromTheFolder) {
  const std::vector<std::string> names = gripperDescriptionNames();
  for (const char* expected : {"franka-hand", "parallel-2f", "robotiq3f"}) {
    EXPECT_NE(std::find(names.begin(), names.end(), expected), names.end()) << expected;
  }
  EXPECT_EQ(gripperKind(gripperDescriptionFile("robotiq3f")), "adaptive-3f");
  EXPECT_EQ(gripperKind(gripperDescriptionFile("franka-hand")), "parallel");
}

TEST(ParallelGripperDescription, BadInputIsRefusedNamingTheField) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("costar_parallel_gripper_test_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  nlohmann::json good;
  std::ifstream(gripperDescriptionFile("parallel-2f")) >> good;
  const auto refused = [&dir](const nlohmann::json& description, const std::string& name = "parallel-2f") {
    const std::filesystem::path file = dir / (name + ".json");
    std::ofstream(file) << description.dump(2);
    try {
      loadParallelGripperDescription(file);
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_EQ(refused(good), "accepted");
  nlohmann::json bad = good;
  bad["kind"] = "adaptive-3f";
  EXPECT_NE(refused(bad).find("kind: is \"adaptive-3f\""), std::string::npos) << refused(bad);
  bad = good;
  bad["kind"] = "vacuum";
  EXPECT_NE(refused(bad).find("kind: must be"), std::string::npos) << refused(bad);
  EXPECT_NE(refused(good, "other").find("name: must be the file's name (other)"), std::string::npos);
  bad = good;
  bad["finger"]["pad"]["centre"][1] = 0.01;
  EXPECT_NE(refused(bad).find("finger.pad: the closed pad's inner face must be on y = 0"), std::string::npos)
      << refused(bad);
  bad = good;
  bad["grip_force_n"]["default"] = 200;
  EXPECT_NE(refused(bad).find("grip_force_n.default: must be at most grip_force_n.max"), std::string::npos);
  bad = good;
  bad["stroke_m"] = -0.1;
  EXPECT_NE(refused(bad).find("stroke_m: must be a length above 0"), std::string::npos) << refused(bad);
  bad = good;
  bad["finger"].erase("link");
  EXPECT_NE(refused(bad).find("finger.link: missing"), std::string::npos) << refused(bad);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace costar::gripper
