#include "server/api.h"

#include <array>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <map>

#include "arm/hand_guiding_limits.h"
#include "bt/plan_xml.h"
#include "server/auth.h"
#include "server/plan_json.h"

namespace costar::server {

HttpResponse errorResponse(int status, const std::string& message) {
  HttpResponse response;
  response.status = status;
  // Messages quote what requests held (names, actions, the bytes a JSON parser stopped at),
  // which may be cut inside a UTF-8 character: replaced with U+FFFD here, the one place
  // errors become answers, rather than thrown as json::type_error 316.
  response.body = nlohmann::json{{"error", message}}.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  if (status == 401) {
    response.headers.emplace_back("WWW-Authenticate", "Bearer");
  }
  return response;
}

namespace {

using nlohmann::json;

HttpResponse jsonResponse(const json& body, int status = 200) {
  HttpResponse response;
  response.status = status;
  // Replace invalid UTF-8 (e.g. from a failure reason) rather than throw.
  response.body = body.dump(-1, ' ', false, json::error_handler_t::replace);
  return response;
}

/// A request target split into path segments and query parameters.
struct Target {
  std::vector<std::string> segments;
  std::map<std::string, std::string> query;
};

Target parseTarget(const std::string& target) {
  Target out;
  const auto question = target.find('?');
  const std::string path = target.substr(0, question);
  std::size_t start = 0;
  while (start <= path.size()) {
    const auto slash = path.find('/', start);
    const std::string segment = path.substr(start, slash == std::string::npos ? std::string::npos : slash - start);
    if (!segment.empty()) {
      out.segments.push_back(segment);
    }
    if (slash == std::string::npos) {
      break;
    }
    start = slash + 1;
  }
  if (question != std::string::npos) {
    std::size_t begin = question + 1;
    while (begin < target.size()) {
      auto end = target.find('&', begin);
      if (end == std::string::npos) {
        end = target.size();
      }
      const std::string pair = target.substr(begin, end - begin);
      const auto equals = pair.find('=');
      out.query[pair.substr(0, equals)] = equals == std::string::npos ? "" : pair.substr(equals + 1);
      begin = end + 1;
    }
  }
  return out;
}

std::optional<long long> parseLong(const std::string& text) {
  long long value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size()) {
    return std::nullopt;
  }
  return value;
}

/// A count from the query (`name` = 1 to `most`), `fallback` when absent.
/// @throws RequestError 400 when it is not such a number.
std::size_t countParameter(const Target& target, const std::string& name, std::size_t fallback, std::size_t most) {
  const auto it = target.query.find(name);
  if (it == target.query.end()) {
    return fallback;
  }
  const auto value = parseLong(it->second);
  if (!value || *value < 1 || static_cast<unsigned long long>(*value) > most) {
    throw RequestError(400, name + " must be 1 to " + std::to_string(most));
  }
  return static_cast<std::size_t>(*value);
}

std::optional<int> versionParameter(const Target& target) {
  const auto it = target.query.find("version");
  if (it == target.query.end()) {
    return std::nullopt;
  }
  const auto value = parseLong(it->second);
  if (!value || *value < 1 || *value > 1'000'000'000) {
    throw RequestError(400, "version must be a positive integer");
  }
  return static_cast<int>(*value);
}

const std::string& checkedName(const std::string& name) {
  if (const std::string problem = checkName(name); !problem.empty()) {
    throw RequestError(400, "bad name: " + problem);
  }
  return name;
}

/// A plan from a request body: {"plan": <editor JSON>} or {"xml": "<root ...>"}.
struct ParsedPlan {
  bt::Plan plan;
  std::string xml;
};

ParsedPlan planFromBody(const json& body, const std::string& label) {
  if (!body.is_object()) {
    throw RequestError(400, "the body must be a JSON object with 'plan' or 'xml'");
  }
  ParsedPlan out;
  bt::PlanFile file;
  if (const auto it = body.find("xml"); it != body.end()) {
    if (!it->is_string()) {
      throw RequestError(400, "'xml' must be a string");
    }
    // Unreadable XML throws bt::PlanError: answered 422 with every problem.
    file = bt::loadPlanText(it->get_ref<const std::string&>(), label, {.follow_includes = false}).file;
  } else if (const auto plan = body.find("plan"); plan != body.end()) {
    file = planFileFromJson(*plan, label);
  } else {
    throw RequestError(400, "the body needs 'plan' (the editor's JSON) or 'xml' (a plan file)");
  }
  // Write and read back: the XML is what is stored and run, and its line numbers map
  // diagnostics to nodes.
  out.xml = bt::writePlanFile(file);
  out.plan = bt::loadPlanText(out.xml, label, {.follow_includes = false});
  return out;
}

/// How messages name a plan: by its saved name, not the file the server reads it from.
std::string planLabel(const std::string& name) { return name.empty() ? "this plan" : "plan '" + name + "'"; }

HttpResponse invalidPlan(const std::vector<bt::Diagnostic>& diagnostics, const bt::PlanFile& file,
                         const std::string& name = {}) {
  const std::string first = diagnostics.empty() ? "it cannot be read" : diagnostics.front().message;
  const std::string count = diagnostics.size() == 1 ? "1 problem" : std::to_string(diagnostics.size()) + " problems";
  json body = {{"error", planLabel(name) + " has " + count + ": " + first},
               {"diagnostics", diagnosticsToJson(diagnostics, file)}};
  return jsonResponse(body, 422);
}

/// Starts a run: 202 with its id, 422 with the plan's problems, or the backend's refusal.
HttpResponse startRun(Backend& backend, RunRequest run) {
  const bt::PlanFile file = run.plan.file;
  const std::string name = run.plan_name;
  const StartResult started = backend.start(std::move(run));
  if (!started.started()) {
    if (!started.diagnostics.empty()) {
      return invalidPlan(started.diagnostics, file, name);
    }
    return errorResponse(started.status != 0 ? started.status : 409, started.error);
  }
  return jsonResponse({{"run", started.run_id}}, 202);
}

json documentJson(const DocumentVersion& document) {
  json out = {
      {"name", document.name}, {"version", document.version}, {"saved_at", document.saved_at}, {"xml", document.xml}};
  try {
    out["plan"] = planFileToJson(bt::parsePlanFile(document.xml, document.name + ".xml"));
  } catch (const bt::PlanError&) {
    out["plan"] = nullptr;  // stored text is always valid; never expected
  }
  return out;
}

json runJson(const RunRecord& run) {
  json out = {{"id", run.id},
              {"plan", run.plan},
              {"version", run.version},
              {"workcell", run.workcell},
              {"started_at", run.started_at},
              {"result", run.result},
              {"ended_at", run.ended_at},
              {"clock_seconds", run.clock_seconds},
              {"transitions", run.transitions},
              {"truncated", run.truncated}};
  if (!run.failure_reason.empty()) {
    out["failure_path"] = run.failure_path;
    out["failure_reason"] = run.failure_reason;
  }
  return out;
}

/// Which transitions of a run log a request asks for: `from` (a seq, default 1) and `limit`
/// (default and most ApiOptions::run_page_transitions), and at most kRunPageBytes of their
/// text, so that a read of any log is bounded in time and memory (issue 27: one answer of a
/// 120,000-transition log took 7 s of CPU and hundreds of MB).
constexpr std::size_t kRunPageBytes = 4u << 20;

TransitionPage transitionPage(const Target& target, std::size_t most) {
  TransitionPage page;
  page.max_bytes = kRunPageBytes;
  if (const auto it = target.query.find("from"); it != target.query.end()) {
    const auto value = parseLong(it->second);
    if (!value || *value < 1) {
      throw RequestError(400, "from must be a transition's seq: 1 or more");
    }
    page.from = static_cast<std::uint64_t>(*value);
  }
  page.limit = countParameter(target, "limit", most, most);
  return page;
}

/// A page of transitions: `transition_list`, and `next_from` (the seq to ask for next, null
/// after the last).
void addTransitions(json& out, const RunLog& log) {
  json transitions = json::array();
  for (const TransitionRecord& t : log.transitions) {
    json item = {{"seq", t.seq}, {"t", t.t}, {"uid", t.uid}, {"from", t.from}, {"to", t.to}};
    if (!t.reason.empty()) {
      item["reason"] = t.reason;
      item["origin"] = t.origin;
    }
    if (!t.data.empty()) {
      item["data"] = json::parse(t.data, nullptr, false);
    }
    transitions.push_back(std::move(item));
  }
  out["transition_list"] = std::move(transitions);
  out["next_from"] = log.next_seq ? json(*log.next_seq) : json(nullptr);
}

json runLogJson(const RunLog& log) {
  json out = runJson(log.run);
  out["xml"] = log.run.xml;
  try {
    out["plan_json"] = planFileToJson(bt::parsePlanFile(log.run.xml, "run.xml"));
  } catch (const bt::PlanError&) {
    out["plan_json"] = nullptr;
  }
  json nodes = json::array();
  for (const RunNode& node : log.nodes) {
    nodes.push_back(
        {{"uid", node.uid}, {"parent", node.parent}, {"id", node.id}, {"name", node.name}, {"path", node.path}});
  }
  out["nodes"] = std::move(nodes);
  addTransitions(out, log);
  return out;
}

// --- the handlers: one per route, each given the request as a Call ---------------------------

/// A request matched to a route: its path parameters (the pattern's {…} segments, in order)
/// and query, and what the API answers from.
struct Call {
  const HttpRequest& request;
  const std::vector<std::string>& params;
  const Target& target;
  Backend& backend;
  Store& store;
  const ApiOptions& options;

