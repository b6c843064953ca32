#include "server/http_server.h"

#include <algorithm>
#include <boost/asio/executor_work_guard.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/strand.hpp>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <thread>
#include <vector>

#include "server/guard.h"
#include "server/http_session.h"
#include "server/plan_json.h"

namespace costar::server {

namespace detail {

namespace {

std::string lower(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(), [](unsigned char c) { return std::tolower(c); });
  return text;
}

}  // namespace

namespace {

bool isDigits(std::string_view text) {
  return !text.empty() && std::all_of(text.begin(), text.end(), [](char c) { return c >= '0' && c <= '9'; });
}

/// An IPv4 literal in 127.0.0.0/8: four decimal parts of 0-255 without leading zeros, as a
/// browser writes it (127.1 or 0177.0.0.1 are not this form: another program's spelling).
bool isLoopbackIpv4(std::string_view text) {
  std::vector<std::string_view> parts;
  for (std::size_t start = 0;;) {
    const std::size_t dot = text.find('.', start);
    parts.push_back(text.substr(start, dot == std::string_view::npos ? dot : dot - start));
    if (dot == std::string_view::npos) {
      break;
    }
    start = dot + 1;
  }
  const auto octet = [](std::string_view part) {
    return isDigits(part) && part.size() <= 3 && (part.size() == 1 || part[0] != '0') &&
           std::stoi(std::string(part)) <= 255;
  };
  return parts.size() == 4 && parts[0] == "127" && std::all_of(parts.begin(), parts.end(), octet);
}

}  // namespace

std::optional<Authority> parseAuthority(std::string_view text) {
  Authority out;
  std::string_view port;
  if (text.starts_with('[')) {
    const std::size_t close = text.find(']');
    if (close == std::string_view::npos) {
      return std::nullopt;
    }
    const std::string literal(text.substr(1, close - 1));
    boost::system::error_code error;
    const auto address = net::ip::make_address_v6(literal, error);
    if (error || literal.find('%') != std::string::npos) {  // no zone: a browser never sends one
      return std::nullopt;
    }
    out.host = address.to_string();
    out.ipv6 = true;
    const std::string_view rest = text.substr(close + 1);
    if (!rest.empty()) {
      if (rest[0] != ':') {
        return std::nullopt;  // "[::1].evil.com"
      }
      port = rest.substr(1);
      if (port.empty()) {
        return std::nullopt;
      }
    }
  } else {
    const std::size_t colon = text.find(':');
    out.host = lower(std::string(text.substr(0, colon)));
    if (colon != std::string_view::npos) {
      port = text.substr(colon + 1);
      if (port.empty()) {
        return std::nullopt;
      }
    }
    const auto hostCharacter = [](char c) {
      return std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '.' || c == '_';
    };
    if (out.host.empty() || !std::all_of(out.host.begin(), out.host.end(), hostCharacter)) {
      return std::nullopt;
    }
  }
  if (!port.empty()) {
    if (!isDigits(port) || port.size() > 5 || std::stoi(std::string(port)) == 0 ||
        std::stoi(std::string(port)) > 65535) {
      return std::nullopt;
    }
    out.port = static_cast<std::uint16_t>(std::stoi(std::string(port)));
  }
  return out;
}

bool isLoopback(const Authority& authority) {
  if (authority.ipv6) {
    return authority.host == "::1";
  }
  return authority.host == "localhost" || isLoopbackIpv4(authority.host);
}

std::optional<Origin> parseOrigin(std::string_view text) {
  const std::size_t separator = text.find("://");
  if (separator == std::string_view::npos) {
    return std::nullopt;  // "null" (a sandboxed page, a file), or not an origin
  }
  Origin out;
  out.scheme = lower(std::string(text.substr(0, separator)));
  if (out.scheme != "http" && out.scheme != "https") {
    return std::nullopt;
  }
  auto authority = parseAuthority(text.substr(separator + 3));  // an origin has no path
  if (!authority) {
    return std::nullopt;
  }
  out.authority = std::move(*authority);
  return out;
}

bool originAllowed(std::string_view origin, std::string_view host_header, bool loopback) {
  if (origin.empty()) {
    return true;  // not a browser: a browser always sends Origin with a WebSocket
  }
  const auto parsed = parseOrigin(origin);
  const auto host = parseAuthority(host_header);
  if (!parsed || !host || (loopback && !isLoopback(parsed->authority))) {
    return false;
  }
  // The page's own origin: the scheme's port when none is written; Host's is HTTP's, 80.
  const std::uint16_t origin_port = parsed->authority.port.value_or(parsed->scheme == "https" ? 443 : 80);
  return parsed->authority.host == host->host && origin_port == host->port.value_or(80);
}

namespace {

std::string contentType(const std::filesystem::path& path) {
  const std::string extension = lower(path.extension().string());
  if (extension == ".html") return "text/html; charset=utf-8";
  if (extension == ".js" || extension == ".mjs") return "text/javascript; charset=utf-8";
  if (extension == ".css") return "text/css; charset=utf-8";
  if (extension == ".json") return "application/json";
  if (extension == ".svg") return "image/svg+xml";
  if (extension == ".png") return "image/png";
  if (extension == ".ico") return "image/x-icon";
  if (extension == ".woff2") return "font/woff2";
  if (extension == ".map") return "application/json";
  return "application/octet-stream";
}

constexpr const char* kNotBuiltPage = R"(<!doctype html><html><head><meta charset="utf-8"><title>costar editor</title>
</head><body style="font-family:sans-serif;max-width:40em;margin:3em auto">
<h1>costar: the editor's page is not built</h1>
<p>The server and its API run, but the page's files were not found. Build them once:</p>
<pre>cd web &amp;&amp; npm ci &amp;&amp; npm run build</pre>
<p>then restart <code>costar serve</code> (or pass <code>--web-root</code>). The API is described in docs/EDITOR.md.</p>
</body></html>)";

}  // namespace

