// The PowerTool component on a test driver (a tool whose speed follows its command with a time
// constant, and whose presence switches the test sets), and its description files.

#include "tool/power_tool.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>

#include "component/registry.h"
#include "core/files.h"
#include "core/paths.h"

namespace costar::tool {
namespace {

using component::OperationResult;
using component::OperationState;
using testing::HasSubstr;

/// A tool whose speed approaches its command with a 0.2 s time constant.
class TestTool final : public PowerToolDriver {
 public:
  explicit TestTool(SimClock& clock) : clock_(clock) {
    clock_.addStepListener([this](TimePoint from, TimePoint to) {
      const double dt = toSeconds(to - from);
      reading_.speed += (target_ - reading_.speed) * (1.0 - std::exp(-dt / 0.2));
      reading_.stamp = to;
    });
  }
  PowerToolReading read() const override { return reading_; }
  void command(bool on, double speed) override {
    reading_.powered = on;
    target_ = on ? speed : 0.0;
    ++commands;
  }
  void setHeld(bool held) { reading_.held = held; }
  void setDocked(bool docked) { reading_.docked = docked; }
  int commands = 0;

 private:
  SimClock& clock_;
  PowerToolReading reading_;
  double target_ = 0.0;
};

class PowerToolTest : public ::testing::Test {
 protected:
  PowerToolTest()
      : driver(clock),
        tool(driver, clock, loadPowerToolDescription(powerToolFile("orbital_sander")),
             {.docked_pose = world::poseFromXyzRpy(0.4, -0.3, 0.08, 0, 0, 0), .object_name = "sander"}) {}

  OperationResult run(const std::string& operation, component::ParamMap params = {}) {
    for (const auto& spec : tool.description().operation(operation)->params) {
      params.try_emplace(spec.name, *spec.default_value);
    }
    const auto id = tool.start(operation, params);
    for (int tick = 0; tick < 1000; ++tick) {
      const OperationResult result = tool.poll(id);
      if (result.state != OperationState::kRunning) {
        return result;
      }
      clock.advanceBy(std::chrono::milliseconds(10));
    }
    return OperationResult::failure("still running after 10 s");
  }

  bool holds(const std::string& predicate) const {
    const world::Report report = tool.report();
    return std::any_of(report.predicates.begin(), report.predicates.end(),
                       [&](const world::Predicate& p) { return p.name == predicate; });
  }

