#include "cli/plan_commands.h"

#include <algorithm>

#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <nlohmann/json.hpp>
#include <set>

#include "bt/builder.h"
#include "bt/executor.h"
#include "bt/nodes_model.h"
#include "bt/plan_xml.h"
#include "bt/trace.h"
#include "cli/inject_option.h"
#include "cli/number_options.h"
#include "cli/output_options.h"
#include "cli/stop_signals.h"
#include "cli/workcell_access.h"
#include "core/files.h"
#include "workcell/workcell.h"

namespace costar::cli {

namespace {

constexpr int kExitSuccess = 0;
constexpr int kExitFailure = 1;
constexpr int kExitInvalid = 2;

struct Colors {
  explicit Colors(bool on)
      : green(on ? "\033[32m" : ""), red(on ? "\033[31m" : ""), dim(on ? "\033[2m" : ""), reset(on ? "\033[0m" : "") {}
  const char* green;
  const char* red;
  const char* dim;
  const char* reset;
};

/// Live status lines: one per start and end of every leaf (robot action, knowledge
/// operation, condition).
class ConsoleStatus final : public bt::TreeObserver {
 public:
  ConsoleStatus(const bt::Tree& tree, const bt::NodeRegistry& registry, bool all_nodes, Colors colors)
      : colors_(colors) {
    for (const bt::TreeNode* node : tree.nodes()) {
      const bt::NodeSpec* spec = registry.find(node->id());
      const bool leaf = node->children().empty() && node->id() != "SubTree";
      if (all_nodes || (leaf && spec != nullptr && spec->category != bt::NodeCategory::kInternal)) {
        shown_.insert(node->uid());
      }
    }
  }

  void onTransition(TimePoint time, const bt::TreeNode& node, bt::Status from, bt::Status to) override {
    if (to == bt::Status::kIdle || !shown_.contains(node.uid())) {
      return;
    }
    const char* color = to == bt::Status::kSuccess ? colors_.green : to == bt::Status::kFailure ? colors_.red : "";
    std::printf("%s[%9.3f s]%s %s%-7s%s %s", colors_.dim, toSeconds(time), colors_.reset, color, toString(to),
                colors_.reset, node.path().c_str());
    if (to == bt::Status::kFailure) {
      std::printf(": %s", std::string(node.failureReason()).c_str());
    }
    std::printf("\n");
    std::fflush(stdout);
  }