HttpResponse staticFile(const std::filesystem::path& root, const std::string& target) {
  std::string path = target.substr(0, target.find_first_of("?#"));
  if (path == "/" || path.empty()) {
    path = "/index.html";
  }
  const bool safe =
      path.size() < 256 && path.find("..") == std::string::npos && std::all_of(path.begin(), path.end(), [](char c) {
        return std::isalnum(static_cast<unsigned char>(c)) || c == '/' || c == '.' || c == '_' || c == '-';
      });
  if (!safe) {
    return errorResponse(404, "not found");
  }
  std::error_code error;
  const std::filesystem::path canonical_root = std::filesystem::canonical(root, error);
  if (error) {
    if (path == "/index.html") {
      HttpResponse response;
      response.content_type = "text/html; charset=utf-8";
      response.body = kNotBuiltPage;
      return response;
    }
    return errorResponse(404, "not found");
  }
  const std::filesystem::path file = std::filesystem::weakly_canonical(canonical_root / path.substr(1), error);
  const std::string prefix = canonical_root.string() + "/";
  if (error || !file.string().starts_with(prefix) || !std::filesystem::is_regular_file(file, error)) {
    if (path == "/index.html") {
      HttpResponse response;
      response.content_type = "text/html; charset=utf-8";
      response.body = kNotBuiltPage;
      return response;
    }
    return errorResponse(404, "not found");
  }
  std::ifstream in(file, std::ios::binary);
  std::ostringstream content;
  content << in.rdbuf();
  HttpResponse response;
  response.content_type = contentType(file);
  response.body = content.str();
  response.headers.emplace_back("Cache-Control",
                                path.starts_with("/assets/") ? "public, max-age=31536000, immutable" : "no-cache");
  if (response.content_type.starts_with("text/html")) {
    response.headers.emplace_back("Content-Security-Policy",
                                  "default-src 'self'; connect-src 'self' ws: wss:; img-src 'self' data: blob:; "
                                  "style-src 'self' 'unsafe-inline'; frame-ancestors 'none'");
  }
  return response;
}

void ServerCore::addClient(const std::shared_ptr<StreamClient>& client) {
  const std::lock_guard lock(mutex_);
  clients_.push_back(client);
}

void ServerCore::broadcastOnce() {
  std::vector<std::shared_ptr<StreamClient>> live;
  {
    const std::lock_guard lock(mutex_);
    std::erase_if(clients_, [](const std::weak_ptr<StreamClient>& client) { return client.expired(); });
    for (const auto& weak : clients_) {
      if (auto client = weak.lock(); client && client->ready()) {
        live.push_back(std::move(client));
      }
    }
  }
  for (std::string& text : backend.drainStream()) {
    auto message = std::make_shared<const std::string>(std::move(text));
    for (const auto& client : live) {
      client->send(message);
    }
  }
}

