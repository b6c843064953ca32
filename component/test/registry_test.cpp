#include "component/registry.h"

#include <gtest/gtest.h>

#include "bt/builder.h"
#include "bt/executor.h"
#include "bt/plan_xml.h"
#include "testing/test_components.h"

namespace costar::component {
namespace {

using bt::Status;

/// An arm that forgot Teach and the endpoint symbol.
class IncompleteArm final : public LocalComponent {
 public:
  IncompleteArm() {
    description_.name = "bad_arm";
    description_.type = "IncompleteArm";
    description_.implements = {"Arm"};
    description_.operations = {{"Move", "", {}}};
  }
  const ComponentDescription& description() const override { return description_; }
  world::Report report() const override {
    world::Report report;
    report.predicates.push_back({"undeclared_thing", {}, true, ""});
    return report;
  }

 private:
  std::unique_ptr<RunningOperation> begin(const std::string&, const ParamMap&) override {
    return std::make_unique<FinishedOperation>(OperationResult::success());
  }
  ComponentDescription description_;
};

TEST(ComponentRegistry, RefusesAComponentThatLacksWhatItsAbstractComponentRequires) {
  ComponentRegistry registry;
  try {
    registry.add(std::make_shared<IncompleteArm>());
    FAIL() << "expected a ComponentError";
  } catch (const ComponentError& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("Arm requires operation 'Teach'"), std::string::npos) << message;
    EXPECT_NE(message.find("Arm requires symbol 'endpoint'"), std::string::npos) << message;
  }
  EXPECT_NO_THROW(registry.add(std::make_shared<testing::TestArm>()));
}

TEST(ComponentRegistry, RefusesTakenNamesAndOperationsOfferedTwice) {
  ComponentRegistry registry;
  registry.add(std::make_shared<testing::TestArm>());
  EXPECT_THROW(registry.add(std::make_shared<testing::TestArm>()), ComponentError);
  auto other = std::make_shared<IncompleteArm>();
  try {
    registry.add(other);
    FAIL();
  } catch (const ComponentError& error) {
    EXPECT_NE(std::string(error.what()).find("operation 'Move' is already offered by component 'test_arm'"),
              std::string::npos)
        << error.what();
  }
}

/// Reports a predicate it never declared.
class Chatty final : public LocalComponent {
 public:
  Chatty() {
    description_.name = "chatty";
    description_.type = "Chatty";
    description_.predicates = {{"declared_thing", 0, ""}};
  }
  const ComponentDescription& description() const override { return description_; }
  world::Report report() const override {
    world::Report report;
    report.predicates.push_back({"declared_thing", {}, true, ""});
    report.predicates.push_back({"undeclared_thing", {}, true, ""});
    report.predicates.push_back({"declared_thing", {"with_an_argument"}, true, ""});  // wrong arity
    return report;
  }

 private:
  std::unique_ptr<RunningOperation> begin(const std::string&, const ParamMap&) override { return nullptr; }
  ComponentDescription description_;
};

TEST(ComponentRegistry, WorldStateIsTheUnionOfReportsAndUndeclaredPredicatesAreDropped) {
  ComponentRegistry registry;
  registry.add(std::make_shared<testing::TestArm>());
  registry.add(std::make_shared<Chatty>());
  registry.refreshWorld();
  ASSERT_NE(registry.world().symbol("endpoint"), nullptr);
  EXPECT_EQ(registry.world().symbol("endpoint")->source, "test_arm");
  EXPECT_NE(registry.world().symbol("home"), nullptr);
  EXPECT_TRUE(registry.world().holds("declared_thing", {}));
  EXPECT_FALSE(registry.world().holds("undeclared_thing", {}));
  const std::vector<std::string> one{"with_an_argument"};
  EXPECT_FALSE(registry.world().holds("declared_thing", one));
  EXPECT_EQ(registry.world().predicates().size(), 1u);
}

class RunsPlans : public ::testing::Test {
 protected:
  RunsPlans() {
    components.add(logger);
    components.add(actions);
    components.add(counter);
    components.add(arm);
    components.registerNodes(nodes);
  }

  bt::RunResult run(const std::string& body) {
    const std::string xml = R"(<root BTCPP_format="4"><BehaviorTree ID="main">)" + body + "</BehaviorTree></root>";
    bt::Tree tree = bt::buildTree(bt::loadPlanText(xml, "plan.xml"), nodes, clock);
    bt::Executor executor(tree, clock);
    executor.setBeforeTick([this] { components.refreshWorld(); });
    return executor.run();
  }

  std::vector<bt::Diagnostic> problems(const std::string& body) {
    const std::string xml = R"(<root BTCPP_format="4"><BehaviorTree ID="main">)" + body + "</BehaviorTree></root>";
    return bt::validatePlan(bt::loadPlanText(xml, "plan.xml"), nodes);
  }

