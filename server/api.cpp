#include "server/api.h"

#include <charconv>
#include <map>

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
  page.limit = most;
  page.max_bytes = kRunPageBytes;
  if (const auto it = target.query.find("from"); it != target.query.end()) {
    const auto value = parseLong(it->second);
    if (!value || *value < 1) {
      throw RequestError(400, "from must be a transition's seq: 1 or more");
    }
    page.from = static_cast<std::uint64_t>(*value);
  }
  if (const auto it = target.query.find("limit"); it != target.query.end()) {
    const auto value = parseLong(it->second);
    if (!value || *value < 1 || *value > static_cast<long long>(most)) {
      throw RequestError(400, "limit must be 1 to " + std::to_string(most));
    }
    page.limit = static_cast<std::size_t>(*value);
  }
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

}  // namespace

Api::Api(Backend& backend, Store& store, ApiOptions options)
    : backend_(backend), store_(store), options_(std::move(options)) {}

bool Api::authorized(std::string_view authorization) const {
  return sameToken(bearerToken(authorization), options_.token);
}

bool Api::isBulkRead(const HttpRequest& request) {
  const std::string_view path = std::string_view(request.target).substr(0, request.target.find('?'));
  return (request.method == "GET" || request.method == "HEAD") &&
         (path == "/api/runs" || path.starts_with("/api/runs/") || path == "/api/pointcloud");
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
    if (request.body.size() > options_.max_body_bytes) {
      return errorResponse(413, "the body is larger than " + std::to_string(options_.max_body_bytes) + " bytes");
    }
    const bool read = request.method == "GET" || request.method == "HEAD";
    if ((!read || options_.reads_need_token) && !authorized(request.authorization)) {
      return errorResponse(401, read ? "sign in: this server needs the token for everything (it listens beyond "
                                       "this machine)"
                                     : "sign in to change plans or move the robot (with the token `costar serve` "
                                       "printed or wrote to its token file)");
    }
    return route(request);
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

HttpResponse Api::route(const HttpRequest& request) {
  const Target target = parseTarget(request.target);
  const auto& s = target.segments;
  const std::string& method = request.method;
  const bool get = method == "GET" || method == "HEAD";
  if (s.empty() || s[0] != "api") {
    return errorResponse(404, "no such endpoint: " + request.target.substr(0, 200));
  }
  const auto is = [&s](std::initializer_list<const char*> path) {
    if (s.size() != path.size() + 1) {
      return false;
    }
    std::size_t i = 1;
    for (const char* part : path) {
      if (part[0] != '*' && s[i] != part) {
        return false;
      }
      ++i;
    }
    return true;
  };
  const auto body = [&request] { return parseRequestJson(request.body); };
  const auto wrongMethod = [&method] {
    return errorResponse(405, "method " + method.substr(0, 16) + " not allowed here");
  };

  if (is({"info"})) {
    return get ? jsonResponse(backend_.info()) : wrongMethod();
  }
  if (is({"nodes"})) {
    if (!get) {
      return wrongMethod();
    }
    HttpResponse response;
    response.body = backend_.nodesJson();
    return response;
  }
  if (is({"choices"})) {
    return get ? jsonResponse(backend_.choices()) : wrongMethod();
  }
  if (is({"state"})) {
    return get ? jsonResponse(backend_.state()) : wrongMethod();
  }
  if (is({"pointcloud"})) {
    if (!get) {
      return wrongMethod();
    }
    std::size_t max_points = 20000;
    if (const auto it = target.query.find("max"); it != target.query.end()) {
      const auto value = parseLong(it->second);
      if (!value || *value < 1 || *value > 200000) {
        throw RequestError(400, "max must be 1 to 200000");
      }
      max_points = static_cast<std::size_t>(*value);
    }
    const auto cloud = backend_.pointCloud(max_points);
    return cloud ? jsonResponse(*cloud) : errorResponse(404, "this workcell has no RGB-D camera to show");
  }

  // --- plans and saved subtrees ----------------------------------------------------------
  if (s.size() >= 2 && (s[1] == "plans" || s[1] == "subtrees")) {
    const DocumentKind kind = s[1] == "plans" ? DocumentKind::kPlan : DocumentKind::kSubtree;
    const char* noun = kind == DocumentKind::kPlan ? "plan" : "subtree";
    if (s.size() == 2) {
      if (!get) {
        return wrongMethod();
      }
      json list = json::array();
      for (const auto& summary : store_.list(kind)) {
        list.push_back({{"name", summary.name},
                        {"latest_version", summary.latest_version},
                        {"versions", summary.versions},
                        {"updated_at", summary.updated_at}});
      }
      return jsonResponse(list);
    }
    const std::string& name = checkedName(s[2]);
    if (s.size() == 3) {
      if (get) {
        const auto document = store_.load(kind, name, versionParameter(target));
        return document ? jsonResponse(documentJson(*document))
                        : errorResponse(404, std::string("no ") + noun + " '" + name + "'" +
                                                 (target.query.contains("version") ? " with that version" : ""));
      }
      if (method == "PUT") {
        ParsedPlan parsed = planFromBody(body(), name + ".xml");
        if (kind == DocumentKind::kSubtree) {
          if (parsed.plan.file.trees.size() != 1 || parsed.plan.file.trees.front().id != name) {
            throw RequestError(422, "a saved subtree is one BehaviorTree whose ID is its name ('" + name + "')");
          }
          parsed.plan.file.main_tree = name;
          parsed.xml = bt::writePlanFile(parsed.plan.file);
          parsed.plan = bt::loadPlanText(parsed.xml, name + ".xml", {.follow_includes = false});
        }
        if (auto diagnostics = backend_.validate(parsed.plan); !diagnostics.empty()) {
          return invalidPlan(diagnostics, parsed.plan.file, name);
        }
        const int version = store_.save(kind, name, parsed.xml);
        return jsonResponse({{"name", name}, {"version", version}}, 201);
      }
      if (method == "DELETE") {
        return store_.remove(kind, name) ? jsonResponse({{"deleted", name}})
                                         : errorResponse(404, std::string("no ") + noun + " '" + name + "'");
      }
      return wrongMethod();
    }
    if (s.size() == 4 && s[3] == "versions") {
      if (!get) {
        return wrongMethod();
      }
      json list = json::array();
      for (const auto& version : store_.versions(kind, name)) {
        list.push_back({{"version", version.version}, {"saved_at", version.saved_at}});
      }
      return list.empty() ? errorResponse(404, std::string("no ") + noun + " '" + name + "'") : jsonResponse(list);
    }
    if (s.size() == 4 && s[3] == "xml") {
      if (!get) {
        return wrongMethod();
      }
      const auto document = store_.load(kind, name, versionParameter(target));
      if (!document) {
        return errorResponse(404, std::string("no ") + noun + " '" + name + "'");
      }
      HttpResponse response;
      response.content_type = "application/xml";
      response.body = document->xml;
      response.headers.emplace_back("Content-Disposition", "attachment; filename=\"" + name + ".xml\"");
      return response;
    }
    return errorResponse(404, "no such endpoint");
  }

  if (is({"robot"})) {
    if (!get) {
      return wrongMethod();
    }
    const auto robot = backend_.robot();
    return robot ? jsonResponse(*robot) : errorResponse(404, "this cell has no robot to draw");
  }
  if (is({"scene", "reset"})) {
    if (method != "POST") {
      return wrongMethod();
    }
    const StartResult reset = backend_.resetScene();
    return reset.status == 0 ? jsonResponse({{"reset", true}}) : errorResponse(reset.status, reset.error);
  }

  if (is({"validate"})) {
    if (method != "POST") {
      return wrongMethod();
    }
    // "name": the plan's name in messages (optional; the page sends the name it has).
    const json request_body = body();
    std::string label = "plan";
    if (request_body.is_object()) {
      if (const auto it = request_body.find("name");
          it != request_body.end() && it->is_string() && checkName(it->get_ref<const std::string&>()).empty()) {
        label = it->get<std::string>();
      }
    }
    const ParsedPlan parsed = planFromBody(request_body, label);
    const auto diagnostics = backend_.checkForCell(parsed.plan);
    return jsonResponse({{"valid", diagnostics.empty()},
                         {"diagnostics", diagnosticsToJson(diagnostics, parsed.plan.file)},
                         {"xml", parsed.xml},
                         {"plan", planFileToJson(parsed.plan.file)}});
  }

  // --- runs ----------------------------------------------------------------------------------
  if (is({"runs"})) {
    if (get) {
      std::size_t limit = 100;
      if (const auto it = target.query.find("limit"); it != target.query.end()) {
        const auto value = parseLong(it->second);
        if (!value || *value < 1 || *value > 10000) {
          throw RequestError(400, "limit must be 1 to 10000");
        }
        limit = static_cast<std::size_t>(*value);
      }
      json list = json::array();
      for (const auto& run : store_.runs(limit)) {
        list.push_back(runJson(run));
      }
      return jsonResponse(list);
    }
    if (method != "POST") {
      return wrongMethod();
    }
    const json request_body = body();
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
      const auto document = store_.load(DocumentKind::kPlan, name, version);
      if (!document) {
        return errorResponse(404, "no plan '" + name + "'");
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
    return startRun(backend_, std::move(run));
  }
  if (is({"runs", "*", "states"})) {
    if (!get) {
      return wrongMethod();
    }
    const auto id = parseLong(s[2]);
    if (!id || *id <= 0) {
      throw RequestError(400, "a logged run's id is a positive integer");
    }
    const std::vector<StateRecord> records = store_.runStates(*id);
    if (records.empty() && !store_.run(*id)) {
      return errorResponse(404, "no run " + std::to_string(*id));
    }
    json states = json::array();
    for (const StateRecord& state : records) {
      json snapshot = json::parse(state.state, nullptr, false);
      if (!snapshot.is_discarded()) {
        states.push_back({{"t", state.t}, {"state", std::move(snapshot)}});
      }
    }
    return jsonResponse({{"run", *id}, {"states", std::move(states)}});
  }
  if (is({"runs", "*"})) {
    if (!get) {
      return wrongMethod();
    }
    if (s[2] == "active") {
      const auto status = backend_.runStatus(std::nullopt);
      return status ? jsonResponse(*status) : errorResponse(404, "nothing has run yet");
    }
    const auto id = parseLong(s[2]);
    if (!id || *id == 0) {
      throw RequestError(400, "a run id is a nonzero integer (plan runs count up from 1, operations down from -1)");
    }
    if (const auto log =
            *id > 0 ? store_.run(*id, transitionPage(target, options_.run_page_transitions)) : std::nullopt) {
      json out = runLogJson(*log);
      if (const auto status = backend_.runStatus(*id)) {
        out["live"] = *status;
      }
      return jsonResponse(out);
    }
    const auto status = backend_.runStatus(*id);
    return status ? jsonResponse(*status) : errorResponse(404, "no run " + std::to_string(*id));
  }
  if (is({"runs", "*", "transitions"})) {
    if (!get) {
      return wrongMethod();
    }
    const auto id = parseLong(s[2]);
    if (!id || *id < 1) {
      throw RequestError(400, "a logged run's id is a positive integer");
    }
    const auto log = store_.run(*id, transitionPage(target, options_.run_page_transitions), /*with_nodes=*/false);
    if (!log) {
      return errorResponse(404, "no logged run " + std::to_string(*id));
    }
    json out = {{"id", *id}, {"transitions", log->run.transitions}};
    addTransitions(out, *log);
    return jsonResponse(out);
  }
  if (is({"control"})) {
    if (method != "POST") {
      return wrongMethod();
    }
    const json request_body = body();
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
    if (!backend_.control(it->second)) {
      return errorResponse(409, "nothing is running");
    }
    return jsonResponse({{"ok", action}});
  }
  if (is({"operations"})) {
    if (method != "POST") {
      return wrongMethod();
    }
    const json request_body = body();
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
    return startRun(backend_, std::move(run));
  }
  if (is({"test", "ground_truth"})) {
    if (!options_.test_endpoints) {
      return errorResponse(404, "no such endpoint");
    }
    if (!get) {
      return wrongMethod();
    }
    if (!authorized(request.authorization)) {
      return errorResponse(401, "test endpoints need the token");
    }
    const auto truth = backend_.groundTruth();
    return truth ? jsonResponse(*truth) : errorResponse(404, "this workcell has no simulator");
  }
  return errorResponse(404, "no such endpoint: " + request.target.substr(0, 200));
}

}  // namespace costar::server
