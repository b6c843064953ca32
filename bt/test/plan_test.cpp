// Plan files: BehaviorTree.CPP v4 XML in and out, and every validation error with its line.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "bt/nodes_model.h"
#include "bt/test/test_support.h"

namespace costar::bt {
namespace {

using testing::planXml;

std::vector<Diagnostic> problems(const std::string& xml) {
  testing::EventLog log;
  const NodeRegistry registry = testing::registryWithTestLeaf(log);
  try {
    return validatePlan(loadPlanText(xml, "plan.xml", {.follow_includes = false}), registry);
  } catch (const PlanError& error) {
    return error.diagnostics();
  }
}

std::string hexBytesForTest(const std::string& bytes) {
  std::string out;
  for (const char c : bytes) {
    out += std::to_string(static_cast<unsigned char>(c)) + " ";
  }
  return out;
}

/// The single problem of `xml`, as "line: message".
std::string problem(const std::string& xml) {
  const auto diagnostics = problems(xml);
  if (diagnostics.size() != 1) {
    std::string all = std::to_string(diagnostics.size()) + " problems:";
    for (const auto& d : diagnostics) {
      all += "\n  " + d.str();
    }
    return all;
  }
  return std::to_string(diagnostics[0].where.line) + ": " + diagnostics[0].message;
}

// --- reading ------------------------------------------------------------------------------

TEST(PlanXml, ReadsCompactAndExplicitFormsAlike) {
  const PlanFile compact =
      parsePlanFile(planXml(R"(<Sequence name="s"><Repeat num_cycles="2"><AlwaysSuccess/></Repeat></Sequence>)"), "a");
  const PlanFile explicit_form = parsePlanFile(
      planXml(
          R"(<Control ID="Sequence" name="s"><Decorator ID="Repeat" num_cycles="2"><Action ID="AlwaysSuccess"/></Decorator></Control>)"),
      "b");
  EXPECT_TRUE(sameContent(compact, explicit_form));
  EXPECT_EQ(compact.main_tree, "main");
  ASSERT_EQ(compact.trees.size(), 1u);
  EXPECT_EQ(compact.trees[0].root.name(), "s");
  EXPECT_EQ(compact.trees[0].root.children[0].attribute("num_cycles"), "2");
}

TEST(PlanXml, IgnoresTreeNodesModelAndRecordsLines) {
  const PlanFile file = parsePlanFile(
      "<root BTCPP_format=\"4\">\n"
      "  <BehaviorTree ID=\"only\">\n"
      "    <Sequence>\n"
      "      <AlwaysSuccess/>\n"
      "    </Sequence>\n"
      "  </BehaviorTree>\n"
      "  <TreeNodesModel><Action ID=\"Move\"/></TreeNodesModel>\n"
      "</root>\n",
      "p.xml");
  EXPECT_EQ(file.trees[0].root.location.line, 3);
  EXPECT_EQ(file.trees[0].root.children[0].location.line, 4);
  Plan plan;
  plan.file = file;
  EXPECT_EQ(plan.mainTreeId(), "only");
}

// --- round trip -----------------------------------------------------------------------------

TEST(PlanXml, LoadSaveLoadIsLosslessAndSavingIsStable) {
  const std::string xml = R"(<root BTCPP_format="4" main_tree_to_execute="main">
    <include path="lib/grasp.xml"/>
    <BehaviorTree ID="main">
      <Sequence name="assemble &amp; check">
        <Reset num_resets="3"><SubTree ID="grasp" _autoremap="false"/></Reset>
        <Parallel success_count="1" failure_count="-1"><Sleep msec="10"/><AlwaysSuccess name="quote &quot;here&quot;"/></Parallel>
        <Iterator><AlwaysFailure/></Iterator>
      </Sequence>
    </BehaviorTree>
    <BehaviorTree ID="other"><Timeout msec="5"><AlwaysSuccess/></Timeout></BehaviorTree>
  </root>)";
  const PlanFile first = parsePlanFile(xml, "a.xml");
  const std::string saved = writePlanFile(first);
  const PlanFile second = parsePlanFile(saved, "b.xml");
  EXPECT_TRUE(sameContent(first, second)) << saved;
  EXPECT_EQ(writePlanFile(second), saved);
  EXPECT_EQ(second.trees[0].root.name(), "assemble & check");
  ASSERT_EQ(second.includes.size(), 1u);
  EXPECT_EQ(second.includes[0].path, "lib/grasp.xml");
}

TEST(PlanXml, SaveWithModelDescribesTheNonBuiltinNodesUsed) {
  testing::EventLog log;
  const NodeRegistry registry = testing::registryWithTestLeaf(log);
  const PlanFile file = parsePlanFile(planXml(R"(<Reset num_resets="1"><TestLeaf ticks="2"/></Reset>)"), "a");
  const std::string saved = writePlanFile(file, {.model_from = &registry});
  EXPECT_NE(saved.find(R"(<Decorator ID="Reset">)"), std::string::npos) << saved;
  EXPECT_NE(saved.find(R"(<Action ID="TestLeaf">)"), std::string::npos);
  EXPECT_EQ(saved.find(R"(ID="Sequence")"), std::string::npos);
  // The model in the file does not change what is read back.
  EXPECT_TRUE(sameContent(parsePlanFile(saved, "b"), file));
}

// --- TreeNodesModel -------------------------------------------------------------------------

TEST(NodesModel, ListsCostarNodesWithPortsTypesAndDefaults) {
  const std::string model = treeNodesModelXml(builtinRegistry());
  EXPECT_NE(model.find(R"(<Decorator ID="Reset">)"), std::string::npos) << model;
  EXPECT_NE(model.find(R"(<Control ID="Iterator">)"), std::string::npos);
  EXPECT_NE(model.find(R"(<input_port name="num_resets" type="int">)"), std::string::npos);
  EXPECT_EQ(model.find(R"(ID="Fallback")"), std::string::npos);  // Groot2 knows it
  const std::string all = treeNodesModelXml(builtinRegistry(), {.include_btcpp_builtins = true});
  EXPECT_NE(all.find(R"(<input_port name="success_count" type="int" default="-1">)"), std::string::npos) << all;
}

// --- validation errors ----------------------------------------------------------------------

TEST(Validation, MalformedXmlNamesTheLine) {
  // The line of the element left open.
  const auto unclosed =
      problems("<root BTCPP_format=\"4\">\n<BehaviorTree ID=\"m\">\n<Sequence>\n</BehaviorTree></root>");
  ASSERT_EQ(unclosed.size(), 1u);
  EXPECT_EQ(unclosed[0].where.line, 3);
  EXPECT_NE(unclosed[0].message.find("<Sequence> is not closed (mismatched end tag on line 4)"), std::string::npos)
      << unclosed[0].message;
  EXPECT_NE(problem("<root><BehaviorTree ID=\"m\"><Sequence></root>").find("malformed XML"), std::string::npos);
  // Comments, self-closed elements and '>' inside attribute values are no open elements.
  const auto inner = problems(
      "<root BTCPP_format=\"4\">\n<BehaviorTree ID=\"m\">\n<Sequence><!-- <Fallback> -->\n"
      "<Script code=\"a > b\"/>\n<Inverter>\n<AlwaysSuccess/>\n</Sequence></BehaviorTree></root>");
  ASSERT_EQ(inner.size(), 1u);
  EXPECT_EQ(inner[0].where.line, 5);
  EXPECT_NE(inner[0].message.find("<Inverter> is not closed"), std::string::npos) << inner[0].message;
}

TEST(Validation, NestingUpToBehaviorTreeCppsLimitIsRead) {
  // 300 levels (BehaviorTree.CPP reads up to 500); deeper is refused with a message, not a crash.
  const auto nested = [](int levels) {
    std::string xml = "<root BTCPP_format=\"4\"><BehaviorTree ID=\"m\">";
    for (int i = 0; i < levels; ++i) {
      xml += "<Inverter>";
    }
    xml += "<AlwaysSuccess/>";
    for (int i = 0; i < levels; ++i) {
      xml += "</Inverter>";
    }
    return xml + "</BehaviorTree></root>";
  };
  EXPECT_TRUE(problems(nested(300)).empty());
  const auto deep = problems(nested(100000));
  ASSERT_EQ(deep.size(), 1u);
  EXPECT_NE(deep[0].message.find("nesting is too deep: more than 500 levels"), std::string::npos) << deep[0].message;
}

TEST(Validation, UnknownNodeWithASuggestion) {
  EXPECT_EQ(problem(planXml("\n<Sequense><AlwaysSuccess/></Sequense>")),
            "2: unknown node 'Sequense' (did you mean 'Sequence'?)");
  EXPECT_EQ(problem(planXml("<Frobnicate/>")), "1: unknown node 'Frobnicate'");
}

TEST(Validation, MissingIllTypedAndUnknownParameters) {
  EXPECT_EQ(problem(planXml("<Repeat><AlwaysSuccess/></Repeat>")),
            "1: Repeat needs parameter 'num_cycles' (successful runs to complete (-1 = forever))");
  EXPECT_EQ(problem(planXml(R"(<Repeat num_cycles="three"><AlwaysSuccess/></Repeat>)")),
            "1: parameter 'num_cycles' of Repeat: 'three' is not an integer");
  EXPECT_EQ(problem(planXml(R"(<Sleep msec="10" sec="1"/>)")), "1: Sleep has no parameter 'sec' (it takes msec)");
  EXPECT_EQ(problem(planXml(R"(<TestLeaf ticks="1.5"/>)")),
            "1: parameter 'ticks' of TestLeaf: '1.5' is not an integer");
}

TEST(Validation, BadCounts) {
  EXPECT_EQ(problem(planXml(R"(<Repeat num_cycles="0"><AlwaysSuccess/></Repeat>)")),
            "1: parameter 'num_cycles' of Repeat: 0 is out of range: expected an integer from 1 to "
            "1000000000, or -1");
  EXPECT_EQ(problem(planXml(R"(<Reset num_resets="-2"><AlwaysSuccess/></Reset>)")),
            "1: parameter 'num_resets' of Reset: -2 is out of range: expected an integer from 0 to "
            "1000000000, or -1");
  EXPECT_NE(problem(planXml(R"(<Parallel success_count="3"><AlwaysSuccess/><AlwaysSuccess/></Parallel>)"))
                .find("success_count=3 does not fit 2 children"),
            std::string::npos);
}

TEST(Validation, ChildCounts) {
  EXPECT_EQ(problem(planXml("<Sequence/>")), "1: Sequence needs at least one child");
  EXPECT_EQ(problem(planXml("<Inverter><AlwaysSuccess/><AlwaysSuccess/></Inverter>")),
            "1: Inverter needs exactly one child, has 2");
  EXPECT_EQ(problem(planXml("<AlwaysSuccess><AlwaysSuccess/></AlwaysSuccess>")),
            "1: AlwaysSuccess is a leaf and cannot have children, has 1");
}

TEST(Validation, UnknownAndRecursiveSubtrees) {
  EXPECT_EQ(problem(planXml(R"(<SubTree ID="grasp"/>)")), "1: unknown subtree 'grasp' (the plan defines: main)");
  const std::string recursive = planXml(R"(<SubTree ID="a"/>)",
                                        R"(<BehaviorTree ID="a"><Sequence><SubTree ID="b"/></Sequence></BehaviorTree>
                                           <BehaviorTree ID="b"><SubTree ID="a"/></BehaviorTree>)");
  EXPECT_EQ(problem(recursive), "2: subtree 'a' contains itself: main -> a -> b -> a");
}

TEST(Validation, NoVariablesNoScripts) {
  EXPECT_NE(problem(planXml(R"(<Sleep msec="{delay}"/>)"))
                .find("a blackboard reference; CoSTAR plans have no "
                      "blackboard, by design"),
            std::string::npos);
  EXPECT_NE(problem(planXml(R"(<AlwaysSuccess _skipIf="x == 1"/>)")).find("script"), std::string::npos);
  EXPECT_NE(problem(planXml(R"(<SubTree ID="main2" target="{t}"/>)",
                            R"(<BehaviorTree ID="main2"><AlwaysSuccess/></BehaviorTree>)"))
                .find("remapping needs a blackboard"),
            std::string::npos);
}

TEST(Validation, BlackboardNodesAreRefusedByDesignSayingWhatToUseInstead) {
  EXPECT_EQ(problem(planXml(R"(<Script code="a := 1"/>)")),
            "1: 'Script' is a BehaviorTree.CPP node that works on the blackboard; CoSTAR plans have no blackboard, "
            "by design (the paper: no user variables, no scope): write each value as a parameter of the node that "
            "uses it instead");
  EXPECT_NE(problem(planXml(R"(<Switch2 variable="{v}" case_1="1"><AlwaysSuccess/><AlwaysSuccess/>)"
                            R"(<AlwaysSuccess/></Switch2>)"))
                .find("IfThenElse, WhileDoElse or a Fallback over CheckPredicate nodes"),
            std::string::npos);
  EXPECT_NE(problem(planXml(R"(<ScriptCondition code="x == 1"/>)")).find("CheckPredicate"), std::string::npos);
  EXPECT_NE(problem(planXml(R"(<AlwaysSuccess _while="busy"/>)")).find("by design"), std::string::npos);
}

TEST(Validation, NewControlNodesCheckTheirChildren) {
  EXPECT_EQ(problem(planXml(R"(<IfThenElse><AlwaysSuccess/></IfThenElse>)")),
            "1: IfThenElse: needs 2 or 3 children (the condition, then-branch, optional else-branch), has 1");
  EXPECT_NE(problem(planXml(R"(<WhileDoElse><AlwaysSuccess/><AlwaysSuccess/><AlwaysSuccess/><AlwaysSuccess/>)"
                            R"(</WhileDoElse>)"))
                .find("needs 2 or 3 children"),
            std::string::npos);
  EXPECT_EQ(problem(planXml(R"(<TryCatch><AlwaysSuccess/></TryCatch>)")),
            "1: TryCatch: needs at least 2 children (the try block, then the catch child), has 1");
  EXPECT_EQ(problem(planXml(R"(<ParallelAll max_failures="3"><AlwaysSuccess/><AlwaysSuccess/></ParallelAll>)")),
            "1: ParallelAll: max_failures=3 is more than its 2 children: it could never fail");
  EXPECT_TRUE(
      problems(planXml(R"(<ParallelAll max_failures="-1"><AlwaysSuccess/><AlwaysSuccess/></ParallelAll>)")).empty());
  EXPECT_NE(problem(planXml(R"(<Delay><AlwaysSuccess/></Delay>)")).find("needs parameter 'delay_msec'"),
            std::string::npos);
  EXPECT_NE(problem(planXml(R"(<RunOnce then_skip="maybe"><AlwaysSuccess/></RunOnce>)")).find("not true or false"),
            std::string::npos);
  // WhileDoElse re-checks its condition on every tick: the condition must not take time.
  EXPECT_NE(problem(planXml(R"(<WhileDoElse><TestLeaf/><AlwaysSuccess/></WhileDoElse>)"))
                .find("WhileDoElse re-checks its first child on every tick"),
            std::string::npos);
  EXPECT_TRUE(problems(planXml(R"(<WhileDoElse><TestCondition/><TestLeaf/><TestLeaf/></WhileDoElse>)")).empty());
}

TEST(PlanXml, AcceptsBehaviorTreeCppsPrivateAttributesAndUnknownRootAttributes) {
  // Forms BehaviorTree.CPP 4.10 accepts (checked with the peer): underscore attributes are
  // metadata, unknown <root> attributes (Groot2's project_name) are ignored.
  EXPECT_TRUE(problems(R"(<root BTCPP_format="4" project_name="demo"><BehaviorTree ID="m" _description="x">)"
                       R"(<Sequence _uid="3" _fullpath="m/seq"><AlwaysSuccess _description="y"/></Sequence>)"
                       R"(</BehaviorTree></root>)")
                  .empty());
  EXPECT_TRUE(problems(R"(<root><BehaviorTree ID="m"><AlwaysSuccess/></BehaviorTree></root>)").empty());
  // ... but not BehaviorTree.CPP's scripts.
  EXPECT_NE(problem(planXml(R"(<AlwaysSuccess _skipIf="a"/>)")).find("by design"), std::string::npos);
}

TEST(PlanXml, ATreeWithoutAnIdIsNamedAsBehaviorTreeCppNamesIt) {
  const std::string xml = R"(<?xml version="1.0"?>
    <root BTCPP_format="4"><BehaviorTree><Sequence><AlwaysSuccess/></Sequence></BehaviorTree></root>)";
  const Plan plan = loadPlanText(xml, "unnamed.xml");
  EXPECT_EQ(plan.mainTreeId(), "BehaviorTree_0");
  SimClock clock;
  Tree tree = buildTree(plan, builtinRegistry(), clock);
  EXPECT_EQ(tree.tick(), Status::kSuccess);
  // As BehaviorTree.CPP: only a file's single tree may leave its ID out.
  EXPECT_EQ(problem("<root BTCPP_format=\"4\"><BehaviorTree ID=\"a\"><AlwaysSuccess/></BehaviorTree>\n"
                    "<BehaviorTree><AlwaysFailure/></BehaviorTree></root>"),
            "2: <BehaviorTree> needs an ID attribute: the file has 2 trees (only a file's single tree may leave it "
            "out)");
  EXPECT_EQ(problem(R"(<root BTCPP_format="4"><BehaviorTree ID=""><AlwaysSuccess/></BehaviorTree></root>)"),
            "1: <BehaviorTree ID=\"\"> has an empty ID: name the tree, or leave ID out");
}