  SimClock clock;
  TestTool driver;
  PowerTool tool;
};

TEST_F(PowerToolTest, ImplementsTheAbstractPowerTool) {
  component::ComponentRegistry registry;
  EXPECT_NO_THROW(registry.add(std::shared_ptr<component::Component>(&tool, [](component::Component*) {})));
  const auto* speed = tool.description().operation("ToolOn")->param("speed");
  ASSERT_NE(speed, nullptr);
  EXPECT_EQ(*speed->min, 4000.0);
  EXPECT_EQ(*speed->max, 12000.0);
  EXPECT_THAT(speed->check("20000"), HasSubstr("12000"));
}

TEST_F(PowerToolTest, ToolOnNeedsTheToolInTheGripper) {
  driver.setDocked(true);
  const OperationResult result = run("ToolOn");
  EXPECT_EQ(result.state, OperationState::kFailure);
  EXPECT_THAT(result.reason, HasSubstr("pick it up first"));
  EXPECT_FALSE(driver.read().powered);
  // On its stand it is an object SmartGrasp can pick up.
  const world::Report report = tool.report();
  EXPECT_TRUE(std::any_of(report.symbols.begin(), report.symbols.end(),
                          [](const world::Symbol& s) { return s.name == "sander" && s.frame() != nullptr; }));
  EXPECT_TRUE(holds("tool_docked"));
  EXPECT_TRUE(holds("tool_in_position"));
  EXPECT_TRUE(holds("is_a"));
}

TEST_F(PowerToolTest, ToolOnWaitsUntilItRunsAtSpeedAndToolOffUntilItStopped) {
  driver.setHeld(true);
  const OperationResult on = run("ToolOn", {{"speed", 8000.0}});
  ASSERT_EQ(on.state, OperationState::kSuccess) << on.reason;
  EXPECT_NEAR(on.data["speed"].get<double>(), 8000.0, 400.0);
  EXPECT_TRUE(holds("tool_on"));
  EXPECT_TRUE(holds("tool_at_speed"));
  EXPECT_FALSE(holds("is_a"));  // in the gripper: not an object on its stand
  const world::Report report = tool.report();
  const auto speed = std::find_if(report.symbols.begin(), report.symbols.end(),
                                  [](const world::Symbol& s) { return s.name == "tool_speed"; });
  ASSERT_NE(speed, report.symbols.end());
  EXPECT_NEAR(speed->number()->value, 8000.0, 400.0);
  EXPECT_EQ(speed->number()->unit, "opm");
  const OperationResult off = run("ToolOff");
  ASSERT_EQ(off.state, OperationState::kSuccess) << off.reason;
  EXPECT_FALSE(holds("tool_on"));
  EXPECT_LT(driver.read().speed, 400.0);
}

TEST_F(PowerToolTest, ARunningToolTakenOutOfTheGripperIsSwitchedOffAtTheNextReport) {
  driver.setHeld(true);
  ASSERT_EQ(run("ToolOn").state, OperationState::kSuccess);
  driver.setHeld(false);
  EXPECT_FALSE(holds("tool_on"));  // this report switched it off
  EXPECT_FALSE(driver.read().powered);
  EXPECT_FALSE(holds("tool_in_position"));
}

TEST_F(PowerToolTest, ToolOnFailsWhenTheToolLeavesTheGripperWhileItStarts) {
  driver.setHeld(true);
  const auto id = tool.start("ToolOn", {{"speed", 10000.0}});
  clock.advanceBy(std::chrono::milliseconds(50));
  driver.setHeld(false);
  const OperationResult result = tool.poll(id);
  EXPECT_EQ(result.state, OperationState::kFailure);
  EXPECT_THAT(result.reason, HasSubstr("left the gripper"));
  EXPECT_FALSE(driver.read().powered);
}

std::filesystem::path writeTool(const std::string& name, const std::string& text) {
  const auto file = std::filesystem::temp_directory_path() / ("costar_tool_" + name + ".json");
  std::ofstream(file) << text;
  return file;
}

TEST(PowerToolDescription, TheShippedSanderReadsAndItsShapeIsAnObjectClass) {
  const PowerToolDescription sander = loadPowerToolDescription(powerToolFile("orbital_sander"));
  EXPECT_EQ(sander.name, "orbital_sander");
  EXPECT_NEAR(sander.mass(), 1.2, 1e-9);
  EXPECT_NEAR(sander.handleCentre().z(), 0.012 + 0.06 + 0.035, 1e-12);
  const world::ObjectClass object = sander.objectClass();
  EXPECT_EQ(object.boxes.size(), 3u);
  EXPECT_EQ(object.symmetries.size(), 4u);  // quarter turns about its axis
  EXPECT_NEAR(object.bounds().max().z(), 0.142, 1e-12);
}

TEST(PowerToolDescription, BadFilesNameTheFileTheFieldAndTheProblem) {
  const std::string good = readFile(powerToolFile("orbital_sander"));
  const auto expectError = [&](const std::string& name, const std::string& from, const std::string& to,
                               const std::string& expected) {
    std::string text = good;
    const auto at = text.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    text.replace(at, from.size(), to);
    const auto file = writeTool(name, text);
    try {
      loadPowerToolDescription(file);
      ADD_FAILURE() << name << ": accepted";
    } catch (const std::runtime_error& e) {
      EXPECT_THAT(e.what(), HasSubstr(file.string())) << name;
      EXPECT_THAT(e.what(), HasSubstr(expected)) << name;
    }
  };
  expectError("zero_pad", R"("size": [0.1, 0.1, 0.012])", R"("size": [0.1, 0, 0.012])", "pad.size");
  expectError("speeds", R"("min": 4000)", R"("min": 14000)", "speed: needs min <= default <= max");
  expectError("unknown", R"("orbit_diameter")", R"("orbit_diametre": 0.003, "orbit_diameter")",
              "orbit_diametre: is not a field");
  expectError("twice", R"("mass": 0.85)", R"("mass": 0.85, "mass": 0.85)", "appears twice");
  expectError("heavy", R"("mass": 0.85)", R"("mass": 1e308)", "body.mass");
  expectError("format", "costar-power-tool/1", "costar-power-tool/2", "format");
}

}  // namespace
}  // namespace costar::tool
