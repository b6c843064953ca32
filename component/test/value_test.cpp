#include "component/value.h"

#include <gtest/gtest.h>

#include "component/component.h"

namespace costar::component {
namespace {

TEST(Value, TextFormRoundTripsForEveryType) {
  const std::vector<std::pair<ValueType, std::string>> cases = {{ValueType::kBool, "true"},
                                                                {ValueType::kInt, "-42"},
                                                                {ValueType::kDouble, "0.125"},
                                                                {ValueType::kString, "grasp link"},
                                                                {ValueType::kPose, "0.1;0.2;0.3;10;-20;30"},
                                                                {ValueType::kStringList, "right_of;table_center"}};
  for (const auto& [type, text] : cases) {
    std::string error;
    const auto value = parseValue(type, text, &error);
    ASSERT_TRUE(value.has_value()) << text << ": " << error;
    EXPECT_EQ(value->type(), type);
    const auto again = parseValue(type, formatValue(*value));
    ASSERT_TRUE(again.has_value());
    EXPECT_EQ(*again, *value) << text;
  }
  EXPECT_TRUE(parseValue(ValueType::kStringList, "")->asList().empty());
}

TEST(Value, BadTextSaysWhatIsWrong) {
  std::string error;
  EXPECT_FALSE(parseValue(ValueType::kInt, "3.5", &error));
  EXPECT_EQ(error, "'3.5' is not an integer");
  EXPECT_FALSE(parseValue(ValueType::kDouble, "inf", &error));
  EXPECT_FALSE(parseValue(ValueType::kBool, "yes", &error));
  EXPECT_EQ(error, "'yes' is not true or false");
  EXPECT_FALSE(parseValue(ValueType::kPose, "1;2", &error));
  EXPECT_THROW(Value(3).asString(), std::invalid_argument);
  EXPECT_DOUBLE_EQ(Value(3).asDouble(), 3.0);
}

TEST(Value, JsonRoundTripsSoOperationsCanCrossAProcessBoundary) {
  const std::vector<OperationSpec> ops;
  std::vector<ParamSpec> specs = {{"speed", ValueType::kDouble, "", 0.5},
                                  {"target", ValueType::kPose, "", {}},
                                  {"predicates", ValueType::kStringList, "", Value::List{}},
                                  {"verbose", ValueType::kBool, "", false},
                                  {"count", ValueType::kInt, "", 3LL}};
  const ParamMap params = {{"speed", 0.25},
                           {"target", *parseValue(ValueType::kPose, "0.4;-0.1;0.2;0;90;0")},
                           {"predicates", Value::List{"right_of", "table_center"}},
                           {"verbose", true},
                           {"count", 7}};
  const nlohmann::json wire = nlohmann::json::parse(toJson(params).dump());
  const ParamMap back = paramsFromJson(specs, wire);
  EXPECT_EQ(back.size(), params.size());
  for (const auto& [name, value] : params) {
    EXPECT_EQ(back.at(name), value) << name;
  }
  // Missing parameters get their defaults; unknown ones and wrong types are refused.
  EXPECT_DOUBLE_EQ(paramsFromJson(specs, {{"target", toJson(params.at("target"))}}).at("speed").asDouble(), 0.5);
  EXPECT_THROW(paramsFromJson(specs, {{"target", toJson(params.at("target"))}, {"sped", 1}}), std::invalid_argument);
  EXPECT_THROW(paramsFromJson(specs, {{"target", "here"}}), std::invalid_argument);
  EXPECT_THROW(paramsFromJson(specs, nlohmann::json::object()), std::invalid_argument);  // target missing

  const OperationResult result = OperationResult::failure("no reachable candidate", {{"candidates", 48}});
  const OperationResult again = resultFromJson(nlohmann::json::parse(toJson(result).dump()));
  EXPECT_EQ(again.state, OperationState::kFailure);
  EXPECT_EQ(again.reason, result.reason);
  EXPECT_EQ(again.data, result.data);
}

TEST(ParamSpec, ChecksChoicesAndRanges) {
  ParamSpec mode{"mode", ValueType::kString, "", {}, {"Basic", "Pinch"}};
  EXPECT_EQ(mode.check("Pinch"), "");
  EXPECT_EQ(mode.check("Wide"), "'Wide' is not one of: Basic, Pinch");
  ParamSpec speed{"speed", ValueType::kDouble, "", 0.5};
  speed.min = 0.01;
  speed.max = 1.0;
  EXPECT_EQ(speed.check("0.5"), "");
  EXPECT_EQ(speed.check("2"), "2 is out of range [0.01, 1]");
  EXPECT_EQ(speed.check("fast"), "'fast' is not a number");
}

}  // namespace
}  // namespace costar::component
