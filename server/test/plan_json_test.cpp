// The editor's JSON form of plans and the checks on what the browser sends.

#include "server/plan_json.h"

#include <gtest/gtest.h>

#include "bt/builder.h"
#include "bt/plan_xml.h"
#include "core/paths.h"

namespace costar::server {
namespace {

TEST(CheckName, AcceptsIdentifiersRefusesPaths) {
  EXPECT_EQ(checkName("pick_up-node2"), "");
  EXPECT_EQ(checkName("A"), "");
  EXPECT_EQ(checkName(std::string(64, 'a')), "");
  EXPECT_NE(checkName(""), "");
  EXPECT_NE(checkName(std::string(65, 'a')), "");
  EXPECT_NE(checkName("../etc/passwd"), "");
  EXPECT_NE(checkName("a/b"), "");
  EXPECT_NE(checkName(".hidden"), "");
  EXPECT_NE(checkName("-rf"), "");
  EXPECT_NE(checkName("%2e%2e"), "");
  EXPECT_NE(checkName("a b"), "");
  EXPECT_NE(checkName(std::string("a\0b", 3)), "");
  EXPECT_NE(checkName("plan.xml"), "");
}

TEST(JsonNesting, CountsArraysAndObjectsOutsideStrings) {
  EXPECT_EQ(jsonNestingDepth("1"), 0u);
  EXPECT_EQ(jsonNestingDepth("[[{}]]"), 3u);
  EXPECT_EQ(jsonNestingDepth(R"({"a": "[[[[[[", "b": [1]})"), 2u);
  EXPECT_EQ(jsonNestingDepth(R"(["\"[[[", [2]])"), 2u);
  EXPECT_EQ(jsonNestingDepth(std::string(100000, '[')), 100000u);
}

TEST(ParseRequestJson, RefusesBadAndDeepJson) {
  EXPECT_EQ(parseRequestJson(R"({"a": 1})")["a"], 1);
  try {
    parseRequestJson("{bad json");
    FAIL() << "accepted bad JSON";
  } catch (const RequestError& error) {
    EXPECT_EQ(error.status(), 400);
  }
  try {
    parseRequestJson(std::string(1000, '[') + std::string(1000, ']'));
    FAIL() << "accepted JSON nested 1000 deep";
  } catch (const RequestError& error) {
    EXPECT_EQ(error.status(), 400);
    EXPECT_NE(std::string(error.what()).find("nested"), std::string::npos);
  }
}

TEST(PlanJson, RoundTripOfAnExamplePlanIsExact) {
  const bt::Plan plan = bt::loadPlan(dataRoot() / "examples/ur5/blind_pick_place.xml");
  const nlohmann::json json = planFileToJson(plan.file);
  EXPECT_EQ(json["main_tree"], "main");
  ASSERT_EQ(json["trees"].size(), 1u);
  EXPECT_EQ(json["trees"][0]["root"]["id"], "Sequence");
  EXPECT_EQ(json["trees"][0]["root"]["children"].size(), 11u);
  // Attribute order is kept.
  EXPECT_EQ(json["trees"][0]["root"]["children"][1]["attributes"][0][0], "name");
  EXPECT_EQ(json["trees"][0]["root"]["children"][1]["attributes"][1][0], "waypoint");

  const bt::PlanFile back = planFileFromJson(nlohmann::json::parse(json.dump()), "back.xml");
  EXPECT_TRUE(bt::sameContent(plan.file, back));
  EXPECT_EQ(bt::writePlanFile(back), bt::writePlanFile(plan.file));
}

TEST(PlanJson, SpecialCharactersSurviveTheTripThroughXml) {
  nlohmann::json json = {
      {"main_tree", "main"},
      {"trees",
       {{{"id", "main"},
         {"root",
          {{"id", "Sequence"},
           {"attributes", nlohmann::json::array({nlohmann::json::array({"name", "a & b < \"c\" 'd'\n\ttab \u00e9"})})},
           {"children", {{{"id", "AlwaysSuccess"}}}}}}}}}};
  const bt::PlanFile file = planFileFromJson(json, "special.xml");
  const bt::PlanFile again = bt::parsePlanFile(bt::writePlanFile(file), "again.xml");
  EXPECT_TRUE(bt::sameContent(file, again));
  EXPECT_EQ(planFileToJson(again)["trees"][0]["root"]["attributes"][0][1], "a & b < \"c\" 'd'\n\ttab \u00e9");
}

void expectRefused(const nlohmann::json& json, const std::string& words) {
  try {
    planFileFromJson(json, "bad.xml");
    FAIL() << "accepted " << json.dump();
  } catch (const RequestError& error) {
    EXPECT_EQ(error.status(), 400);
    EXPECT_NE(std::string(error.what()).find(words), std::string::npos) << error.what();
  }
}

TEST(PlanJson, RefusesMalformedPlans) {
  const auto tree = [](nlohmann::json root) {
    return nlohmann::json{{"main_tree", "main"}, {"trees", {{{"id", "main"}, {"root", std::move(root)}}}}};
  };
  expectRefused(nlohmann::json::array(), "must be an object");
  expectRefused({{"trees", nlohmann::json::array()}}, "non-empty");
  expectRefused({{"trees", {{{"id", "main"}, {"root", {{"id", "Sequence"}}}}}}, {"includes", {"x.xml"}}},
                "cannot include");
  expectRefused(tree({{"id", 5}}), "'id' must be a string");
  expectRefused(tree({{"id", "<script>"}}), "not a node type name");
  const auto pairs = [](std::vector<nlohmann::json> list) { return nlohmann::json(list); };
  const auto pair = [](nlohmann::json key, nlohmann::json value) { return nlohmann::json::array({key, value}); };
  expectRefused(tree({{"id", "Open"}, {"attributes", {{"speed", 1}}}}), "must be a list");
  expectRefused(tree({{"id", "Open"}, {"attributes", pairs({pair("speed", 1)})}}), "pair of strings");
  expectRefused(tree({{"id", "Open"}, {"attributes", pairs({pair("a", "1"), pair("a", "2")})}}), "given twice");
  expectRefused(tree({{"id", "Open"}, {"attributes", pairs({pair("bad name", "1")})}}), "not an attribute name");
  expectRefused(tree({{"id", "Open"}, {"attributes", pairs({pair("a", std::string("x\0y", 3))})}}), "NUL");
  expectRefused(tree({{"id", "Sequence"}, {"children", "no"}}), "must be a list");
  expectRefused({{"trees", {{{"id", "main"}}}}}, "root node");
}

TEST(PlanJson, LimitsTheNumberOfNodes) {
  nlohmann::json root = {{"id", "Sequence"}, {"children", nlohmann::json::array()}};
  for (int i = 0; i < 50; ++i) {
    root["children"].push_back({{"id", "AlwaysSuccess"}});
  }
  const nlohmann::json json = {{"trees", {{{"id", "main"}, {"root", root}}}}};
  EXPECT_NO_THROW(planFileFromJson(json, "ok.xml", 51));
  EXPECT_THROW(planFileFromJson(json, "big.xml", 50), RequestError);
}

TEST(PlanJson, DiagnosticsPointAtTheEditorsNode) {
  const nlohmann::json json = {
      {"main_tree", "main"},
      {"trees",
       {{{"id", "main"},
         {"root",
          {{"id", "Sequence"},
           {"children", {{{"id", "AlwaysSuccess"}}, {{"id", "Fallback"}, {"children", {{{"id", "Sequense"}}}}}}}}}}}}};
  const bt::PlanFile file = planFileFromJson(json, "plan.xml");
  const bt::Plan plan = bt::loadPlanText(bt::writePlanFile(file), "plan.xml", {.follow_includes = false});
  const bt::NodeRegistry registry = bt::builtinRegistry();
  const auto diagnostics = bt::validatePlan(plan, registry);
  ASSERT_FALSE(diagnostics.empty());
  const nlohmann::json out = diagnosticsToJson(diagnostics, plan.file);
  EXPECT_NE(out[0]["message"].get<std::string>().find("Sequense"), std::string::npos) << out.dump();
  ASSERT_TRUE(out[0].contains("node")) << out.dump();
  EXPECT_EQ(out[0]["node"]["tree"], "main");
  EXPECT_EQ(out[0]["node"]["path"], nlohmann::json({1, 0}));
}

}  // namespace
}  // namespace costar::server
