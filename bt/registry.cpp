#include "bt/registry.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <set>
#include <stdexcept>

#include "bt/control_nodes.h"
#include "bt/decorator_nodes.h"
#include "bt/leaf_nodes.h"

namespace costar::bt {

const char* toString(NodeKind kind) {
  switch (kind) {
    case NodeKind::kControl:
      return "Control";
    case NodeKind::kDecorator:
      return "Decorator";
    case NodeKind::kAction:
      return "Action";
    case NodeKind::kCondition:
      return "Condition";
    case NodeKind::kSubTree:
      return "SubTree";
  }
  return "?";
}

const char* toString(NodeCategory category) {
  switch (category) {
    case NodeCategory::kInternal:
      return "internal";
    case NodeCategory::kRobotAction:
      return "robot_action";
    case NodeCategory::kKnowledge:
      return "knowledge";
  }
  return "?";
}

// --- value parsing ---------------------------------------------------------------------

namespace {

std::string_view trim(std::string_view text) {
  const auto first = text.find_first_not_of(" \t\r\n");
  if (first == std::string_view::npos) {
    return {};
  }
  const auto last = text.find_last_not_of(" \t\r\n");
  return text.substr(first, last - first + 1);
}

}  // namespace

std::optional<long long> parseInteger(std::string_view text) {
  text = trim(text);
  if (!text.empty() && text.front() == '+') {
    text.remove_prefix(1);
  }
  long long value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (text.empty() || error != std::errc() || end != text.data() + text.size()) {
    return std::nullopt;
  }
  return value;
}

std::optional<double> parseNumber(std::string_view text) {
  text = trim(text);
  if (!text.empty() && text.front() == '+') {
    text.remove_prefix(1);
  }
  double value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (text.empty() || error != std::errc() || end != text.data() + text.size() || !std::isfinite(value)) {
    return std::nullopt;
  }
  return value;
}

std::optional<bool> parseBoolean(std::string_view text) {
  text = trim(text);
  std::string lower(text);
  std::transform(lower.begin(), lower.end(), lower.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (lower == "true" || lower == "1") {
    return true;
  }
  if (lower == "false" || lower == "0") {
    return false;
  }
  return std::nullopt;
}

// --- PortSpec factories ---------------------------------------------------------------------

PortSpec PortSpec::text(std::string name, std::string description, std::optional<std::string> default_value) {
  PortSpec port;
  port.name = std::move(name);
  port.description = std::move(description);
  port.default_value = std::move(default_value);
  port.check = [](std::string_view) { return std::string(); };
  return port;
}

PortSpec PortSpec::integer(std::string name, std::string description, std::optional<std::string> default_value,
                           long long min, long long max, std::optional<long long> special) {
  PortSpec port;
  port.name = std::move(name);
  port.type_name = "int";
  port.description = std::move(description);
  port.default_value = std::move(default_value);
  port.check = [min, max, special](std::string_view text) -> std::string {
    const auto value = parseInteger(text);
    if (!value) {
      return "'" + std::string(text) + "' is not an integer";
    }
    if ((special && *value == *special) || (*value >= min && *value <= max)) {
      return {};
    }
    std::string allowed = "an integer from " + std::to_string(min) + " to " + std::to_string(max);
    if (special) {
      allowed += ", or " + std::to_string(*special);
    }
    return std::to_string(*value) + " is out of range: expected " + allowed;
  };
  return port;
}

PortSpec PortSpec::number(std::string name, std::string description, std::optional<std::string> default_value,
                          double min, double max) {
  PortSpec port;
  port.name = std::move(name);
  port.type_name = "double";
  port.description = std::move(description);
  port.default_value = std::move(default_value);
  port.check = [min, max](std::string_view text) -> std::string {
    const auto value = parseNumber(text);
    if (!value) {
      return "'" + std::string(text) + "' is not a number";
    }
    if (*value < min || *value > max) {
      return std::string(text) + " is out of range [" + std::to_string(min) + ", " + std::to_string(max) + "]";
    }
    return {};
  };
  return port;
}

PortSpec PortSpec::boolean(std::string name, std::string description, std::optional<std::string> default_value) {
  PortSpec port;
  port.name = std::move(name);
  port.type_name = "bool";
  port.description = std::move(description);
  port.default_value = std::move(default_value);
  port.choices = {"true", "false"};
  port.check = [](std::string_view text) -> std::string {
    return parseBoolean(text) ? std::string() : "'" + std::string(text) + "' is not true or false";
  };
  return port;
}

PortSpec PortSpec::choice(std::string name, std::string description, std::vector<std::string> choices,
                          std::optional<std::string> default_value) {
  PortSpec port;
  port.name = std::move(name);
  port.description = std::move(description);
  port.default_value = std::move(default_value);
  port.choices = choices;
  port.check = [choices](std::string_view text) -> std::string {
    if (std::find(choices.begin(), choices.end(), text) != choices.end()) {
      return {};
    }
    std::string allowed;
    for (const auto& choice : choices) {
      allowed += (allowed.empty() ? "" : ", ") + choice;
    }
    return "'" + std::string(text) + "' is not one of: " + allowed;
  };
  return port;
}

// --- NodeArgs / NodeSpec ---------------------------------------------------------------------

NodeArgs::NodeArgs(const NodeSpec& spec, const std::vector<std::pair<std::string, std::string>>& attributes)
    : spec_(&spec) {
  for (const auto& port : spec.ports) {
    if (port.default_value) {
      values_[port.name] = *port.default_value;
    }
  }
  for (const auto& [key, value] : attributes) {
    if (key == "name") {
      name_ = value;
    } else {
      values_[key] = value;
    }
  }
}

const std::string& NodeArgs::get(std::string_view port) const {
  const auto it = values_.find(port);
  if (it == values_.end()) {
    throw std::out_of_range("node " + spec_->id + " has no value for port '" + std::string(port) + "'");
  }
  return it->second;
}

long long NodeArgs::getInt(std::string_view port) const {
  const auto value = parseInteger(get(port));
  if (!value) {
    throw std::invalid_argument("port '" + std::string(port) + "' is not an integer");
  }
  return *value;
}

double NodeArgs::getDouble(std::string_view port) const {
  const auto value = parseNumber(get(port));
  if (!value) {
    throw std::invalid_argument("port '" + std::string(port) + "' is not a number");
  }
  return *value;
}

bool NodeArgs::getBool(std::string_view port) const {
  const auto value = parseBoolean(get(port));
  if (!value) {
    throw std::invalid_argument("port '" + std::string(port) + "' is not a boolean");
  }
  return *value;
}

const PortSpec* NodeSpec::port(std::string_view name) const {
  for (const auto& port : ports) {
    if (port.name == name) {
      return &port;
    }
  }
  return nullptr;
}

// --- NodeRegistry -----------------------------------------------------------------------------

void NodeRegistry::add(NodeSpec spec) {
  if (spec.id.empty()) {
    throw std::invalid_argument("node type without an ID");
  }
  if (specs_.contains(spec.id)) {
    throw std::invalid_argument("node type '" + spec.id + "' is registered twice");
  }
  std::string id = spec.id;
  specs_.emplace(std::move(id), std::move(spec));
}

const NodeSpec* NodeRegistry::find(std::string_view id) const {
  const auto it = specs_.find(id);
  return it == specs_.end() ? nullptr : &it->second;
}

std::vector<const NodeSpec*> NodeRegistry::all() const {
  std::vector<const NodeSpec*> result;
  result.reserve(specs_.size());
  for (const auto& [id, spec] : specs_) {
    result.push_back(&spec);
  }
  return result;
}

namespace {

std::size_t editDistance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) {
    row[j] = j;
  }
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t above = row[j];
      const bool same =
          std::tolower(static_cast<unsigned char>(a[i - 1])) == std::tolower(static_cast<unsigned char>(b[j - 1]));
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (same ? 0 : 1)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

}  // namespace

std::optional<std::string> NodeRegistry::suggest(std::string_view id) const {
  std::optional<std::string> best;
  std::size_t best_distance = std::max<std::size_t>(2, id.size() / 3) + 1;
  for (const auto& [candidate, spec] : specs_) {
    // The distance is at least the difference in length: a name of a megabyte costs nothing.
    const std::size_t shorter = std::min(id.size(), candidate.size());
    if (std::max(id.size(), candidate.size()) - shorter >= best_distance) {
      continue;
    }
    const std::size_t distance = editDistance(id, candidate);
    if (distance < best_distance) {
      best_distance = distance;
      best = candidate;
    }
  }
  return best;
}

// --- built-in nodes ---------------------------------------------------------------------------

namespace {

template <typename T>
NodeBuilder plain() {
  return [](const NodeArgs& args) { return std::make_unique<T>(args.spec().id, args.name()); };
}

NodeSpec control(std::string id, std::string description, NodeBuilder build) {
  NodeSpec spec;
  spec.id = std::move(id);
  spec.kind = NodeKind::kControl;
  spec.description = std::move(description);
  spec.build = std::move(build);
  return spec;
}

NodeSpec decorator(std::string id, std::string description, NodeBuilder build, std::vector<PortSpec> ports = {}) {
  NodeSpec spec = control(std::move(id), std::move(description), std::move(build));
  spec.kind = NodeKind::kDecorator;
  spec.ports = std::move(ports);
  return spec;
}

NodeSpec asynchronous(NodeSpec spec) {
  spec.asynchronous = true;  // a loop returns RUNNING between runs
  return spec;
}

constexpr long long kMaxCount = 1'000'000'000;

int toInt(long long value) { return static_cast<int>(value); }

}  // namespace

void registerBuiltinNodes(NodeRegistry& registry) {
  // Nodes that BehaviorTree.CPP v4 has under the same ID and semantics.
  static const std::set<std::string, std::less<>> kBehaviorTreeCpp = {"Sequence",
                                                                      "SequenceWithMemory",
                                                                      "ReactiveSequence",
                                                                      "Fallback",
                                                                      "ReactiveFallback",
                                                                      "Parallel",
                                                                      "AsyncSequence",
                                                                      "AsyncFallback",
                                                                      "ParallelAll",
                                                                      "IfThenElse",
                                                                      "WhileDoElse",
                                                                      "TryCatch",
                                                                      "Inverter",
                                                                      "ForceSuccess",
                                                                      "ForceFailure",
                                                                      "Repeat",
                                                                      "Timeout",
                                                                      "RetryUntilSuccessful",
                                                                      "Delay",
                                                                      "RunOnce",
                                                                      "KeepRunningUntilFailure",
                                                                      "SubTree",
                                                                      "AlwaysSuccess",
                                                                      "AlwaysFailure",
                                                                      "Sleep"};
  const auto add = [&registry](NodeSpec spec) {
    spec.btcpp_builtin = kBehaviorTreeCpp.contains(spec.id);
    registry.add(std::move(spec));
  };

  add(control("Sequence",
              "Ticks children in order while they succeed; resumes at the RUNNING child; "
              "a FAILURE fails the sequence and restarts it next time.",
              plain<Sequence>()));
  add(control("SequenceWithMemory",
              "Sequence that keeps its place across a FAILURE or a halt: the next tick "
              "retries the same child. Reset clears it.",
              plain<SequenceWithMemory>()));
  add(control("ReactiveSequence",
              "Re-ticks all children from the first on every tick; a child that fails "
              "halts the running one. Only the last child may be asynchronous.",
              plain<ReactiveSequence>()));
  add(control("Fallback",
              "The paper's Selector (?): ticks children in order until one succeeds; "
              "resumes at the RUNNING child.",
              plain<Fallback>()));
  add(control("ReactiveFallback",
              "Fallback that re-ticks from the first child on every tick, so a "
              "higher-priority child preempts a lower one. Only the last child may be "
              "asynchronous.",
              plain<ReactiveFallback>()));
  {
    NodeSpec spec =
        control("Parallel",
                "Ticks all children together; SUCCESS when success_count succeeded, FAILURE when "
                "failure_count failed. Negative counts are relative to the number of children (-1 = all).",
                [](const NodeArgs& args) {
                  return std::make_unique<Parallel>(args.spec().id, args.name(), toInt(args.getInt("success_count")),
                                                    toInt(args.getInt("failure_count")));
                });
    spec.ports = {
        PortSpec::integer("success_count", "children that must succeed (-1 = all)", "-1", -kMaxCount, kMaxCount),
        PortSpec::integer("failure_count", "children whose failure fails the node", "1", -kMaxCount, kMaxCount)};
    spec.check_instance = [](const NodeArgs& args, std::size_t child_count) -> std::string {
      const long long n = static_cast<long long>(child_count);
      for (const char* port : {"success_count", "failure_count"}) {
        const long long count = args.getInt(port);
        const long long resolved = count < 0 ? n + count + 1 : count;
        if (resolved < 1 || resolved > n) {
          return std::string(port) + "=" + std::to_string(count) + " does not fit " + std::to_string(n) +
                 " children: it must name between 1 and " + std::to_string(n) +
                 " of them (negative counts from the end: -1 = all)";
        }
      }
      return {};
    };
    add(std::move(spec));
  }
  add(asynchronous(control("AsyncSequence",
                           "Sequence that gives the tick back after each child that completed at once (RUNNING, "
                           "then resumes immediately), so a long chain stays interruptible.",
                           plain<AsyncSequence>())));
  add(asynchronous(control("AsyncFallback",
                           "Fallback that gives the tick back after each child that failed at once (RUNNING, then "
                           "resumes immediately).",
                           plain<AsyncFallback>())));
  {
    NodeSpec spec =
        control("ParallelAll",
                "Ticks all children together until every one has completed (none is halted early); "
                "FAILURE if at least max_failures failed, else SUCCESS.",
                [](const NodeArgs& args) {
                  return std::make_unique<ParallelAll>(args.spec().id, args.name(), toInt(args.getInt("max_failures")));
                });
    spec.ports = {PortSpec::integer("max_failures",
                                    "failed children that make it fail (negative: from the end, -1 = all)", "1",
                                    -kMaxCount, kMaxCount)};
    spec.check_instance = [](const NodeArgs& args, std::size_t child_count) -> std::string {
      const long long n = static_cast<long long>(child_count);
      const long long count = args.getInt("max_failures");
      const long long resolved = count < 0 ? std::max(n + count + 1, 0LL) : count;
      if (resolved > n) {
        return "max_failures=" + std::to_string(count) + " is more than its " + std::to_string(n) +
               " children: it could never fail";
      }
      return {};
    };
    add(std::move(spec));
  }
  const auto two_or_three = [](const NodeArgs&, std::size_t child_count) -> std::string {
    if (child_count == 2 || child_count == 3) {
      return {};
    }
    return "needs 2 or 3 children (the condition, then-branch, optional else-branch), has " +
           std::to_string(child_count);
  };
  {
    NodeSpec spec = control("IfThenElse",
                            "2 or 3 children: runs the first (the condition) to completion; SUCCESS runs the second, "
                            "FAILURE the third (or fails without one). Returns the branch's result.",
                            plain<IfThenElse>());
    spec.check_instance = two_or_three;
    add(std::move(spec));
  }
  {
    NodeSpec spec = control("WhileDoElse",
                            "2 or 3 children: re-checks the first (the condition) on every tick; while it succeeds "
                            "runs the second, else the third (halting the other). Returns the branch's result.",
                            plain<WhileDoElse>());
    spec.check_instance = two_or_three;
    add(std::move(spec));
  }
  {
    NodeSpec spec =
        control("TryCatch",
                "Runs children 1..n-1 as a Sequence (try); if one fails, runs the last child (catch, e.g. "
                "open the gripper and retreat) and returns FAILURE whatever it returned.",
                [](const NodeArgs& args) {
                  return std::make_unique<TryCatch>(args.spec().id, args.name(), args.getBool("catch_on_halt"));
                });
    spec.ports = {
        PortSpec::boolean("catch_on_halt", "also tick the catch child once when halted during the try block", "false")};
    spec.check_instance = [](const NodeArgs&, std::size_t child_count) -> std::string {
      return child_count >= 2 ? std::string()
                              : "needs at least 2 children (the try block, then the catch child), has " +
                                    std::to_string(child_count);
    };
    add(std::move(spec));
  }
  add(control("Iterator",
              "CoSTAR's Iterator: runs each child once, in order, ignoring failures; "
              "SUCCESS after the last.",
              plain<Iterator>()));

  add(decorator("Inverter", "SUCCESS becomes FAILURE and FAILURE becomes SUCCESS.", plain<Inverter>()));
  add(decorator("ForceSuccess", "Returns SUCCESS once the child completes.", plain<ForceSuccess>()));
  add(decorator("ForceFailure", "Returns FAILURE once the child completes.", plain<ForceFailure>()));
  add(asynchronous(decorator("Repeat",
                             "Re-runs the child until num_cycles successful runs (SUCCESS); a FAILURE stops the loop "
                             "(FAILURE). -1 = forever.",
                             [](const NodeArgs& args) {
                               return std::make_unique<Repeat>(args.spec().id, args.name(),
                                                               toInt(args.getInt("num_cycles")));
                             },
                             {PortSpec::integer("num_cycles", "successful runs to complete (-1 = forever)",
                                                std::nullopt, 1, kMaxCount, -1)})));
  add(asynchronous(decorator("RepeatRuns",
                             "The paper's REPEAT N: runs the child num_runs times whatever each run returns, then "
                             "SUCCESS. -1 = forever.",
                             [](const NodeArgs& args) {
                               return std::make_unique<RepeatRuns>(args.spec().id, args.name(),
                                                                   toInt(args.getInt("num_runs")));
                             },
                             {PortSpec::integer("num_runs", "runs to complete, successful or not (-1 = forever)",
                                                std::nullopt, 1, kMaxCount, -1)})));
  add(decorator("Reset",
                "CoSTAR's RESET N: returns the child's value; on FAILURE resets the child (clearing its "
                "memory) up to num_resets times, then passes FAILURE on. -1 = always.",
                [](const NodeArgs& args) {
                  return std::make_unique<Reset>(args.spec().id, args.name(), toInt(args.getInt("num_resets")));
                },
                {PortSpec::integer("num_resets", "resets allowed (-1 = unlimited)", std::nullopt, 0, kMaxCount, -1)}));
  add(decorator("Timeout", "Halts the child and fails if it has not completed msec after it started.",
                [](const NodeArgs& args) {
                  return std::make_unique<Timeout>(args.spec().id, args.name(),
                                                   std::chrono::milliseconds(args.getInt("msec")));
                },
                {PortSpec::integer("msec", "time limit in milliseconds", std::nullopt, 0, kMaxCount)}));
  add(asynchronous(decorator(
      "RetryUntilSuccessful", "Re-runs a failing child, up to num_attempts runs in all (-1 = until it succeeds).",
      [](const NodeArgs& args) {
        return std::make_unique<RetryUntilSuccessful>(args.spec().id, args.name(), toInt(args.getInt("num_attempts")));
      },
      {PortSpec::integer("num_attempts", "runs allowed in all (-1 = unlimited)", std::nullopt, 1, kMaxCount, -1)})));
  add(asynchronous(decorator("KeepRunningUntilFailure",
                             "Re-runs the child while it succeeds (RUNNING in between, one run per tick at most); "
                             "FAILURE when it fails. Never succeeds.",
                             plain<KeepRunningUntilFailure>())));
  add(asynchronous(decorator("Delay",
                             "Waits delay_msec milliseconds of clock time, then ticks the child and returns its "
                             "result.",
                             [](const NodeArgs& args) {
                               return std::make_unique<Delay>(args.spec().id, args.name(),
                                                              std::chrono::milliseconds(args.getInt("delay_msec")));
                             },
                             {PortSpec::integer("delay_msec", "wait before ticking the child, in milliseconds",
                                                std::nullopt, 0, kMaxCount)})));
  add(decorator(
      "RunOnce",
      "Runs the child once; afterwards it is skipped (then_skip=true) or returns that first result "
      "again without ticking the child (then_skip=false).",
      [](const NodeArgs& args) {
        return std::make_unique<RunOnce>(args.spec().id, args.name(), args.getBool("then_skip"));
      },
      {PortSpec::boolean("then_skip", "after the first run: skipped (true) or same result (false)", "true")}));
  {
    NodeSpec spec;
    spec.id = "SubTree";
    spec.kind = NodeKind::kSubTree;
    spec.description = "Runs another BehaviorTree of the plan (saved subtrees are reused this way).";
    spec.ports = {PortSpec::text("ID", "ID of the BehaviorTree to run")};
    add(std::move(spec));
  }

  {
    NodeSpec spec;
    spec.id = "AlwaysSuccess";
    spec.kind = NodeKind::kAction;
    spec.description = "Returns SUCCESS.";
    spec.build = plain<AlwaysSuccess>();
    add(std::move(spec));
  }
  {
    NodeSpec spec;
    spec.id = "AlwaysFailure";
    spec.kind = NodeKind::kAction;
    spec.description = "Returns FAILURE.";
    spec.build = plain<AlwaysFailure>();
    add(std::move(spec));
  }
  {
    NodeSpec spec;
    spec.id = "Sleep";
    spec.kind = NodeKind::kAction;
    spec.description = "RUNNING for msec milliseconds of clock time, then SUCCESS.";
    spec.category = NodeCategory::kRobotAction;
    spec.ports = {PortSpec::integer("msec", "how long to wait, in milliseconds", std::nullopt, 0, kMaxCount)};
    spec.asynchronous = true;
    spec.build = [](const NodeArgs& args) {
      return std::make_unique<Sleep>(args.spec().id, args.name(), std::chrono::milliseconds(args.getInt("msec")));
    };
    add(std::move(spec));
  }
}

NodeRegistry builtinRegistry() {
  NodeRegistry registry;
  registerBuiltinNodes(registry);
  return registry;
}

}  // namespace costar::bt