std::size_t ServerCore::clients() const {
  const std::lock_guard lock(mutex_);
  return static_cast<std::size_t>(
      std::count_if(clients_.begin(), clients_.end(), [](const auto& client) { return !client.expired(); }));
}

bool ServerCore::hostAllowed(const std::string& host_header) const {
  if (!loopback) {
    return true;
  }
  const auto host = parseAuthority(host_header);
  return host && isLoopback(*host);
}

std::vector<std::string> answerStreamMessage(ServerCore& core, const std::string& text, bool& authenticated) {
  using nlohmann::json;
  const auto answer = [](json message) {
    return std::vector<std::string>{message.dump(-1, ' ', false, json::error_handler_t::replace)};
  };
  json message;
  try {
    message = parseRequestJson(text, 16);
  } catch (const RequestError& e) {
    return answer({{"type", "error"}, {"error", e.what()}});
  }
  if (!message.is_object() || !message.contains("type") || !message["type"].is_string()) {
    return answer({{"type", "error"}, {"error", "a message is an object with a 'type'"}});
  }
  const std::string type = message["type"].get<std::string>();
  if (type == "auth") {
    const bool ok = message.contains("token") && message["token"].is_string() &&
                    core.api.tokenMatches(message["token"].get_ref<const std::string&>());
    authenticated = ok;  // the last auth counts: a wrong token ends an authenticated session
    return answer({{"type", "auth"}, {"ok", ok}});
  }
  if (type == "control") {
    if (!authenticated) {
      return answer(
          {{"type", "error"}, {"error", "commands need the token: send {\"type\":\"auth\",\"token\":...} first"}});
    }
    static const std::map<std::string, RunControl> kActions = {{"pause", RunControl::kPause},
                                                               {"resume", RunControl::kResume},
                                                               {"step", RunControl::kStep},
                                                               {"stop", RunControl::kStop}};
    const auto it = message.contains("action") && message["action"].is_string()
                        ? kActions.find(message["action"].get<std::string>())
                        : kActions.end();
    if (it == kActions.end()) {
      return answer({{"type", "error"}, {"error", "action must be pause, resume, step or stop"}});
    }
    const bool ok = core.backend.control(it->second);
    return answer({{"type", "control"}, {"action", it->first}, {"ok", ok}});
  }
  if (type == "ping") {
    return answer({{"type", "pong"}});
  }
  return answer({{"type", "error"}, {"error", "unknown message type"}});
}

}  // namespace detail

using tcp = detail::net::ip::tcp;
namespace net = detail::net;
namespace beast = detail::beast;

/// The TCP side: the acceptor, the I/O threads and the stream's timer.
struct HttpServer::Impl {
  Impl(Api& api, Backend& backend, HttpServerOptions options)
      : core(api, backend, std::move(options)), acceptor(ioc), timer(ioc) {
    core.bulk = bulk_ioc.get_executor();
  }

  detail::ServerCore core;
  net::io_context ioc;
  tcp::acceptor acceptor;
  net::steady_timer timer;
  std::vector<std::thread> threads;
  // Long reads (run logs) on a thread of their own: the I/O threads stay free for the stream.
  net::io_context bulk_ioc;
  std::optional<net::executor_work_guard<net::io_context::executor_type>> bulk_work;
  std::thread bulk_thread;
  std::atomic<bool> stopped{false};
  std::uint16_t port = 0;

  void accept();
  /// Sends what the backend has for the stream, then waits for the next round.
  void broadcast();
  void scheduleBroadcast();
};

void HttpServer::Impl::accept() {
  acceptor.async_accept(net::make_strand(ioc), [this](beast::error_code error, tcp::socket socket) {
    if (error == net::error::operation_aborted || !acceptor.is_open()) {
      return;
    }
    if (!error) {
      guarded("accepting a connection", [&] {
        std::make_shared<detail::HttpSession<beast::tcp_stream>>(beast::tcp_stream(std::move(socket)), core)->run();
      });
    }
    if (!guarded("accept loop", [this] { accept(); })) {
      // Cannot wait for the next connection now (e.g. out of memory): try again shortly.
      auto retry = std::make_shared<net::steady_timer>(ioc, std::chrono::milliseconds(100));
      retry->async_wait([this, retry](beast::error_code wait_error) {
        if (!wait_error && !stopped) {
          guarded("accept loop", [this] { accept(); });
        }
      });
    }
  });
}

