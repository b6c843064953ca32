#pragma once
// A run's beginning and end, apart from the thread that executes it: a request (a plan, or one
// operation from the menu) checked against the cell, its tree built on the cell's node types and
// clock and its state as the browser will see it; the executor's result written into that
// state; both as the run log's records. Engine thread (it reads the cell).

#include <functional>
#include <memory>
#include <variant>
#include <vector>

#include "bt/executor.h"
#include "bt/tree.h"
#include "server/backend.h"
#include "server/run_state.h"
#include "server/store.h"

namespace costar::workcell {
class Workcell;
}

namespace costar::server {

/// A run ready to execute.
struct PreparedRun {
  bt::Tree tree;
  /// Its id is 0: the Engine numbers it when it starts.
  std::shared_ptr<RunState> run;
};

/// Every problem of a plan for the cell (the plan's own and what it names that the cell does
/// not know now).
using PlanProblems = std::function<std::vector<bt::Diagnostic>(const bt::Plan&)>;

/// `request` ready to run in `cell`, or why not (status 422): a plan whose main tree cannot be
/// found, an operation that is not one action or condition, the plan's `problems`, or a tree
/// that cannot be built (the error's diagnostics or message).
std::variant<PreparedRun, StartResult> prepareRun(const RunRequest& request, workcell::Workcell& cell,
                                                  const PlanProblems& problems);

/// Writes the executor's `result`, the run's times and its end (now) into `run`, which is no
/// longer active.
void endRun(RunState& run, const bt::RunResult& result, double cpu_seconds, double wall_seconds);

/// The run log's record of a plan run (the store reads its id, plan, version, XML, start and
/// cell when it begins, its result, end, clock time, failure and transitions when it has ended).
RunRecord runRecord(const RunState& run);

}  // namespace costar::server
