// libFuzzer target: any bytes as an HTTP request to the editor's API (method, token or not,
// target, body). Handling must never crash, hang or leak, and must always answer a status
// between 200 and 599 with a JSON body that parses (unless it is an XML export).
//
// Input layout: byte 0 picks the method, byte 1 the Authorization (none, right, wrong), then
// the target up to the first '\n', then the body.

#include <cstdint>
#include <cstdlib>
#include <memory>
#include <string>
#include <string_view>

#include "server/api.h"
#include "server/fuzz/fuzz_backend.h"
#include "server/store.h"

using namespace costar;

namespace {

constexpr const char* kToken = "fuzz-token-0123456789abcdef";

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static server::fuzzing::FuzzBackend backend;
  static std::unique_ptr<server::Store> store;
  static std::unique_ptr<server::Api> api;
  static std::size_t inputs = 0;
  if (inputs++ % 2000 == 0) {  // a fresh in-memory store now and then keeps memory flat
    api.reset();
    store = std::make_unique<server::Store>(":memory:");
    api = std::make_unique<server::Api>(backend, *store, server::ApiOptions{.token = kToken, .test_endpoints = true});
  }
  if (size < 2) {
    return 0;
  }
  static constexpr const char* kMethods[] = {"GET", "PUT", "POST", "DELETE", "HEAD", "PATCH", "OPTIONS", "get"};
  server::HttpRequest request;
  request.method = kMethods[data[0] % 8];
  request.authorization = data[1] % 3 == 0 ? "" : (data[1] % 3 == 1 ? std::string("Bearer ") + kToken : "Bearer nope");
  const std::string_view rest(reinterpret_cast<const char*>(data + 2), size - 2);
  const auto newline = rest.find('\n');
  request.target = std::string(rest.substr(0, newline));
  request.body = newline == std::string_view::npos ? std::string() : std::string(rest.substr(newline + 1));

  const server::HttpResponse response = api->handle(request);
  if (response.status < 200 || response.status > 599) {
    std::abort();
  }
  if (response.content_type == "application/json" &&
      nlohmann::json::parse(response.body, nullptr, /*allow_exceptions=*/false).is_discarded()) {
    std::abort();
  }
  return 0;
}