TEST(Validation, ReactiveNodesOnlyLetTheirLastChildRun) {
  EXPECT_NE(problem(planXml(R"(<ReactiveSequence><TestLeaf/><TestLeaf/></ReactiveSequence>)"))
                .find("only the last child of a ReactiveSequence may take time"),
            std::string::npos);
  EXPECT_NE(
      problem(
          planXml(
              R"(<ReactiveFallback><Repeat num_cycles="2"><TestCondition/></Repeat><TestLeaf/></ReactiveFallback>)"))
          .find("Repeat can be RUNNING"),
      std::string::npos);
  EXPECT_TRUE(
      problems(planXml(R"(<ReactiveSequence><Inverter><TestCondition/></Inverter><TestLeaf/></ReactiveSequence>)"))
          .empty());
}

TEST(Validation, StructureOfTheFile) {
  EXPECT_EQ(problem(R"(<root BTCPP_format="3"><BehaviorTree ID="m"><AlwaysSuccess/></BehaviorTree></root>)"),
            "1: BTCPP_format=\"3\" is not supported: plans use BehaviorTree.CPP's format 4");
  EXPECT_EQ(
      problem(
          "<root BTCPP_format=\"4\"><BehaviorTree ID=\"m\">\n<AlwaysSuccess/><AlwaysSuccess/></BehaviorTree></root>"),
      "2: BehaviorTree 'm' has more than one root node: wrap them in a Sequence");
  EXPECT_EQ(
      problem(
          R"(<root BTCPP_format="4" main_tree_to_execute="nope"><BehaviorTree ID="m"><AlwaysSuccess/></BehaviorTree></root>)"),
      "0: main_tree_to_execute names 'nope', but no BehaviorTree has that ID");
  EXPECT_EQ(
      problem(
          R"(<root BTCPP_format="4"><BehaviorTree ID="a"><AlwaysSuccess/></BehaviorTree><BehaviorTree ID="b"><AlwaysSuccess/></BehaviorTree></root>)"),
      "0: the file defines several BehaviorTrees but no main_tree_to_execute");
  EXPECT_EQ(problem(R"(<plan/>)"), "1: the top element must be <root BTCPP_format=\"4\">, found <plan>");
}

