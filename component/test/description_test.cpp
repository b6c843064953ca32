#include "component/description.h"

#include <gtest/gtest.h>

#include "bt/builder.h"
#include "bt/plan_xml.h"
#include "component/registry.h"
#include "testing/test_components.h"

namespace costar::component {
namespace {

ComponentDescription richDescription() {
  ComponentDescription d;
  d.name = "arm";
  d.type = "UR5";
  d.implements = {"Arm"};
  d.inputs = {"joint_states"};
  d.outputs = {"joint_trajectory"};
  ParamSpec speed{"speed", ValueType::kDouble, "fraction", 0.25};
  speed.min = 0.01;
  speed.max = 1.0;
  ParamSpec frame{"frame", ValueType::kString, "axes", std::string("world"), {"world", "tool"}};
  frame.choices_from = "frame";
  ParamSpec pose{"pose", ValueType::kPose, "x;y;z", world::Pose(Eigen::Translation3d(0.1, -0.2, 0.3))};
  ParamSpec joint{"joint", ValueType::kInt, "joint number", {}};
  ParamSpec list{"names", ValueType::kStringList, "names", Value::List{"a", "b"}};
  ParamSpec flag{"fast", ValueType::kBool, "hurry", true};
  d.operations = {{"Move", "Moves.", {speed, frame, pose, joint, list, flag}},
                  {"Teach", "Saves.", {}, OperationKind::kKnowledge}};
  d.symbols = {{"endpoint", world::SymbolKind::kFrame, "tcp"}, {"arm_joints", world::SymbolKind::kJoints, "q"}};
  d.predicates = {{"at_waypoint", 1, "at w"}, {"arm_moving", 0, "moving"}};
  return d;
}

TEST(ComponentDescriptionJson, RoundTripsEveryField) {
  const ComponentDescription original = richDescription();
  const nlohmann::json json = toJson(original);
  const ComponentDescription back = descriptionFromJson(json);
  EXPECT_EQ(toJson(back), json);
  ASSERT_EQ(back.operations.size(), 2u);
  EXPECT_EQ(back.operations[1].kind, OperationKind::kKnowledge);
  const ParamSpec& speed = back.operations[0].params[0];
  EXPECT_EQ(speed.type, ValueType::kDouble);
  EXPECT_EQ(*speed.min, 0.01);
  EXPECT_EQ(*speed.max, 1.0);
  EXPECT_EQ(speed.default_value->asDouble(), 0.25);
  EXPECT_FALSE(back.operations[0].params[3].default_value.has_value());  // required stays required
  EXPECT_TRUE(
      back.operations[0].params[2].default_value->asPose().isApprox(world::Pose(Eigen::Translation3d(0.1, -0.2, 0.3))));
  EXPECT_EQ(back.operations[0].params[1].choices, (std::vector<std::string>{"world", "tool"}));
  EXPECT_EQ(back.operations[0].params[1].choices_from, "frame");
  EXPECT_EQ(back.symbols[1].kind, world::SymbolKind::kJoints);
  EXPECT_EQ(back.predicates[0].arity, 1u);
  // Checks of written values behave the same.
  EXPECT_EQ(back.operations[0].params[0].check("2"), original.operations[0].params[0].check("2"));
  EXPECT_FALSE(back.operations[0].params[0].check("2").empty());
}

TEST(ComponentDescriptionJson, NamesWhatIsWrong) {
  nlohmann::json json = toJson(richDescription());
  json["operations"][0]["params"][0]["type"] = "float";
  try {
    descriptionFromJson(json);
    FAIL() << "accepted an unknown type";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("component 'arm': unknown parameter type 'float'"), std::string::npos)
        << e.what();
  }
  json = toJson(richDescription());
  json["operations"][0]["params"][0].erase("name");
  EXPECT_THROW(descriptionFromJson(json), std::invalid_argument);
  json = toJson(richDescription());
  json["operations"][0]["params"][0]["default"] = "fast";
  EXPECT_THROW(descriptionFromJson(json), std::invalid_argument);
}

// `costar validate` without the robot refused nothing of a force at or above max_force: the
// check lived in code (OperationSpec::check), not in the stored description.
TEST(DescribedComponent, ANumberAboveTheOneItMustStayBelowIsRefusedFromTheStoredDescription) {
  ParamSpec force{"force", ValueType::kDouble, "pushes with (N)", 10.0};
  force.less_than = "max_force";
  const ParamSpec max_force{"max_force", ValueType::kDouble, "a force above this (N) stops the arm", 40.0};
  ComponentDescription description;
  description.name = "arm";
  description.type = "Arm";
  description.operations = {{"Press", "Presses.", {force, max_force}}};
  const nlohmann::json json = toJson(description);
  EXPECT_EQ(json["operations"][0]["params"][0]["less_than"], "max_force");
  ComponentRegistry registry;
  registry.add(std::make_shared<DescribedComponent>(descriptionFromJson(json)));
  bt::NodeRegistry nodes;
  registry.registerNodes(nodes);
  const auto diagnostics = [&nodes](const std::string& attributes) {
    const bt::Plan plan = bt::loadPlanText(
        R"(<root BTCPP_format="4"><BehaviorTree ID="main"><Press )" + attributes + "/></BehaviorTree></root>", "p.xml");
    std::string all;
    for (const auto& diagnostic : bt::validatePlan(plan, nodes)) {
      all += diagnostic.message + "\n";
    }
    return all;
  };
  EXPECT_EQ(diagnostics(R"(force="39.5")"), "");
  EXPECT_NE(diagnostics(R"(force="40")")
                .find("force (40) must be below max_force (40): a force above this (N) stops "
                      "the arm"),
            std::string::npos)
      << diagnostics(R"(force="40")");
  EXPECT_NE(diagnostics(R"(force="20" max_force="15")").find("must be below max_force (15)"), std::string::npos);
}

TEST(ComponentDescriptionJson, ALessThanNamingNoNumberOfTheOperationIsRefused) {
  ParamSpec force{"force", ValueType::kDouble, "N", 10.0};
  force.less_than = "max_force";
  ComponentDescription description;
  description.name = "arm";
  description.type = "Arm";
  description.operations = {{"Press", "Presses.", {force}}};
  try {
    descriptionFromJson(toJson(description));
    FAIL() << "accepted a less_than naming no parameter";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("parameter 'force': less_than: 'max_force' is not a number of the operation"),
              std::string::npos)
        << e.what();
  }
  nlohmann::json json = toJson(richDescription());
  json["operations"][0]["params"][1]["less_than"] = "speed";  // a string parameter
  EXPECT_THROW(descriptionFromJson(json), std::invalid_argument);
}

TEST(DescribedComponent, HasTheNodeTypesOfTheRealOneButRunsNothing) {
  testing::TestArm real;
  ComponentRegistry real_registry;
  real_registry.add(std::shared_ptr<Component>(&real, [](Component*) {}));
  auto described = std::make_shared<DescribedComponent>(descriptionFromJson(toJson(real.description())));
  ComponentRegistry described_registry;
  described_registry.add(described);  // its abstract requirements (Arm) hold as for the real one
  EXPECT_EQ(toJson(described->description()), toJson(real.description()));
  try {
    described->start("Move", {});
    FAIL() << "a described component started an operation";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("cannot run"), std::string::npos);
  }
  EXPECT_TRUE(described->report().symbols.empty());
}

}  // namespace
}  // namespace costar::component
