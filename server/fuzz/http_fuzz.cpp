// libFuzzer target, end to end in memory: any bytes as one connection to the server's real
// sessions (http_session.h: Boost.Beast's HTTP parser, the Host and upgrade checks, the static
// files, the API's router and handlers, the error answers, and after an upgrade to /api/stream
// the WebSocket frames, their messages and the stream's broadcasts), then the client's end of
// the stream; everything the server sends is checked (http_check.h). The server must never
// crash, hang (leave a session waiting once the client has closed) or leak.
//
// The connection is in memory (server/http_memory.h: Beast's test stream on one io_context,
// polled on this thread), so a run costs microseconds, not a socket, an accept and a thread hop;
// http_socket_fuzz.cpp drives the same server over loopback TCP. The bytes reach the parser
// all at once, or 256 or 16 at a time (chosen by the input's length), as TCP may cut them.
//
// The store holds a run log longer than a page (run 1), so that reading logs in pages is fuzzed.
//
// Run: build-fuzz/server/http_fuzz -dict=server/fuzz/http.dict server/fuzz/http_corpus

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "server/api.h"
#include "server/fuzz/fuzz_backend.h"
#include "server/fuzz/http_check.h"
#include "server/http_memory.h"
#include "server/store.h"

using namespace costar;

namespace {

constexpr const char* kToken = "fuzz-token-0123456789abcdef";

/// Run 1, a log of three pages (GET /api/runs/1 answers it in pages: from=, limit=).
void seedLongRunLog(server::Store& store) {
  server::RunRecord run;
  run.id = 1;
  run.xml = R"(<root BTCPP_format="4"><BehaviorTree ID="m"><Repeat num_cycles="-1"><AlwaysSuccess/></Repeat>)"
            "</BehaviorTree></root>";
  store.beginRun(run,
                 {{0, -1, "Repeat", "", "m/Repeat[1]"}, {1, 0, "AlwaysSuccess", "", "m/Repeat[1]/AlwaysSuccess[1]"}});
  std::vector<server::TransitionRecord> transitions;
  for (std::uint64_t seq = 1; seq <= 120; ++seq) {
    transitions.push_back({seq, 0.01 * static_cast<double>(seq), static_cast<std::uint32_t>(seq % 2), "IDLE", "RUNNING",
                           "", "", seq % 10 == 0 ? R"({"candidates":[1,2]})" : ""});
  }
  store.appendTransitions(1, transitions);
  run.result = "STOPPED";
  run.transitions = 120;
  store.endRun(run);
}

/// The server with an in-memory store.
struct Harness {
  server::fuzzing::FuzzBackend backend;
  std::unique_ptr<server::Store> store;
  std::unique_ptr<server::Api> api;
  std::unique_ptr<server::MemoryHttpServer> http;

  void restart() {
    http.reset();
    api.reset();
    store = std::make_unique<server::Store>(":memory:");
    seedLongRunLog(*store);
    // Pages of 50 (not 5,000): a long log in few transitions, so that reading it stays cheap.
    api = std::make_unique<server::Api>(
        backend, *store, server::ApiOptions{.token = kToken, .test_endpoints = true, .run_page_transitions = 50});
    server::HttpServerOptions options;
    options.address = "127.0.0.1";
    options.web_root = std::filesystem::path("/nonexistent-costar-web-root");
    options.max_body_bytes = 64 * 1024;
    http = std::make_unique<server::MemoryHttpServer>(*api, backend, options);
  }
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static Harness harness;
  static std::size_t inputs = 0;
  if (inputs++ % 2000 == 0) {  // a fresh store now and then keeps memory flat
    harness.restart();
  }
  constexpr std::size_t kReadSizes[] = {0, 0, 256, 16};
  const auto exchange =
      harness.http->exchange({reinterpret_cast<const char*>(data), size}, kReadSizes[size % std::size(kReadSizes)]);
  if (!exchange.closed) {
    server::fuzzing::fail("the server did not close the connection after the client's end (a session hangs)",
                          exchange.output);
  }
  server::fuzzing::checkOutput(exchange.output);
  return 0;
}
