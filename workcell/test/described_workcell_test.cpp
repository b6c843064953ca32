// A workcell made from a description has the node types of the real one. The simulated UR5
// cell's description is compared with the cell in cli_test.sh (costar vs costar-robot).

#include "workcell/described_workcell.h"

#include <gtest/gtest.h>

#include <fstream>

#include "bt/nodes_model.h"
#include "bt/plan_xml.h"

namespace costar::workcell {
namespace {

TEST(DescribedWorkcell, HasTheNodeTypesOfTheCellItDescribes) {
  auto real = makeLightWorkcell({.name = "test", .memory_only = true});
  const WorkcellDescription description = describeWorkcell(*real, {"node", "link"});
  const auto json = toJson(description);
  const auto described = makeDescribedWorkcell(workcellDescriptionFromJson(json), {.memory_only = true});
  EXPECT_EQ(described->name(), "test");
  EXPECT_EQ(bt::treeNodesModelXml(described->nodes(), {.include_btcpp_builtins = true}),
            bt::treeNodesModelXml(real->nodes(), {.include_btcpp_builtins = true}));
  EXPECT_EQ(toJson(describeWorkcell(*described, {"node", "link"}))["components"], json["components"]);
}

TEST(DescribedWorkcell, ChecksPredicateListsAgainstFramesClassesAndWaypoints) {
  WorkcellDescription description;
  description.name = "cell";
  component::ComponentDescription mover;
  mover.name = "mover";
  mover.type = "Mover";
  component::ParamSpec predicates{"predicates", component::ValueType::kString, "conditions", std::string()};
  predicates.choices_from = "predicate";
  mover.operations = {{"Pick", "picks", {predicates}}};
  mover.predicates = {{"left_of", 2, ""}};
  description.components = {mover};
  description.references = {"table_center"};
  description.object_classes = {"node"};

  const std::filesystem::path waypoints = std::filesystem::temp_directory_path() / "described_workcell_test.json";
  std::ofstream(waypoints) << R"({"waypoints": [{"name": "above", "joints": [0, 0, 0, 0, 0, 0]}]})";
  const auto cell = makeDescribedWorkcell(description, {.waypoints = waypoints});
  const bt::NodeSpec* pick = cell->nodes().find("Pick");
  ASSERT_NE(pick, nullptr);
  const auto& check = pick->ports.at(0).check;
  EXPECT_EQ(check("left_of(table_center)"), "");
  EXPECT_EQ(check("left_of(node)"), "");   // a class
  EXPECT_EQ(check("left_of(above)"), "");  // a taught waypoint
  EXPECT_NE(check("left_of(node_1)").find("unknown reference frame 'node_1'"), std::string::npos);
  EXPECT_NE(check("right_of(table_center)").find("unknown predicate 'right_of' (known: left_of)"), std::string::npos);
  EXPECT_NE(check("left_of(a, b)").find("takes 2 argument(s), 3 given"), std::string::npos);
  EXPECT_NE(check("left_of(table_center").find("must look like"), std::string::npos);

  const auto without = makeDescribedWorkcell(description, {.memory_only = true});
  EXPECT_NE(without->nodes().find("Pick")->ports.at(0).check("left_of(above)"), "");
  // Described operations cannot run: a node of one fails with the reason.
  EXPECT_THROW(cell->components().find("mover")->start("Pick", {}), std::runtime_error);
  std::filesystem::remove(waypoints);
}

}  // namespace
}  // namespace costar::workcell