  json body() const { return parseRequestJson(request.body); }
  /// A logged run's id from the path: a positive integer.
  std::int64_t loggedRunId() const {
    const auto id = parseLong(params[0]);
    if (!id || *id < 1) {
      throw RequestError(400, "a logged run's id is a positive integer");
    }
    return *id;
  }
};

HttpResponse getInfo(const Call& call) { return jsonResponse(call.backend.info()); }

HttpResponse getNodes(const Call& call) {
  HttpResponse response;
  response.body = call.backend.nodesJson();
  return response;
}

HttpResponse getChoices(const Call& call) { return jsonResponse(call.backend.choices()); }

HttpResponse getState(const Call& call) { return jsonResponse(call.backend.state()); }

HttpResponse getPointCloud(const Call& call) {
  const auto cloud = call.backend.pointCloud(countParameter(call.target, "max", 20000, 200000));
  return cloud ? jsonResponse(*cloud) : errorResponse(404, "this workcell has no RGB-D camera to show");
}

HttpResponse getRobot(const Call& call) {
  const auto robot = call.backend.robot();
  return robot ? jsonResponse(*robot) : errorResponse(404, "this cell has no robot to draw");
}

HttpResponse resetScene(const Call& call) {
  const StartResult reset = call.backend.resetScene();
  return reset.status == 0 ? jsonResponse({{"reset", true}}) : errorResponse(reset.status, reset.error);
}

// Saved plans and subtrees: the same handlers for both kinds of document.
constexpr const char* noun(DocumentKind kind) { return kind == DocumentKind::kPlan ? "plan" : "subtree"; }

HttpResponse noDocument(DocumentKind kind, const std::string& name, const std::string& detail = {}) {
  return errorResponse(404, std::string("no ") + noun(kind) + " '" + name + "'" + detail);
}

template <DocumentKind kind>
HttpResponse listDocuments(const Call& call) {
  json list = json::array();
  for (const auto& summary : call.store.list(kind)) {
    list.push_back({{"name", summary.name},
                    {"latest_version", summary.latest_version},
                    {"versions", summary.versions},
                    {"updated_at", summary.updated_at}});
  }
  return jsonResponse(list);
}

template <DocumentKind kind>
HttpResponse getDocument(const Call& call) {
  const std::string& name = call.params[0];
  const auto document = call.store.load(kind, name, versionParameter(call.target));
  return document ? jsonResponse(documentJson(*document))
                  : noDocument(kind, name, call.target.query.contains("version") ? " with that version" : "");
}

template <DocumentKind kind>
HttpResponse saveDocument(const Call& call) {
  const std::string& name = call.params[0];
  ParsedPlan parsed = planFromBody(call.body(), name + ".xml");
  if (kind == DocumentKind::kSubtree) {
    if (parsed.plan.file.trees.size() != 1 || parsed.plan.file.trees.front().id != name) {
      throw RequestError(422, "a saved subtree is one BehaviorTree whose ID is its name ('" + name + "')");
    }
    parsed.plan.file.main_tree = name;
    parsed.xml = bt::writePlanFile(parsed.plan.file);
    parsed.plan = bt::loadPlanText(parsed.xml, name + ".xml", {.follow_includes = false});
  }
  if (auto diagnostics = call.backend.validate(parsed.plan); !diagnostics.empty()) {
    return invalidPlan(diagnostics, parsed.plan.file, name);
  }
  const int version = call.store.save(kind, name, parsed.xml);
  return jsonResponse({{"name", name}, {"version", version}}, 201);
}

template <DocumentKind kind>
HttpResponse deleteDocument(const Call& call) {
  const std::string& name = call.params[0];
  if (!call.target.query.empty()) {
    // A hostile tester's DELETE .../NAME?version=1 removed every version.
    throw RequestError(400, std::string("DELETE removes the ") + noun(kind) + " '" + name +
                                "' with all its versions and takes no query ('" + call.target.query.begin()->first +
                                "' given); one version cannot be deleted");
  }
  return call.store.remove(kind, name) ? jsonResponse({{"deleted", name}}) : noDocument(kind, name);
}

template <DocumentKind kind>
HttpResponse listVersions(const Call& call) {
  json list = json::array();
  for (const auto& version : call.store.versions(kind, call.params[0])) {
    list.push_back({{"version", version.version}, {"saved_at", version.saved_at}});
  }
  return list.empty() ? noDocument(kind, call.params[0]) : jsonResponse(list);
}

template <DocumentKind kind>
HttpResponse getDocumentXml(const Call& call) {
  const std::string& name = call.params[0];
  const auto document = call.store.load(kind, name, versionParameter(call.target));
  if (!document) {
    return noDocument(kind, name);
  }
  HttpResponse response;
  response.content_type = "application/xml";
  response.body = document->xml;
  response.headers.emplace_back("Content-Disposition", "attachment; filename=\"" + name + ".xml\"");
  return response;
}

HttpResponse validatePlan(const Call& call) {
  // "name": the plan's name in messages (optional; the page sends the name it has).
  const json request_body = call.body();
  std::string label = "plan";
  if (request_body.is_object()) {
    if (const auto it = request_body.find("name");
        it != request_body.end() && it->is_string() && checkName(it->get_ref<const std::string&>()).empty()) {
      label = it->get<std::string>();
    }
  }
  const ParsedPlan parsed = planFromBody(request_body, label);
  const auto diagnostics = call.backend.checkForCell(parsed.plan);
  return jsonResponse({{"valid", diagnostics.empty()},
                       {"diagnostics", diagnosticsToJson(diagnostics, parsed.plan.file)},
                       {"xml", parsed.xml},
                       {"plan", planFileToJson(parsed.plan.file)}});
}

HttpResponse listRuns(const Call& call) {
  json list = json::array();
  for (const auto& run : call.store.runs(countParameter(call.target, "limit", 100, 10000))) {
    list.push_back(runJson(run));
  }
  return jsonResponse(list);
}

/// POST /api/runs: a saved plan by name (and version), or a plan in the body.
HttpResponse startPlanRun(const Call& call) {
  const json request_body = call.body();
  RunRequest run;
  if (request_body.is_object() && request_body.contains("name")) {
    if (!request_body["name"].is_string()) {
      throw RequestError(400, "'name' must be a string");
    }
    const std::string& name = checkedName(request_body["name"].get_ref<const std::string&>());
    std::optional<int> version;
    if (const auto it = request_body.find("version"); it != request_body.end() && !it->is_null()) {
      if (!it->is_number_integer() || it->get<long long>() < 1 || it->get<long long>() > 1'000'000'000) {
        throw RequestError(400, "'version' must be a positive integer");
      }
      version = it->get<int>();
    }
    const auto document = call.store.load(DocumentKind::kPlan, name, version);
    if (!document) {
      const auto versions = call.store.versions(DocumentKind::kPlan, name);
      return versions.empty() || !version
                 ? noDocument(DocumentKind::kPlan, name)
                 : noDocument(DocumentKind::kPlan, name,
                              " with version " + std::to_string(*version) + " (its latest is version " +
                                  std::to_string(versions.front().version) + ")");
    }
    run.plan = bt::loadPlanText(document->xml, name + ".xml", {.follow_includes = false});
    run.xml = document->xml;
    run.plan_name = name;
    run.version = document->version;
  } else {
    ParsedPlan parsed = planFromBody(request_body, "plan.xml");
    run.plan = std::move(parsed.plan);
    run.xml = std::move(parsed.xml);
  }
  if (const auto it = request_body.find("paused"); it != request_body.end()) {
    if (!it->is_boolean()) {
      throw RequestError(400, "'paused' must be true or false");
    }
    run.start_paused = it->get<bool>();
  }
  return startRun(call.backend, std::move(run));
}

/// GET /api/runs/ID: a logged run (a page of its transitions, and its live status while it
/// runs), an operation the engine remembers (negative ids), or "active".
HttpResponse getRun(const Call& call) {
  if (call.params[0] == "active") {
    const auto status = call.backend.runStatus(std::nullopt);
    return status ? jsonResponse(*status) : errorResponse(404, "nothing has run yet");
  }
  const auto id = parseLong(call.params[0]);
  if (!id || *id == 0) {
    throw RequestError(400, "a run id is a nonzero integer (plan runs count up from 1, operations down from -1)");
  }
  if (const auto log = *id > 0 ? call.store.run(*id, transitionPage(call.target, call.options.run_page_transitions))
                               : std::nullopt) {
    json out = runLogJson(*log);
    if (const auto status = call.backend.runStatus(*id)) {
      out["live"] = *status;
    }
    return jsonResponse(out);
  }
  const auto status = call.backend.runStatus(*id);
  return status ? jsonResponse(*status) : errorResponse(404, "no run " + std::to_string(*id));
}

HttpResponse getRunStates(const Call& call) {
  const std::int64_t id = call.loggedRunId();
  const std::vector<StateRecord> records = call.store.runStates(id);
  if (records.empty() && !call.store.run(id)) {
    return errorResponse(404, "no run " + std::to_string(id));
  }
  json states = json::array();
  for (const StateRecord& state : records) {
    json snapshot = json::parse(state.state, nullptr, false);
    if (!snapshot.is_discarded()) {
      states.push_back({{"t", state.t}, {"state", std::move(snapshot)}});
    }
  }
  return jsonResponse({{"run", id}, {"states", std::move(states)}});
}

HttpResponse getRunTransitions(const Call& call) {
  const std::int64_t id = call.loggedRunId();
  const auto log = call.store.run(id, transitionPage(call.target, call.options.run_page_transitions),
                                  /*with_nodes=*/false);
  if (!log) {
    return errorResponse(404, "no logged run " + std::to_string(id));
  }
  json out = {{"id", id}, {"transitions", log->run.transitions}};
  addTransitions(out, *log);
  return jsonResponse(out);
}

HttpResponse controlRun(const Call& call) {
  const json request_body = call.body();
  if (!request_body.is_object() || !request_body.contains("action") || !request_body["action"].is_string()) {
    throw RequestError(400, "the body must be {\"action\": \"pause\" | \"resume\" | \"step\" | \"stop\"}");
  }
  const std::string& action = request_body["action"].get_ref<const std::string&>();
  static const std::map<std::string, RunControl> kActions = {{"pause", RunControl::kPause},
                                                             {"resume", RunControl::kResume},
                                                             {"step", RunControl::kStep},
                                                             {"stop", RunControl::kStop}};
  const auto it = kActions.find(action);
  if (it == kActions.end()) {
    throw RequestError(400, "unknown action '" + action.substr(0, 32) + "' (pause, resume, step, stop)");
  }
  if (!call.backend.control(it->second)) {
    return errorResponse(409, "nothing is running");
  }
  return jsonResponse({{"ok", action}});
}

/// POST /api/operations: one operation from the menu or the waypoint panel, as a one-node plan.
HttpResponse startOperation(const Call& call) {
  const json request_body = call.body();
  if (!request_body.is_object() || !request_body.contains("node") || !request_body["node"].is_string()) {
    throw RequestError(400, "the body must be {\"node\": TYPE, \"attributes\": {NAME: VALUE, ...}}");
  }
  json node = {{"id", request_body["node"]}, {"attributes", json::array()}, {"children", json::array()}};
  if (const auto it = request_body.find("attributes"); it != request_body.end()) {
    if (!it->is_object()) {
      throw RequestError(400, "'attributes' must be an object of strings");
    }
    for (const auto& [key, value] : it->items()) {
      if (!value.is_string()) {
        throw RequestError(400, "attribute '" + key.substr(0, 64) + "' must be a string");
      }
      node["attributes"].push_back({key, value});
    }
  }
  ParsedPlan parsed = planFromBody(
      {{"plan", {{"main_tree", "operation"}, {"trees", {{{"id", "operation"}, {"root", node}}}}}}}, "operation.xml");
  RunRequest run;
  run.plan = std::move(parsed.plan);
  run.xml = std::move(parsed.xml);
  run.operation = true;
  return startRun(call.backend, std::move(run));
}

/// POST /api/drag: free-drive's hand and dead-man (Backend::Drag): {"force": [x, y, z], "torque":
/// [x, y, z]} (N, N m, world, at the tool), a push for 0.25 s and the dead-man for 2 s, answered
/// with why free-drive's last step was not wholly taken ("blocked", empty when it was) and its
/// speed (m/s); or {"release": true}.
HttpResponse dragTool(const Call& call) {
  const json body = call.body();
  if (!body.is_object()) {
    throw RequestError(400, "the body must be {\"force\": [x, y, z], \"torque\": [x, y, z]} or {\"release\": true}");
  }
  Backend::Drag drag;
  for (const auto& [key, value] : body.items()) {
    if (key == "release") {
      if (!value.is_boolean()) {
        throw RequestError(400, "'release' must be true or false");
      }
      drag.release = value.get<bool>();
    } else if (key == "force" || key == "torque") {
      const double limit = key == "force" ? arm::kMaxHandForce : arm::kMaxHandTorque;
      if (!value.is_array() || value.size() != 3) {
        throw RequestError(400, "'" + key + "' must be [x, y, z]");
      }
      std::array<double, 3>& out = key == "force" ? drag.force : drag.torque;
      for (std::size_t i = 0; i < 3; ++i) {
        if (!value[i].is_number() || !std::isfinite(value[i].get<double>())) {
          throw RequestError(400, "'" + key + "[" + std::to_string(i) + "]' must be a finite number");
        }
        out[i] = value[i].get<double>();
      }
      const double size = std::sqrt(out[0] * out[0] + out[1] * out[1] + out[2] * out[2]);
      if (size > limit) {
        char text[160];
        std::snprintf(text, sizeof text, "'%s' is %.1f %s, more than a hand pushes with (at most %.0f)", key.c_str(),
                      size, key == "force" ? "N" : "N m", limit);
        throw RequestError(400, text);
      }
    } else {
      throw RequestError(400, "unknown field '" + key.substr(0, 32) + "' (force, torque, release)");
    }
  }
  const Backend::DragResult result = call.backend.drag(drag);
  if (result.status != 0) {
    return errorResponse(result.status, result.error);
  }
  if (drag.release) {
    return jsonResponse({{"ok", "released"}});
  }
  return jsonResponse({{"ok", "held"}, {"blocked", result.blocked}, {"speed", result.speed}});
}

HttpResponse getGroundTruth(const Call& call) {
  const auto truth = call.backend.groundTruth();
  return truth ? jsonResponse(*truth) : errorResponse(404, "this workcell has no simulator");
}

// --- the route table ---------------------------------------------------------------------------

/// Who may call a route: kRead, anyone while the server listens on loopback only (else the
/// token); kChange, the token (every method but GET); kToken, the token always (test endpoints).
enum class Access { kRead, kChange, kToken };

/// A command's body is small: 16 KiB is far more than any needs.
constexpr std::size_t kSmallBody = 16u << 10;

struct Route {
  /// "GET" (which answers HEAD too), "POST", "PUT" or "DELETE".
  std::string_view method;
  /// Segments after /api/; "{name}" is a plan's or subtree's name (refused with 400 unless it
  /// is an identifier), any other "{…}" one segment as it is. Both are the handler's params.
  std::string_view pattern;
  HttpResponse (*handler)(const Call&);
  Access access;
  /// The most bytes of body this route reads; 0: ApiOptions::max_body_bytes.
  std::size_t max_body = 0;
  /// A long read (run logs, the run list, the point cloud), answered on a thread of its own.
  bool bulk = false;
  /// TEST ONLY: served only with ApiOptions::test_endpoints.
  bool test_only = false;
};

// Adding an endpoint is a row here and its handler above (and its line in docs/EDITOR.md).
constexpr Route kRoutes[] = {
    {"GET", "info", getInfo, Access::kRead},
    {"GET", "nodes", getNodes, Access::kRead},
    {"GET", "choices", getChoices, Access::kRead},
    {"GET", "state", getState, Access::kRead},
    {"GET", "pointcloud", getPointCloud, Access::kRead, 0, true},
    {"GET", "robot", getRobot, Access::kRead},
    {"POST", "scene/reset", resetScene, Access::kChange, kSmallBody},
    {"GET", "plans", listDocuments<DocumentKind::kPlan>, Access::kRead},
    {"GET", "plans/{name}", getDocument<DocumentKind::kPlan>, Access::kRead},
    {"PUT", "plans/{name}", saveDocument<DocumentKind::kPlan>, Access::kChange},
    {"DELETE", "plans/{name}", deleteDocument<DocumentKind::kPlan>, Access::kChange},
    {"GET", "plans/{name}/versions", listVersions<DocumentKind::kPlan>, Access::kRead},
    {"GET", "plans/{name}/xml", getDocumentXml<DocumentKind::kPlan>, Access::kRead},
    {"GET", "subtrees", listDocuments<DocumentKind::kSubtree>, Access::kRead},
    {"GET", "subtrees/{name}", getDocument<DocumentKind::kSubtree>, Access::kRead},
    {"PUT", "subtrees/{name}", saveDocument<DocumentKind::kSubtree>, Access::kChange},
    {"DELETE", "subtrees/{name}", deleteDocument<DocumentKind::kSubtree>, Access::kChange},
    {"GET", "subtrees/{name}/versions", listVersions<DocumentKind::kSubtree>, Access::kRead},
    {"GET", "subtrees/{name}/xml", getDocumentXml<DocumentKind::kSubtree>, Access::kRead},
    {"POST", "validate", validatePlan, Access::kChange},
    {"GET", "runs", listRuns, Access::kRead, 0, true},
    {"POST", "runs", startPlanRun, Access::kChange},
    {"GET", "runs/{id}", getRun, Access::kRead, 0, true},
    {"GET", "runs/{id}/states", getRunStates, Access::kRead, 0, true},
    {"GET", "runs/{id}/transitions", getRunTransitions, Access::kRead, 0, true},
    {"POST", "control", controlRun, Access::kChange, kSmallBody},
    {"POST", "operations", startOperation, Access::kChange},
    {"POST", "drag", dragTool, Access::kChange, kSmallBody},
    {"GET", "test/ground_truth", getGroundTruth, Access::kToken, 0, false, true},
};

bool isRead(std::string_view method) { return method == "GET" || method == "HEAD"; }

/// Whether a request's path (segments after "api") has a route's pattern; fills its params.
bool matches(const Route& route, const std::vector<std::string>& segments, std::vector<std::string>& params) {
  params.clear();
  std::size_t i = 1;
  std::string_view rest = route.pattern;
  while (!rest.empty()) {
    const std::size_t slash = rest.find('/');
    const std::string_view part = rest.substr(0, slash);
    rest = slash == std::string_view::npos ? std::string_view() : rest.substr(slash + 1);
    if (i >= segments.size()) {
      return false;
    }
    if (part.starts_with('{')) {
      params.push_back(segments[i]);
    } else if (segments[i] != part) {
      return false;
    }
    ++i;
  }
  return i == segments.size();
}

/// What a request reaches: the route for its path and method, whether any route has its path
/// (then a wrong method is 405), and the route's params.
struct Match {
  const Route* route = nullptr;
  const Route* path = nullptr;
  std::vector<std::string> params;
};

Match findRoute(const Target& target, std::string_view method, bool test_endpoints) {
  Match match;
  if (target.segments.empty() || target.segments[0] != "api") {
    return match;
  }
  std::vector<std::string> params;
  for (const Route& route : kRoutes) {
    if ((route.test_only && !test_endpoints) || !matches(route, target.segments, params)) {
      continue;
    }
    if (match.path == nullptr) {
      match.path = &route;
      match.params = params;
    }
    if (route.method == method || (route.method == "GET" && method == "HEAD")) {
      match.route = &route;
      match.params = std::move(params);
      return match;
    }
  }
  return match;
}

}  // namespace

