#pragma once
// The editor's HTTP API, independent of any network library: a request in, a response out.
// http_server.cpp feeds it from Boost.Beast; tests and the fuzz target call it directly.
//
// Every request that changes anything or moves the robot (every method but GET) needs
// `Authorization: Bearer <token>`; GETs are open when the server listens on loopback only.
// Bad JSON, unknown node types, invalid plans, oversize bodies and names that are not
// identifiers are answered with 4xx and a message; nothing a request holds can stop the server.
// The endpoints are listed in docs/EDITOR.md.

#include <cstddef>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "server/backend.h"
#include "server/store.h"

namespace costar::server {

struct HttpRequest {
  std::string method;  // "GET", "PUT", ...
  std::string target;  // path and query, e.g. "/api/plans/pick?version=2"
  std::string body;
  std::string authorization;  // the Authorization header, if any
};

struct HttpResponse {
  int status = 200;
  std::string content_type = "application/json";
  std::string body;
  std::vector<std::pair<std::string, std::string>> headers;
};

struct ApiOptions {
  /// The token every change needs. Never empty.
  std::string token;
  /// Listening beyond loopback: reads need the token too.
  bool reads_need_token = false;
  /// TEST ONLY: GET /api/test/ground_truth (the simulator's true state). Off unless asked.
  bool test_endpoints = false;
  /// Larger bodies are refused with 413 (the HTTP layer refuses them before reading them).
  std::size_t max_body_bytes = 1u << 20;
  /// Transitions of a run log per answer, by default and at most (GET /api/runs/ID?limit=).
  std::size_t run_page_transitions = 5000;
};

class Api {
 public:
  /// `backend` and `store` must outlive the Api.
  Api(Backend& backend, Store& store, ApiOptions options);

  /// Thread-safe. Never throws: every failure is a response.
  HttpResponse handle(const HttpRequest& request);

  /// Whether a request is a long read (run logs, the run list, the point cloud): the HTTP side
  /// answers those on a thread of their own, so that they never hold up the live stream or a
  /// command such as stop.
  static bool isBulkRead(const HttpRequest& request);

  /// Whether an Authorization header value carries the token.
  bool authorized(std::string_view authorization) const;
  /// Whether a token given by itself (e.g. in a WebSocket message) is the token.
  bool tokenMatches(std::string_view token) const;
  const ApiOptions& options() const { return options_; }

 private:
  /// handle() without its last guard: finds the request's route in the route table (api.cpp:
  /// method, path pattern, handler, who may call it, its body limit) and answers; every
  /// failure it knows becomes a 4xx or 5xx answer.
  HttpResponse answer(const HttpRequest& request);

  Backend& backend_;
  Store& store_;
  ApiOptions options_;
};

/// A JSON error response: {"error": message}.
HttpResponse errorResponse(int status, const std::string& message);

}  // namespace costar::server