  SimClock clock;
  ComponentRegistry components;
  bt::NodeRegistry nodes = bt::builtinRegistry();
  std::shared_ptr<testing::TestLogger> logger = std::make_shared<testing::TestLogger>();
  std::shared_ptr<testing::TestActions> actions = std::make_shared<testing::TestActions>();
  std::shared_ptr<testing::TestCounter> counter = std::make_shared<testing::TestCounter>();
  std::shared_ptr<testing::TestArm> arm = std::make_shared<testing::TestArm>();
};

TEST_F(RunsPlans, OperationsBecomeNodeTypesWithTypedValidatedParameters) {
  const bt::NodeSpec* move = nodes.find("Move");
  ASSERT_NE(move, nullptr);
  EXPECT_EQ(move->category, bt::NodeCategory::kRobotAction);
  EXPECT_EQ(nodes.find("TestLog")->category, bt::NodeCategory::kKnowledge);
  const auto bad = problems(
      R"(<Sequence><TestAction polls="soon"/><TestAction result="maybe"/><SetEndpoint pose="1;2"/></Sequence>)");
  ASSERT_EQ(bad.size(), 3u);
  EXPECT_EQ(bad[0].message, "parameter 'polls' of TestAction: 'soon' is not an integer");
  EXPECT_EQ(bad[1].message, "parameter 'result' of TestAction: 'maybe' is not one of: success, failure");
  EXPECT_NE(bad[2].message.find("has 2 numbers"), std::string::npos);
}

TEST_F(RunsPlans, AnOperationRunsAcrossTicksAndItsResultIsTheLeafsResult) {
  const bt::RunResult result = run(R"(<Sequence><TestLog message="hello"/><TestAction polls="3"/>
      <TestAction name="grasp" result="failure" reason="no reachable candidate"/></Sequence>)");
  EXPECT_EQ(result.status, Status::kFailure);
  EXPECT_EQ(result.failure_path, R"(main/Sequence[1]/TestAction "grasp")");
  EXPECT_EQ(result.failure_reason, "no reachable candidate");
  EXPECT_EQ(result.ticks, 4u);
  EXPECT_EQ(logger->messages(), std::vector<std::string>{"hello"});
}

TEST_F(RunsPlans, AHaltedOperationIsCancelledOnTheComponent) {
  const bt::RunResult result = run(R"(<Timeout msec="100"><TestAction polls="1000"/></Timeout>)");
  EXPECT_EQ(result.status, Status::kFailure);
  EXPECT_EQ(actions->starts.load(), 1);
  EXPECT_EQ(actions->cancels.load(), 1);
}

TEST_F(RunsPlans, AComponentFaultIsAFailureWithAReasonNotACrash) {
  const bt::RunResult result = run(R"(<TestThrow/>)");
  EXPECT_EQ(result.status, Status::kFailure);
  EXPECT_EQ(result.failure_reason, "test_actions failed: simulated component fault");
  EXPECT_EQ(result.ticks, 1u);
}

TEST_F(RunsPlans, AbstractArmOperationsAndPredicatesDriveThePlan) {
  const bt::RunResult result = run(R"(<Sequence>
      <SetEndpoint pose="0.5;0;0.2;180;0;0"/><Teach waypoint="above_part"/>
      <Move waypoint="home"/><CheckPredicate predicate="at_waypoint" args="home"/>
      <Move waypoint="above_part"/><CheckPredicate predicate="at_waypoint" args="home" expected="false"/>
      <Move name="nowhere" waypoint="nowhere"/></Sequence>)");
  EXPECT_EQ(result.status, Status::kFailure);
  EXPECT_EQ(result.failure_path, R"(main/Sequence[1]/Move "nowhere")");
  EXPECT_EQ(result.failure_reason, "unknown waypoint 'nowhere'");
}

TEST_F(RunsPlans, ConditionsTestTheWorldStateAndSayWhichPredicateFailed) {
  const bt::RunResult result = run(R"(<Sequence>
      <Repeat num_cycles="3"><TestCount counter="parts"/></Repeat>
      <CheckPredicate predicate="test_count" args="parts;3"/>
      <CheckPredicate predicate="test_count" args="parts;4"/></Sequence>)");
  EXPECT_EQ(result.status, Status::kFailure);
  EXPECT_EQ(result.failure_reason, "test_count(parts,4) is false");
  EXPECT_EQ(counter->value("parts"), 3);
}

TEST_F(RunsPlans, AWildcardAsksWhetherAnySymbolSatisfiesThePredicate) {
  const bt::RunResult result = run(R"(<Sequence>
      <TestCount counter="parts"/>
      <CheckPredicate predicate="test_count" args="?;1"/>
      <CheckPredicate predicate="test_count" args="parts;?"/>
      <CheckPredicate predicate="test_count" args="?;7" expected="false"/>
      <CheckPredicate predicate="test_count" args="?;2"/></Sequence>)");
  EXPECT_EQ(result.status, Status::kFailure);
  EXPECT_EQ(result.failure_reason, "no symbol satisfies test_count(?,2)");
  EXPECT_EQ(problems(R"(<CheckPredicate predicate="test_count" args="?;?"/>)")[0].message,
            "CheckPredicate: only one argument may be the wildcard ?");
}

TEST_F(RunsPlans, UnknownPredicatesAndWrongArityFailValidation) {
  const auto bad = problems(R"(<Sequence><CheckPredicate predicate="is_blue" args="x"/>
      <CheckPredicate predicate="test_count" args="parts"/></Sequence>)");
  ASSERT_EQ(bad.size(), 2u);
  EXPECT_NE(bad[0].message.find("'is_blue' is not one of"), std::string::npos) << bad[0].message;
  EXPECT_EQ(bad[1].message, "CheckPredicate: predicate 'test_count' takes 2 argument(s), 1 given");
}

}  // namespace
}  // namespace costar::component