TEST(Validation, ReportsEveryProblemNotJustTheFirst) {
  const auto diagnostics = problems(planXml("<Sequence>\n<Foo/>\n<Repeat/>\n<Sleep msec=\"x\"/></Sequence>"));
  ASSERT_EQ(diagnostics.size(), 4u);  // Foo, Repeat without child, Repeat without num_cycles, msec
  EXPECT_EQ(diagnostics[0].where.line, 2);
  EXPECT_EQ(diagnostics[3].where.line, 4);
}

TEST(Validation, SizeLimitsStopExponentialSubtrees) {
  std::string trees;
  for (int i = 0; i < 30; ++i) {
    trees += "<BehaviorTree ID=\"t" + std::to_string(i) + "\"><Sequence><SubTree ID=\"t" + std::to_string(i + 1) +
             "\"/><SubTree ID=\"t" + std::to_string(i + 1) + "\"/></Sequence></BehaviorTree>";
  }
  trees += "<BehaviorTree ID=\"t30\"><AlwaysSuccess/></BehaviorTree>";
  EXPECT_NE(problem(planXml(R"(<SubTree ID="t0"/>)", trees)).find("expands to more than 1000000 nodes"),
            std::string::npos);
}

TEST(Validation, AChainOf12000SubTreesIsRefusedAsTooDeepNotACrash) {
  // Issue 27: ~950 KB, a chain of 12,000 SubTrees. The depth measurement recursed to the end of
  // the chain before checking the limit (and searched the stack at each level): SIGSEGV.
  const std::string xml = testing::subTreeChainXml(12000);
  ASSERT_GT(xml.size(), 900'000u);
  const auto diagnostics = problems(xml);
  ASSERT_EQ(diagnostics.size(), 1u);
  EXPECT_EQ(diagnostics[0].where.file, "plan.xml");
  // 1,000 levels: the Inverter of T0 is level 1, so the 1,001st level is T500's Inverter, line 502.
  EXPECT_EQ(diagnostics[0].str(),
            "plan.xml:502: the plan nests deeper than 1000 levels once its subtrees are instantiated");
  // So is a chain that leads back to its start, and building refuses it the same way.
  EXPECT_NE(problem(testing::subTreeChainXml(12000, true)).find("nests deeper than 1000 levels"), std::string::npos);
  testing::EventLog log;
  SimClock clock;
  EXPECT_THROW(buildTree(loadPlanText(xml, "plan.xml"), testing::registryWithTestLeaf(log), clock), PlanError);
}

TEST(Validation, AChainWithinTheDepthLimitBuildsAndRuns) {
  // 500 trees: 500 Inverters, 499 SubTrees and the leaf, 1,000 levels.
  testing::EventLog log;
  SimClock clock;
  Tree tree =
      buildTree(loadPlanText(testing::subTreeChainXml(500), "plan.xml"), testing::registryWithTestLeaf(log), clock);
  EXPECT_EQ(tree.nodes().size(), 1000u);
  EXPECT_EQ(tree.tick(), Status::kSuccess);  // an even number of Inverters over a SUCCESS
  EXPECT_NE(problem(testing::subTreeChainXml(501)).find("nests deeper than 1000 levels"), std::string::npos);
}

TEST(Validation, ALongLoopOfSubTreesIsReportedAsRecursion) {
  EXPECT_EQ(problem(testing::subTreeChainXml(3, true)), "4: subtree 'T0' contains itself: T0 -> T1 -> T2 -> T0");
}

TEST(Validation, RunningIsFoundThroughAnyNumberOfSubTrees) {
  // The RUNNING check looked only 64 levels down: a TestLeaf 100 SubTrees below the first child
  // of a ReactiveSequence was missed.
  std::string trees;
  for (int i = 0; i < 100; ++i) {
    trees += "<BehaviorTree ID=\"s" + std::to_string(i) + "\"><SubTree ID=\"s" + std::to_string(i + 1) +
             "\"/></BehaviorTree>";
  }
  trees += R"(<BehaviorTree ID="s100"><TestLeaf/></BehaviorTree>)";
  EXPECT_NE(problem(planXml(R"(<ReactiveSequence><SubTree ID="s0"/><TestLeaf/></ReactiveSequence>)", trees))
                .find("only the last child of a ReactiveSequence may take time"),
            std::string::npos);
}

TEST(Validation, TheRunningCheckLooksAtEachTreeOnce) {
  // Each tree uses the next twice: 2^40 paths through 40 trees. The check went down every path
  // (to 64 levels: billions of calls); it looks at each tree once.
  std::string trees;
  for (int i = 0; i < 40; ++i) {
    const std::string next = "<SubTree ID=\"d" + std::to_string(i + 1) + "\"/>";
    trees += "<BehaviorTree ID=\"d" + std::to_string(i) + "\"><Sequence>" + next + next + "</Sequence></BehaviorTree>";
  }
  trees += R"(<BehaviorTree ID="d40"><AlwaysSuccess/></BehaviorTree>)";
  // Only the size is refused: nothing in it can be RUNNING.
  const auto diagnostics =
      problems(planXml(R"(<ReactiveSequence><SubTree ID="d0"/><TestLeaf/></ReactiveSequence>)", trees));
  ASSERT_EQ(diagnostics.size(), 1u);
  EXPECT_NE(diagnostics[0].message.find("expands to more than 1000000 nodes"), std::string::npos);
}

TEST(Validation, PathsThatAddUpToTooManyBytesAreRefused) {
  // A 100 KB name above 1,000 nodes: each of their paths repeats it (100 MB of paths).
  std::string wide = "<BehaviorTree ID=\"wide\"><Sequence>";
  for (int i = 0; i < 1000; ++i) {
    wide += "<AlwaysSuccess/>";
  }
  wide += "</Sequence></BehaviorTree>";
  const std::string name(100'000, 'n');
  EXPECT_NE(problem(planXml("<Sequence name=\"" + name + "\"><SubTree ID=\"wide\"/></Sequence>", wide))
                .find("node paths (main/Sequence[1]/..., one per node) add up to more than 64 MiB"),
            std::string::npos);
  EXPECT_TRUE(problems(planXml("<Sequence name=\"short\"><SubTree ID=\"wide\"/></Sequence>", wide)).empty());
}

TEST(Validation, AnUnknownSubtreeListsTheFirstTwentyTrees) {
  std::string trees;
  for (int i = 0; i < 30; ++i) {
    trees += "<BehaviorTree ID=\"t" + std::to_string(i) + "\"><AlwaysSuccess/></BehaviorTree>";
  }
  EXPECT_EQ(problem(planXml(R"(<SubTree ID="nope"/>)", trees)),
            "1: unknown subtree 'nope' (the plan defines: main, t0, t1, t2, t3, t4, t5, t6, t7, t8, t9, t10, t11, "
            "t12, t13, t14, t15, t16, t17, t18 and 11 more)");
}

TEST(PlanXml, InvalidUtf8IsRefusedAtLoadWithLineColumnAndBytes) {
  // Issue 27: a name with bytes that are not UTF-8 validated and ran; writing the trials' JSON
  // threw at the end, losing the batch.
  EXPECT_EQ(problem("<root BTCPP_format=\"4\">\n<BehaviorTree ID=\"m\">\n  <AlwaysSuccess name=\"ok \xff\xfe\"/>\n"
                    "</BehaviorTree></root>"),
            "3: column 27: invalid UTF-8 (bytes FF FE): plan files are UTF-8 text (save it as UTF-8)");
  // A character cut short, an overlong form, an encoded surrogate, beyond U+10FFFF: each refused.
  for (const std::string bad : {"\xc3", "\xe2\x82", "\xc0\xaf", "\xed\xa0\x80", "\xf4\x90\x80\x80", "\x80"}) {
    const auto diagnostics = problems(planXml("<AlwaysSuccess name=\"" + bad + "\"/>"));
    ASSERT_EQ(diagnostics.size(), 1u) << hexBytesForTest(bad);
    EXPECT_NE(diagnostics[0].message.find("invalid UTF-8"), std::string::npos) << diagnostics[0].message;
    EXPECT_EQ(diagnostics[0].where.file, "plan.xml");
  }
  // In an element's name too, and each line once.
  EXPECT_EQ(problems("<root BTCPP_format=\"4\"><BehaviorTree ID=\"m\"><Sequence\xe9 a=\"\xe9\"/>\n<X \xe9/>"
                     "</BehaviorTree></root>")
                .size(),
            2u);
  // Valid UTF-8 everywhere is read as it is.
  const Plan plan =
      loadPlanText(planXml("<AlwaysSuccess name=\"n\xc5\x93ud \xf0\x9f\x99\x82 \xe2\x82\xac\"/>"), "ok.xml");
  EXPECT_EQ(plan.file.trees[0].root.name(), "n\xc5\x93ud \xf0\x9f\x99\x82 \xe2\x82\xac");
}

TEST(PlanXml, CharacterReferencesToSurrogatesAndNonCharactersAreRefused) {
  // Issue 27: the XML parser turns &#xD800; into bytes that are not UTF-8 (the server accepted it).
  EXPECT_EQ(problem(planXml("\n<AlwaysSuccess name=\"a&#xD800;b\"/>")),
            "2: column 23: the character reference '&#xD800;' is not a character XML allows (a UTF-16 surrogate, not "
            "a character)");
  for (const std::string reference :
       {"&#55296;", "&#xdfff;", "&#0;", "&#x1;", "&#x110000;", "&#xFFFE;", "&#99999999999999999999;"}) {
    EXPECT_NE(problem(planXml("<AlwaysSuccess name=\"" + reference + "\"/>")).find("is not a character XML allows"),
              std::string::npos)
        << reference;
  }
  // Characters XML allows, written as references, are read as those characters.
  const Plan plan = loadPlanText(planXml("<AlwaysSuccess name=\"&#x10FFFF;&#233;&#x9;&amp;\"/>"), "ok.xml");
  EXPECT_EQ(plan.file.trees[0].root.name(), "\xf4\x8f\xbf\xbf\xc3\xa9\t&");
  // In comments and CDATA a reference is text, not a character: not refused.
  EXPECT_TRUE(problems(planXml("<!-- &#xD800; --><AlwaysSuccess/>")).empty());
}

// A hostile tester: a NUL byte ended the plan there without a word (the nodes after it vanished),
// and a <!DOCTYPE>'s entities were left as written ("&part;" became a node's name).
TEST(PlanXml, ControlCharactersAndADoctypeAreRefusedWithLineAndColumn) {
  const std::string nul = planXml("\n<AlwaysSuccess/>" + std::string(1, '\0') + "<AlwaysFailure/>");
  EXPECT_EQ(problem(nul), "2: column 17: a control character (byte 0x00) is not allowed in XML");
  EXPECT_NE(problem(planXml("<AlwaysSuccess name=\"a\x07" "b\"/>")).find("byte 0x07"), std::string::npos);
  EXPECT_EQ(problem("<?xml version=\"1.0\"?>\n<!DOCTYPE root [<!ENTITY part \"node\">]>\n<root BTCPP_format=\"4\">"
                    "<BehaviorTree ID=\"m\"><AlwaysSuccess name=\"&part;\"/></BehaviorTree></root>"),
            "2: column 1: a <!DOCTYPE> is not allowed in a plan (its entities would not be expanded)");
  // Tabs, line feeds and carriage returns are text.
  EXPECT_TRUE(problems(planXml("\t<AlwaysSuccess/>\r\n")).empty());
}

// --- includes ---------------------------------------------------------------------------------

class IncludeTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("costar_include_test_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_ / "lib");
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  void write(const std::string& name, const std::string& text) { std::ofstream(dir_ / name) << text; }
  std::filesystem::path dir_;
};

TEST_F(IncludeTest, IncludedTreesAreUsableAndRelativeToTheIncludingFile) {
  write("main.xml", R"(<root BTCPP_format="4" main_tree_to_execute="main"><include path="lib/a.xml"/>
    <BehaviorTree ID="main"><SubTree ID="a"/></BehaviorTree></root>)");
  write(
      "lib/a.xml",
      R"(<root BTCPP_format="4"><include path="b.xml"/><BehaviorTree ID="a"><SubTree ID="b"/></BehaviorTree></root>)");
  write("lib/b.xml", R"(<root BTCPP_format="4"><BehaviorTree ID="b"><AlwaysSuccess/></BehaviorTree></root>)");
  const Plan plan = loadPlan(dir_ / "main.xml");
  EXPECT_EQ(plan.included.size(), 2u);
  SimClock clock;
  Tree tree = buildTree(plan, builtinRegistry(), clock);
  EXPECT_EQ(tree.tick(), Status::kSuccess);
}

TEST_F(IncludeTest, ACycleOfIncludesIsAnErrorNamingTheCycle) {
  write("main.xml",
        "<root BTCPP_format=\"4\">\n<include path=\"lib/a.xml\"/><BehaviorTree "
        "ID=\"m\"><AlwaysSuccess/></BehaviorTree></root>");
  write("lib/a.xml", "<root BTCPP_format=\"4\">\n\n<include path=\"../main.xml\"/></root>");
  try {
    loadPlan(dir_ / "main.xml");
    FAIL() << "expected a PlanError";
  } catch (const PlanError& error) {
    ASSERT_EQ(error.diagnostics().size(), 1u);
    EXPECT_EQ(error.diagnostics()[0].where.line, 3);
    EXPECT_NE(error.diagnostics()[0].message.find("cycle of includes"), std::string::npos);
    EXPECT_NE(error.diagnostics()[0].where.file.find("a.xml"), std::string::npos);
  }
}

TEST_F(IncludeTest, AChainOf20000IncludesLoadsWithoutExhaustingTheStack) {
  // Each file includes the next: the loader once recursed per level and overflowed near 20,000.
  constexpr int kFiles = 20000;
  for (int i = 0; i < kFiles; ++i) {
    const std::string next = i + 1 < kFiles ? "<include path=\"f" + std::to_string(i + 1) + ".xml\"/>" : "";
    write("f" + std::to_string(i) + ".xml", "<root BTCPP_format=\"4\">" + next + "<BehaviorTree ID=\"t" +
                                                std::to_string(i) + "\"><AlwaysSuccess/></BehaviorTree></root>");
  }
  const Plan plan = loadPlan(dir_ / "f0.xml");
  ASSERT_EQ(plan.included.size(), static_cast<std::size_t>(kFiles - 1));
  EXPECT_EQ(plan.included.front().trees.front().id, "t" + std::to_string(kFiles - 1));  // deepest first
  EXPECT_NE(plan.findTree("t12345"), nullptr);
  // A cycle at the end of the chain is still found, and named.
  write("f" + std::to_string(kFiles - 1) + ".xml",
        "<root BTCPP_format=\"4\"><include path=\"f0.xml\"/><BehaviorTree ID=\"last\"><AlwaysSuccess/>"
        "</BehaviorTree></root>");
  try {
    loadPlan(dir_ / "f0.xml");
    FAIL() << "expected a PlanError";
  } catch (const PlanError& error) {
    ASSERT_EQ(error.diagnostics().size(), 1u);
    EXPECT_NE(error.diagnostics()[0].where.file.find("f19999.xml"), std::string::npos);
    EXPECT_NE(error.diagnostics()[0].message.find("cycle of includes"), std::string::npos);
  }
}

TEST_F(IncludeTest, AMissingIncludeNamesTheIncludingLine) {
  write("main.xml",
        "<root BTCPP_format=\"4\">\n<include path=\"nope.xml\"/><BehaviorTree "
        "ID=\"m\"><AlwaysSuccess/></BehaviorTree></root>");
  try {
    loadPlan(dir_ / "main.xml");
    FAIL() << "expected a PlanError";
  } catch (const PlanError& error) {
    EXPECT_EQ(error.diagnostics()[0].where.line, 2);
    EXPECT_NE(error.diagnostics()[0].message.find("nope.xml"), std::string::npos);
  }
}

TEST_F(IncludeTest, SavingIsAtomicAndReadable) {
  const PlanFile file = parsePlanFile(planXml("<AlwaysSuccess/>"), "x");
  savePlanFile(file, dir_ / "saved.xml");
  EXPECT_TRUE(sameContent(loadPlan(dir_ / "saved.xml").file, file));
  for (const auto& entry : std::filesystem::directory_iterator(dir_)) {
    EXPECT_EQ(entry.path().string().find(".tmp"), std::string::npos);
  }
}

}  // namespace
}  // namespace costar::bt