Api::Api(Backend& backend, Store& store, ApiOptions options)
    : backend_(backend), store_(store), options_(std::move(options)) {}

bool Api::authorized(std::string_view authorization) const {
  return sameToken(bearerToken(authorization), options_.token);
}

bool Api::isBulkRead(const HttpRequest& request) {
  const Match match = findRoute(parseTarget(request.target), request.method, false);
  return match.route != nullptr && match.route->bulk;
}

bool Api::tokenMatches(std::string_view token) const { return sameToken(token, options_.token); }

HttpResponse Api::handle(const HttpRequest& request) {
  try {
    return answer(request);
  } catch (...) {  // e.g. out of memory while building an error answer
    HttpResponse response;
    response.status = 500;
    response.body = R"({"error":"internal error"})";
    return response;
  }
}

HttpResponse Api::answer(const HttpRequest& request) {
  try {
    // Refusals come in this order: too large, not signed in, no such endpoint, a bad name in
    // the path, a method the endpoint does not take.
    const Target target = parseTarget(request.target);
    const Match match = findRoute(target, request.method, options_.test_endpoints);
    const std::size_t max_body =
        match.route != nullptr && match.route->max_body != 0 ? match.route->max_body : options_.max_body_bytes;
    if (request.body.size() > max_body) {
      return errorResponse(413, "the body is larger than " + std::to_string(max_body) + " bytes");
    }
    const bool read = isRead(request.method);
    const Access access = match.route != nullptr ? match.route->access : (read ? Access::kRead : Access::kChange);
    if ((access != Access::kRead || options_.reads_need_token) && !authorized(request.authorization)) {
      return errorResponse(401, access == Access::kToken ? "test endpoints need the token"
                                : read ? "sign in: this server needs the token for everything (it listens beyond "
                                         "this machine)"
                                       : "sign in to change plans or move the robot (with the token `costar serve` "
                                         "printed or wrote to its token file)");
    }
    if (match.path == nullptr) {
      return errorResponse(404, "no such endpoint: " + request.target.substr(0, 200));
    }
    if (match.path->pattern.find("{name}") != std::string_view::npos) {
      checkedName(match.params[0]);
    }
    if (match.route == nullptr) {
      return errorResponse(405, "method " + request.method.substr(0, 16) + " not allowed here");
    }
    return match.route->handler(Call{request, match.params, target, backend_, store_, options_});
  } catch (const RequestError& error) {
    return errorResponse(error.status(), error.what());
  } catch (const bt::PlanError& error) {
    return invalidPlan(error.diagnostics(), bt::PlanFile{});
  } catch (const StoreError& error) {
    return errorResponse(503, error.what());
  } catch (const BackendBusy& error) {
    return errorResponse(503, error.what());
  } catch (const std::exception& error) {
    return errorResponse(500, std::string("internal error: ") + error.what());
  }
}

}  // namespace costar::server
