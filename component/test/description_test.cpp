#include "component/description.h"

#include <gtest/gtest.h>

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