void HttpServer::Impl::broadcast() {
  // A failure to stream one round (the backend threw) is logged; the next round comes anyway.
  guarded("stream broadcast", [this] { core.broadcastOnce(); });
  if (stopped) {
    return;
  }
  guarded("stream timer", [this] { scheduleBroadcast(); });
}

void HttpServer::Impl::scheduleBroadcast() {
  const auto period = std::chrono::duration_cast<net::steady_timer::duration>(
      std::chrono::duration<double>(0.5 / std::max(1.0, core.options.stream_hz)));  // twice per snapshot
  const auto now = net::steady_timer::clock_type::now();
  timer.expires_at(timer.expiry() + period > now ? timer.expiry() + period : now + period);
  timer.async_wait([this](beast::error_code error) {
    if (!error) {
      broadcast();
    }
  });
}

HttpServer::HttpServer(Api& api, Backend& backend, HttpServerOptions options)
    : impl_(std::make_unique<Impl>(api, backend, std::move(options))) {
  beast::error_code error;
  const std::string address = impl_->core.options.address == "localhost" ? "127.0.0.1" : impl_->core.options.address;
  const net::ip::address ip = net::ip::make_address(address, error);
  if (error) {
    throw std::runtime_error("cannot listen on '" + impl_->core.options.address + "': not an IP address");
  }
  const tcp::endpoint endpoint(ip, impl_->core.options.port);
  impl_->acceptor.open(endpoint.protocol(), error);
  if (!error) {
    impl_->acceptor.set_option(net::socket_base::reuse_address(true), error);
  }
  if (!error) {
    impl_->acceptor.bind(endpoint, error);
  }
  if (!error) {
    impl_->acceptor.listen(net::socket_base::max_listen_connections, error);
  }
  if (error) {
    throw std::runtime_error("cannot listen on " + address + ":" + std::to_string(impl_->core.options.port) + ": " +
                             error.message());
  }
  impl_->port = impl_->acceptor.local_endpoint().port();
}

HttpServer::~HttpServer() { stop(); }

void HttpServer::start() {
  impl_->accept();
  net::post(impl_->ioc, [this] { impl_->broadcast(); });
  impl_->bulk_work.emplace(impl_->bulk_ioc.get_executor());
  impl_->bulk_thread = std::thread([this] {
    prepareServerThread("reads");
    while (!guarded("long reads thread", [this] { impl_->bulk_ioc.run(); })) {
    }
  });
  for (int i = 0; i < std::max(1, impl_->core.options.threads); ++i) {
    impl_->threads.emplace_back([this] {
      prepareServerThread("io");
      // A handler that throws ends run() with its exception: log it and go on serving.
      while (!guarded("I/O thread", [this] { impl_->ioc.run(); })) {
      }
    });
  }
}

void HttpServer::stop() {
  if (impl_->stopped) {
    return;
  }
  impl_->stopped = true;
  net::post(impl_->ioc, [this] {
    beast::error_code ignored;
    impl_->acceptor.close(ignored);
    impl_->timer.cancel();
  });
  impl_->ioc.stop();
  for (auto& thread : impl_->threads) {
    if (thread.joinable()) {
      thread.join();
    }
  }
  impl_->threads.clear();
  impl_->bulk_work.reset();
  impl_->bulk_ioc.stop();
  if (impl_->bulk_thread.joinable()) {
    impl_->bulk_thread.join();
  }
}

std::uint16_t HttpServer::port() const { return impl_->port; }

std::size_t HttpServer::streamClients() const { return impl_->core.clients(); }

std::uint64_t HttpServer::streamMessagesSent() const { return impl_->core.sent.load(); }

bool HttpServer::isLoopback(const std::string& address) {
  if (address == "localhost") {
    return true;
  }
  beast::error_code error;
  const net::ip::address ip = net::ip::make_address(address, error);
  return !error && ip.is_loopback();
}

}  // namespace costar::server
