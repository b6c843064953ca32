// Conformance with BehaviorTree.CPP 4.10 on its own unit-test trees: every tree that its
// built-in nodes alone can run (bt/test/btcpp_trees/, copied from the peer's tests/*.cpp, MIT
// licence) must give BehaviorTree.CPP's verdict here, or, when it needs a blackboard, be refused
// with an error that says this is by design. MANIFEST.txt holds the verdicts the peer gave
// (measured with /work/shared/peers/btcpp-runner; the peer itself is not needed here).

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "bt/builder.h"
#include "bt/executor.h"
#include "bt/plan_xml.h"
#include "bt/registry.h"
#include "core/clock.h"
#include "core/paths.h"

namespace costar::bt {
namespace {

struct Expectation {
  std::string file;
  std::string expected;  // SUCCESS, FAILURE or REFUSED
  std::string peer;      // what BehaviorTree.CPP returned
};

std::filesystem::path treesDir() { return dataRoot() / "bt" / "test" / "btcpp_trees"; }

std::vector<Expectation> readManifest() {
  std::ifstream in(treesDir() / "MANIFEST.txt");
  std::vector<Expectation> entries;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line.front() == '#') {
      continue;
    }
    std::istringstream fields(line);
    Expectation entry;
    fields >> entry.file >> entry.expected >> entry.peer;
    entries.push_back(entry);
  }
  return entries;
}

/// "SUCCESS", "FAILURE", or "REFUSED: <message>".
std::string verdict(const std::filesystem::path& file) {
  const NodeRegistry registry = builtinRegistry();
  SimClock clock;
  try {
    Tree tree = buildTree(loadPlan(file), registry, clock);
    ExecutorOptions options;
    options.time_limit = std::chrono::seconds(60);  // clock time: the trees wait at most 1 s
    Executor executor(tree, clock, options);
    return toString(executor.run().status);
  } catch (const PlanError& error) {
    return std::string("REFUSED: ") + error.what();
  }
}

TEST(BehaviorTreeCppConformance, ManifestListsEveryComparableTree) {
  const auto entries = readManifest();
  ASSERT_EQ(entries.size(), 65u) << "manifest not found or incomplete in " << treesDir();
  int refused = 0;
  for (const auto& entry : entries) {
    EXPECT_TRUE(std::filesystem::is_regular_file(treesDir() / entry.file)) << entry.file;
    EXPECT_TRUE(entry.peer == "SUCCESS" || entry.peer == "FAILURE") << entry.file;
    refused += entry.expected == "REFUSED" ? 1 : 0;
  }
  EXPECT_EQ(refused, 16);  // the trees that need a blackboard
}

TEST(BehaviorTreeCppConformance, EveryBlackboardFreeTreeGivesThePeersVerdict) {
  int agreed = 0;
  for (const auto& entry : readManifest()) {
    if (entry.expected == "REFUSED") {
      continue;
    }
    const std::string result = verdict(treesDir() / entry.file);
    EXPECT_EQ(result, entry.expected) << entry.file;
    agreed += result == entry.peer ? 1 : 0;
  }
  EXPECT_EQ(agreed, 49);
}

TEST(BehaviorTreeCppConformance, TreesThatNeedABlackboardAreRefusedSayingWhy) {
  for (const auto& entry : readManifest()) {
    if (entry.expected != "REFUSED") {
      continue;
    }
    const std::string result = verdict(treesDir() / entry.file);
    EXPECT_TRUE(result.starts_with("REFUSED: ")) << entry.file << ": " << result;
    EXPECT_NE(result.find("by design"), std::string::npos) << entry.file << ": " << result;
    EXPECT_NE(result.find("instead"), std::string::npos) << entry.file << ": " << result;
  }
}

}  // namespace
}  // namespace costar::bt
