#include "server/run_lifecycle.h"

#include "bt/builder.h"
#include "server/plan_json.h"
#include "workcell/workcell.h"

namespace costar::server {

namespace {

StartResult refused(std::vector<bt::Diagnostic> diagnostics) {
  StartResult out;
  out.status = 422;
  out.diagnostics = std::move(diagnostics);
  return out;
}

StartResult refused(std::string error) {
  StartResult out;
  out.status = 422;
  out.error = std::move(error);
  return out;
}

}  // namespace

std::variant<PreparedRun, StartResult> prepareRun(const RunRequest& request, workcell::Workcell& cell,
                                                  const PlanProblems& problems) {
  // The main tree; a single operation is one action or condition.
  const bt::PlanTree* main = nullptr;
  try {
    main = request.plan.findTree(request.plan.mainTreeId());
  } catch (const bt::PlanError& error) {
    return refused(error.diagnostics());
  }
  if (request.operation && main != nullptr) {
    const bt::NodeSpec* spec = cell.nodes().find(main->root.id);
    if (spec != nullptr && spec->kind != bt::NodeKind::kAction && spec->kind != bt::NodeKind::kCondition) {
      return refused("an operation is one action or condition, not a " + std::string(bt::toString(spec->kind)));
    }
  }
  // The plan checked against the cell, its tree built.
  std::optional<bt::Tree> tree;
  try {
    if (auto diagnostics = problems(request.plan); !diagnostics.empty()) {
      return refused(std::move(diagnostics));
    }
    tree.emplace(bt::buildTree(request.plan, cell.nodes(), cell.clock()));
  } catch (const bt::PlanError& error) {
    return refused(error.diagnostics());
  } catch (const std::exception& error) {
    return refused(std::string(error.what()));
  }
  // The run as the browser will see it: every node of the tree, idle.
  auto run = std::make_shared<RunState>();
  run->operation = request.operation;
  run->plan_name = request.plan_name;
  run->version = request.version;
  run->label = request.operation ? (main != nullptr ? main->root.id : "") : tree->mainTreeId();
  run->xml = request.xml;
  run->workcell = cell.name();
  if (!request.operation) {
    run->plan_json = planFileToJson(request.plan.file);
  }
  for (const bt::TreeNode* node : tree->nodes()) {
    run->nodes.push_back({node->uid(),
                          node->parent() != nullptr ? static_cast<std::int64_t>(node->parent()->uid()) : -1, node->id(),
                          node->name(), node->path()});
  }
  run->statuses.resize(run->nodes.size());
  run->start_time = cell.clock().now();
  run->started_at = unixNow();
  return PreparedRun{std::move(*tree), std::move(run)};
}

void endRun(RunState& run, const bt::RunResult& result, double cpu_seconds, double wall_seconds) {
  run.active = false;
  run.stopped = result.stopped;
  run.result = result.stopped ? "STOPPED" : bt::toString(result.status);
  run.failure_path = result.failure_path;
  run.failure_reason = result.failure_reason;
  run.clock_seconds = toSeconds(result.elapsed);
  run.cpu_seconds = cpu_seconds;
  run.wall_seconds = wall_seconds;
  run.ended_at = unixNow();
}

RunRecord runRecord(const RunState& run) {
  return {.id = run.id,
          .workcell = run.workcell,
          .plan = run.plan_name,
          .version = run.version,
          .xml = run.xml,
          .started_at = run.started_at,
          .result = run.result,
          .ended_at = run.ended_at,
          .clock_seconds = run.clock_seconds,
          .failure_path = run.failure_path,
          .failure_reason = run.failure_reason,
          .transitions = run.transitions,
          .truncated = run.truncated};
}

}  // namespace costar::server
