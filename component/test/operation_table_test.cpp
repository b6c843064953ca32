#include "component/operation_table.h"

#include <gtest/gtest.h>

#include "bt/registry.h"
#include "component/description.h"
#include "component/registry.h"

namespace costar::component {
namespace {

std::unique_ptr<RunningOperation> done(std::string what) {
  return std::make_unique<FinishedOperation>(OperationResult::success({{"ran", std::move(what)}}));
}

/// A component declaring `declared` in its description and handling `handled` in its table.
class Tabled final : public TableComponent {
 public:
  Tabled(std::vector<std::string> declared, std::vector<std::string> handled) {
    ComponentDescription description;
    description.name = "tabled";
    for (const std::string& name : declared) {
      description.operations.push_back({name, "", {}});
    }
    OperationTable operations;
    for (const std::string& name : handled) {
      operations.add({name, "does " + name, {}}, [name](const ParamMap&) { return done(name); });
    }
    declare(std::move(description), std::move(operations));
  }
  world::Report report() const override { return {}; }
};

TEST(OperationTable, EachOperationStartsItsOwnHandler) {
  Tabled component({}, {"Open", "Close"});
  ASSERT_EQ(component.description().operations.size(), 2u);
  EXPECT_EQ(component.description().operations[1].name, "Close");
  EXPECT_EQ(component.description().operations[1].description, "does Close");
  for (const std::string name : {"Open", "Close"}) {
    const OperationId id = component.start(name, {});
    EXPECT_EQ(component.poll(id).data.at("ran"), name);
  }
  try {
    component.start("Jump", {});
    FAIL() << "an undeclared operation started";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("no operation 'Jump'"), std::string::npos) << e.what();
  }
}

TEST(OperationTable, AComponentWhoseDescriptionAndTableDisagreeCannotBeBuilt) {
  // Declared with no handler, and a handler of an operation not declared: both named.
  try {
    Tabled component({"Open", "Close"}, {"Open", "Squeeze"});
    FAIL() << "a component whose description and table disagree was built";
  } catch (const std::logic_error& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("component 'tabled'"), std::string::npos) << message;
    EXPECT_NE(message.find("'Close' is declared but has no handler"), std::string::npos) << message;
    EXPECT_NE(message.find("'Squeeze' has a handler but is not declared"), std::string::npos) << message;
  }
  // The same operations both ways: built.
  EXPECT_NO_THROW(Tabled({"Open"}, {"Open"}));
}

TEST(OperationTable, RefusesAnOperationTwiceOrWithoutAHandlerOrAName) {
  OperationTable table;
  table.add({"Open", "", {}}, [](const ParamMap&) { return done("Open"); });
  EXPECT_THROW(table.add({"Open", "", {}}, [](const ParamMap&) { return done("again"); }), std::logic_error);
  EXPECT_THROW(table.add({"Close", "", {}}, nullptr), std::logic_error);
  EXPECT_THROW(table.add({"", "", {}}, [](const ParamMap&) { return done(""); }), std::logic_error);
  EXPECT_EQ(table.specs().size(), 1u);
}

TEST(OperationTable, InternalOperationsStartButAreNoNodeTypes) {
  class WithInternal final : public TableComponent {
   public:
    WithInternal() {
      ComponentDescription description;
      description.name = "mover";
      OperationTable operations;
      operations.add({"Go", "for plans", {}}, [](const ParamMap&) { return done("Go"); });
      operations.add({"FollowPath", "for other components", {}, OperationKind::kInternal},
                     [](const ParamMap&) { return done("FollowPath"); });
      declare(std::move(description), std::move(operations));
    }
    world::Report report() const override { return {}; }
  };
  auto component = std::make_shared<WithInternal>();
  ComponentRegistry registry;
  registry.add(component);
  bt::NodeRegistry nodes;
  registry.registerNodes(nodes);
  EXPECT_NE(nodes.find("Go"), nullptr);
  EXPECT_EQ(nodes.find("FollowPath"), nullptr);
  EXPECT_EQ(component->poll(component->start("FollowPath", {})).data.at("ran"), "FollowPath");
  // The kind survives the description's JSON.
  EXPECT_EQ(descriptionFromJson(toJson(component->description())).operations[1].kind, OperationKind::kInternal);
}

}  // namespace
}  // namespace costar::component