 private:
  Colors colors_;
  std::set<std::uint32_t> shown_;
};

void printDiagnostics(const bt::PlanError& error) {
  for (const auto& diagnostic : error.diagnostics()) {
    std::cerr << "error: " << diagnostic.str() << "\n";
  }
  std::cerr << error.diagnostics().size() << " problem(s); nothing was run.\n";
}

/// Options that choose and set up the workcell, shared by the plan commands.
void addWorkcellOptions(CLI::App* command, workcell::WorkcellOptions& options) {
  command->add_option("-w,--workcell", options.name, "workcell to run on: " + workcell::knownWorkcellNames())
      ->capture_default_str();
  command->add_option("--scene", options.scene, "simulated workcells: scene file (default sim/scenes/assembly.json)")
      ->check(CLI::ExistingFile);
  command->add_option("--seed", options.seed, "simulated workcells: seed of part placement and sensor noise")
      ->check(wholeNumber());
  command->add_option("--waypoints", options.waypoints,
                      "waypoint file (default " + workcell::defaultWaypointFile("<workcell>").string() + ")");
  command
      ->add_option("--remote", options.remote,
                   "JSON file naming the components served by `costar host` elsewhere, over DDS: {\"components\": "
                   "[...], \"domain\", \"partition\", \"interface\"} (test cell only)")
      ->check(CLI::ExistingFile);
}

std::unique_ptr<workcell::Workcell> openWorkcell(const workcell::WorkcellOptions& options, WorkcellUse use) {
  try {
    workcell::refuseSimulationOptionsOfLightCells(options);  // what the user gave applies
    return openWorkcellFor(options, use);
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return nullptr;
  }
}

struct RunOptions {
  std::string plan;
  workcell::WorkcellOptions workcell;
  std::string trace;
  double rate_hz = 100.0;
  double time_limit_s = 0.0;
  bool quiet = false;
  bool all_nodes = false;
  std::vector<std::string> inject;
};

int runPlan(RunOptions options) {
  // From the start: a signal while the cell is built stops the run at its first tick, with its
  // trace written, rather than killing the process.
  const StopSignals signals;
  bt::ExecutorOptions executor_options;
  try {
    executor_options.tick_period = checkedDuration(1.0 / options.rate_hz, "--rate: the tick period");
    if (options.time_limit_s > 0) {
      executor_options.time_limit = checkedDuration(options.time_limit_s, "--time-limit");
    }
  } catch (const std::invalid_argument& e) {
    std::cerr << "error: " << e.what() << "\n";
    return kExitInvalid;
  }
  try {
    // Before the cell is built: the trace must not replace the plan or the taught waypoints.
    const std::filesystem::path waypoints = options.workcell.waypoints.empty()
                                                ? workcell::defaultWaypointFile(options.workcell.name)
                                                : std::filesystem::path(options.workcell.waypoints);
    refuseWritingAnInput(options.trace, "--trace",
                         {{options.plan, "the plan"},
                          {waypoints, "the waypoint file"},
                          {options.workcell.scene, "the --scene file"},
                          {options.workcell.remote, "the --remote file"}});
  } catch (const std::invalid_argument& e) {
    std::cerr << "error: " << e.what() << "; nothing was run\n";
    return kExitInvalid;
  }
  if (!options.inject.empty()) {
    options.workcell.faults = makeFaultInjector(options.inject, options.workcell.seed.value_or(1));
  }
  const std::unique_ptr<workcell::Workcell> cell = openWorkcell(options.workcell, WorkcellUse::kRun);
  if (!cell) {
    return kExitInvalid;
  }
  std::optional<bt::Tree> tree;
  try {
    tree.emplace(bt::buildTree(bt::loadPlan(options.plan), cell->nodes(), cell->clock()));
  } catch (const bt::PlanError& error) {
    printDiagnostics(error);
    return kExitInvalid;
  }

  // The trace is written as the run goes: each tick's transitions at the next tick.
  std::optional<bt::JsonLinesFileTrace> trace;
  if (!options.trace.empty()) {
    try {
      trace.emplace(options.trace);
    } catch (const std::exception& e) {
      std::cerr << "error: " << e.what() << "\n";
      return kExitInvalid;
    }
    tree->addObserver(&*trace);
  }
  const Colors colors(::isatty(STDOUT_FILENO) != 0);
  std::optional<ConsoleStatus> console;
  if (!options.quiet) {
    console.emplace(*tree, cell->nodes(), options.all_nodes, colors);
    tree->addObserver(&*console);
    std::printf("costar: running %s (tree '%s', %zu nodes) at %.0f Hz on %s\n", options.plan.c_str(),
                tree->mainTreeId().c_str(), tree->nodes().size(), options.rate_hz, cell->description().c_str());
  }

  bt::Executor executor(*tree, cell->clock(), executor_options);
  bool trace_error_said = false;
  const auto flushTrace = [&trace, &trace_error_said] {
    if (trace) {
      trace->flush();
      if (!trace->error().empty() && !trace_error_said) {
        std::cerr << "error: " << trace->error() << "; the run goes on without its trace\n";
        trace_error_said = true;
      }
    }
  };
  executor.setBeforeTick([&cell, &executor, &flushTrace] {
    if (StopSignals::stopRequested().load()) {
      executor.requestStop();  // halts the tree at the next tick: running operations are cancelled
    }
    flushTrace();
    cell->beforeTick();
  });
  const auto wall_start = std::chrono::steady_clock::now();
  const bt::RunResult result = executor.run();
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  if (trace) {
    trace->close();
    flushTrace();  // says a failure of the last writes
  }
  const int signal = StopSignals::received();

  const char* clock_kind = cell->clock().simulated() ? "simulated" : "real";
  if (options.workcell.faults) {
    std::printf("%s", faultSummary(*options.workcell.faults).c_str());
  }
  const std::uint64_t node_ticks = tree->context().nodeTicks();
  // A trace that could not be written makes the exit code 2 whatever the run's result.
  const auto exitCode = [&trace](int code) { return trace && !trace->error().empty() ? kExitInvalid : code; };
  if (result.stopped) {
    std::printf("%sSTOPPED%s by %s after %.3f s %s; running operations were cancelled\n", colors.red, colors.reset,
                StopSignals::name(signal).c_str(), toSeconds(result.elapsed), clock_kind);
    return exitCode(StopSignals::exitCode(signal));
  }
  if (result.status == bt::Status::kSuccess) {
    std::printf("%sSUCCESS%s in %.3f s %s (%.3f s wall, %llu ticks, %llu node ticks)\n", colors.green, colors.reset,
                toSeconds(result.elapsed), clock_kind, wall, static_cast<unsigned long long>(result.ticks),
                static_cast<unsigned long long>(node_ticks));
    return exitCode(kExitSuccess);
  }
  std::printf("%sFAILURE%s at %s: %s\n  after %.3f s %s (%.3f s wall, %llu ticks)\n", colors.red, colors.reset,
              result.failure_path.c_str(), result.failure_reason.c_str(), toSeconds(result.elapsed), clock_kind, wall,
              static_cast<unsigned long long>(result.ticks));
  return exitCode(kExitFailure);
}

int validatePlan(const std::string& path, const workcell::WorkcellOptions& workcell_options) {
  try {
    const auto cell = openWorkcellFor(workcell_options, WorkcellUse::kDescribe);
    const bt::Plan plan = bt::loadPlan(path);
    const auto diagnostics = bt::validatePlan(plan, cell->nodes());
    if (!diagnostics.empty()) {
      printDiagnostics(bt::PlanError(diagnostics));
      return kExitInvalid;
    }
    SimClock clock;
    const bt::Tree tree = bt::buildTree(plan, cell->nodes(), clock);
    std::printf("%s: valid for workcell '%s' (main tree '%s', %zu nodes with subtrees expanded, %zu file(s))\n",
                path.c_str(), cell->name().c_str(), tree.mainTreeId().c_str(), tree.nodes().size(),
                1 + plan.included.size());
    return kExitSuccess;
  } catch (const bt::PlanError& error) {
    printDiagnostics(error);
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
  }
  return kExitInvalid;
}

nlohmann::json nodesJson(const bt::NodeRegistry& registry) {
  nlohmann::json nodes = nlohmann::json::array();
  for (const bt::NodeSpec* spec : registry.all()) {
    nlohmann::json ports = nlohmann::json::array();
    for (const auto& port : spec->ports) {
      nlohmann::json item = {{"name", port.name}, {"type", port.type_name}, {"description", port.description}};
      if (port.default_value) {
        item["default"] = *port.default_value;
      }
      if (!port.choices.empty()) {
        item["choices"] = port.choices;
      }
      ports.push_back(std::move(item));
    }
    nodes.push_back({{"id", spec->id},
                     {"kind", bt::toString(spec->kind)},
                     {"category", bt::toString(spec->category)},
                     {"description", spec->description},
                     {"asynchronous", spec->asynchronous},
                     {"ports", std::move(ports)}});
  }
  return nodes;
}

int writeNodes(const workcell::WorkcellOptions& workcell_options, const std::string& format, bool all,
               const std::string& out) {
  const std::unique_ptr<workcell::Workcell> cell = openWorkcell(workcell_options, WorkcellUse::kDescribe);
  if (!cell) {
    return kExitInvalid;
  }
  const std::string text = format == "json" ? nodesJson(cell->nodes()).dump(2) + "\n"
                                            : bt::treeNodesModelXml(cell->nodes(), {.include_btcpp_builtins = all});
  if (out.empty()) {
    std::cout << text << std::flush;
    if (!std::cout) {
      std::cerr << "error: cannot write the standard output: " << std::strerror(errno) << "\n";
      return kExitInvalid;
    }
    return kExitSuccess;
  }
  try {
    writeOutputFile(out, text);
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return kExitInvalid;
  }
  std::cerr << "wrote " << out << "\n";
  return kExitSuccess;
}

}  // namespace

void addPlanCommands(CLI::App& app, int& exit_code) {
  auto options = std::make_shared<RunOptions>();
  CLI::App* run = app.add_subcommand("run", "Run a task plan (BehaviorTree.CPP v4 XML) on a workcell");
  run->add_option("plan", options->plan, "plan file")->required()->check(CLI::ExistingFile);
  addWorkcellOptions(run, options->workcell);
  run->add_option("--trace", options->trace,
                  "write every status transition to FILE as JSON lines, as the run goes (each tick's at the next)")
      ->check(aFileName());
  run->add_option("--rate", options->rate_hz, "ticks per second of clock time")
      ->check(numberIn(0.1, 10000.0, false, " Hz"))
      ->capture_default_str();
  run->add_option("--time-limit", options->time_limit_s, "fail the run after this many clock seconds (0: none)")
      ->check(numberIn(0.0, kMaxDurationSeconds, false, " s"));
  run->add_flag("-q,--quiet", options->quiet, "print only the result");
  run->add_flag("--all-nodes", options->all_nodes, "status lines for internal nodes too");
  addInjectOption(run, options->inject);
  run->footer(
      "Exit code: 0 SUCCESS, 1 FAILURE (the failing node's path and reason are printed), 2 invalid plan or option,\n"
      "or the --trace could not be written; 130 stopped by Ctrl-C (SIGINT), 143 by SIGTERM (running operations\n"
      "are cancelled, the trace is complete).");
  run->callback([options, &exit_code] { exit_code = runPlan(*options); });

  auto validate_plan = std::make_shared<std::string>();
  auto validate_workcell = std::make_shared<workcell::WorkcellOptions>();
  CLI::App* validate = app.add_subcommand("validate", "Check a plan without running it");
  validate->add_option("plan", *validate_plan, "plan file")->required()->check(CLI::ExistingFile);
  addWorkcellOptions(validate, *validate_workcell);
  validate->footer("Exit code: 0 valid, 2 invalid (each problem is printed as file:line: message).");
  validate->callback([=, &exit_code] { exit_code = validatePlan(*validate_plan, *validate_workcell); });

  auto nodes_workcell = std::make_shared<workcell::WorkcellOptions>();
  auto nodes_format = std::make_shared<std::string>("xml");
  auto nodes_all = std::make_shared<bool>(false);
  auto nodes_out = std::make_shared<std::string>();
  CLI::App* nodes = app.add_subcommand("nodes", "Write the TreeNodesModel of every node type (for Groot2)");
  addWorkcellOptions(nodes, *nodes_workcell);
  nodes->add_option("--format", *nodes_format, "xml (TreeNodesModel) or json")
      ->check(CLI::IsMember({"xml", "json"}))
      ->capture_default_str();
  nodes->add_flag("--all", *nodes_all, "also describe nodes that BehaviorTree.CPP has built in");
  nodes->add_option("-o,--out", *nodes_out, "write to FILE instead of standard output")->check(aFileName());
  nodes->footer("Exit code: 0 written, 2 bad options or a file that could not be written.");
  nodes->callback([=, &exit_code] { exit_code = writeNodes(*nodes_workcell, *nodes_format, *nodes_all, *nodes_out); });

  CLI::App* workcells = app.add_subcommand("workcells", "List the workcells this build knows");
  workcells->callback([&exit_code] {
    const auto known = workcell::knownWorkcells();
    int width = 0;  // the names in one column, however long the longest
    for (const auto& info : known) {
      width = std::max(width, static_cast<int>(info.name.size()));
    }
    for (const auto& info : known) {
      std::printf("%-*s  %s\n", width, info.name.c_str(), info.description.c_str());
    }
    exit_code = kExitSuccess;
  });
}

}  // namespace costar::cli
