// Every plan in examples/ and bench/plans/ is valid for its workcell and survives
// load -> save -> load without loss.

#include <gtest/gtest.h>

#include <filesystem>

#include "bt/builder.h"
#include "bt/plan_xml.h"
#include "workcell/workcell.h"

namespace costar {
namespace {

std::vector<std::filesystem::path> planFiles() {
  std::vector<std::filesystem::path> files;
  for (const char* root : {"examples", "bench/plans"}) {
    for (const auto& entry : std::filesystem::recursive_directory_iterator(root)) {
      if (entry.path().extension() == ".xml") {
        files.push_back(entry.path());
      }
    }
  }
  std::sort(files.begin(), files.end());
  return files;
}

/// The workcell a plan is written for: by folder; in iiwa/, the 3-finger cell's unless the
/// name ends in _2f (the 2-finger gripper's cell).
std::string workcellFor(const std::filesystem::path& file) {
  const std::string folder = file.parent_path().filename().string();
  if (folder == "test_workcell") {
    return "test";
  }
  if (folder == "iiwa") {
    return file.stem().string().ends_with("_2f") ? "iiwa-sim" : "iiwa-3f-sim";
  }
  return folder == "ur5" ? "ur5-sim" : "none";
}

TEST(Examples, ThereAreExamplesToCheck) { EXPECT_GE(planFiles().size(), 4u); }

TEST(Examples, EveryPlanIsValidForItsWorkcell) {
  for (const auto& file : planFiles()) {
    if (file.parent_path().filename() == "subtrees") {
      continue;  // a library of subtrees, without a main tree of its own
    }
    const auto cell = workcell::makeWorkcell({.name = workcellFor(file), .memory_only = true});
    const bt::Plan plan = bt::loadPlan(file);
    const auto diagnostics = bt::validatePlan(plan, cell->nodes());
    EXPECT_TRUE(diagnostics.empty()) << file << ": " << (diagnostics.empty() ? "" : diagnostics[0].str());
  }
}

TEST(Examples, EveryPlanSurvivesLoadSaveLoad) {
  for (const auto& file : planFiles()) {
    const bt::Plan first = bt::loadPlan(file);
    const std::string saved = bt::writePlanFile(first.file);
    const bt::PlanFile second = bt::parsePlanFile(saved, file.string());
    EXPECT_TRUE(bt::sameContent(first.file, second)) << file;
    EXPECT_EQ(bt::writePlanFile(second), saved) << file;
  }
}

}  // namespace
}  // namespace costar
