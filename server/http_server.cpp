#include "server/http_server.h"

#include <algorithm>
#include <atomic>
#include <boost/asio/dispatch.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/strand.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <deque>
#include <fstream>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <thread>
#include <vector>

#include "server/api.h"
#include "server/backend.h"
#include "server/guard.h"
#include "server/plan_json.h"

namespace costar::server {

namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
namespace net = boost::asio;
using tcp = net::ip::tcp;

namespace {

constexpr std::size_t kMaxQueuedMessages = 256;
constexpr auto kRequestTimeout = std::chrono::seconds(30);

std::string lower(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(), [](unsigned char c) { return std::tolower(c); });
  return text;
}

/// The host part of a Host header or an Origin's authority ("[::1]:8080" -> "[::1]").
std::string hostOf(std::string authority) {
  if (const auto scheme = authority.find("://"); scheme != std::string::npos) {
    authority = authority.substr(scheme + 3);
  }
  if (const auto slash = authority.find('/'); slash != std::string::npos) {
    authority = authority.substr(0, slash);
  }
  if (!authority.empty() && authority.front() == '[') {
    const auto close = authority.find(']');
    return lower(close == std::string::npos ? authority : authority.substr(0, close + 1));
  }
  if (const auto colon = authority.rfind(':'); colon != std::string::npos) {
    authority = authority.substr(0, colon);
  }
  return lower(authority);
}

bool loopbackHost(const std::string& host) {
  return host == "localhost" || host == "[::1]" || host == "::1" || host.starts_with("127.");
}

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

}  // namespace

/// One WebSocket client of the live stream.
class StreamSession : public std::enable_shared_from_this<StreamSession> {
 public:
  StreamSession(tcp::socket&& socket, HttpServer::Impl& server) : ws_(std::move(socket)), server_(server) {}

  void run(http::request<http::string_body> request);
  /// Thread-safe: queues a message.
  void send(std::shared_ptr<const std::string> message);
  bool ready() const { return ready_.load(); }

 private:
  void onAccept(beast::error_code error);
  void read();
  void onRead(beast::error_code error, std::size_t bytes);
  void handleMessage(const std::string& text);
  void enqueue(std::shared_ptr<const std::string> message);
  /// Ends the session after an error: closes the socket, sends nothing more.
  void fail() noexcept;
  void write();
  void onWrite(beast::error_code error, std::size_t bytes);

  websocket::stream<beast::tcp_stream> ws_;
  HttpServer::Impl& server_;
  beast::flat_buffer buffer_;
  std::deque<std::shared_ptr<const std::string>> queue_;
  bool authenticated_ = false;
  std::atomic<bool> ready_{false};
  bool closing_ = false;
};

struct HttpServer::Impl {
  Impl(Api& api_, Backend& backend_, HttpServerOptions options_)
      : api(api_), backend(backend_), options(std::move(options_)), acceptor(ioc), timer(ioc) {}

  Api& api;
  Backend& backend;
  HttpServerOptions options;
  bool loopback = true;
  net::io_context ioc;
  tcp::acceptor acceptor;
  net::steady_timer timer;
  std::vector<std::thread> threads;
  mutable std::mutex sessions_mutex;
  std::vector<std::weak_ptr<StreamSession>> sessions;
  std::atomic<std::uint64_t> sent{0};
  std::atomic<bool> stopped{false};
  std::uint16_t port = 0;

  void accept();
  /// Sends what the backend has for the stream, then waits for the next round.
  void broadcast();
  void broadcastOnce();
  void scheduleBroadcast();
  void addSession(const std::shared_ptr<StreamSession>& session) {
    const std::lock_guard lock(sessions_mutex);
    sessions.push_back(session);
  }
  /// Loopback servers answer only requests addressed to this machine (DNS rebinding).
  bool hostAllowed(const std::string& host_header) const { return !loopback || loopbackHost(hostOf(host_header)); }
};

/// One HTTP connection.
class HttpSession : public std::enable_shared_from_this<HttpSession> {
 public:
  HttpSession(tcp::socket&& socket, HttpServer::Impl& server) : stream_(std::move(socket)), server_(server) {}

  void run() {
    net::dispatch(stream_.get_executor(), beast::bind_front_handler(&HttpSession::read, shared_from_this()));
  }

 private:
  void read() {
    parser_.emplace();
    parser_->body_limit(server_.options.max_body_bytes);
    parser_->header_limit(8 * 1024);
    stream_.expires_after(kRequestTimeout);
    http::async_read(stream_, buffer_, *parser_, beast::bind_front_handler(&HttpSession::onRead, shared_from_this()));
  }

  void onRead(beast::error_code error, std::size_t bytes) {
    // Whatever a handler throws becomes a 500 answer (or, failing that, a closed connection).
    bool answered = false;
    const bool ok = guarded("HTTP request", [&] { answered = handleRead(error, bytes); });
    if (!ok && !answered) {
      guarded("HTTP error answer", [&] {
        answered = true;
        reply(errorResponse(500, "internal error while answering the request"), 11, false, false);
      });
    }
    if (!answered) {
      close();
    }
  }

  /// Answers what was read. Returns false when nothing was (or will be) written: the caller
  /// closes the connection.
  bool handleRead(beast::error_code error, std::size_t /*bytes*/) {
    if (error == http::error::end_of_stream || error == beast::error::timeout || error == net::error::eof ||
        error == net::error::connection_reset || error == net::error::operation_aborted) {
      return false;
    }
    if (error == http::error::body_limit) {
      reply(errorResponse(413, "the body is larger than " + std::to_string(server_.options.max_body_bytes) + " bytes"),
            11, false, false);
      return true;
    }
    if (error) {
      reply(errorResponse(400, "malformed HTTP request: " + error.message()), 11, false, false);
      return true;
    }
    http::request<http::string_body> request = parser_->release();
    const std::string host(request[http::field::host]);
    if (!server_.hostAllowed(host)) {
      reply(errorResponse(421, "this server answers only requests to 127.0.0.1 or localhost"), request.version(), false,
            false);
      return true;
    }
    const std::string target(request.target());
    if (websocket::is_upgrade(request)) {
      const std::string origin(request[http::field::origin]);
      const bool origin_ok =
          origin.empty() || (server_.loopback ? loopbackHost(hostOf(origin)) : hostOf(origin) == hostOf(host));
      if (target.substr(0, target.find('?')) != "/api/stream" || !origin_ok) {
        reply(errorResponse(origin_ok ? 404 : 403,
                            origin_ok ? "the stream is at /api/stream" : "WebSocket from another site refused"),
              request.version(), false, false);
        return true;
      }
      stream_.expires_never();
      auto session = std::make_shared<StreamSession>(stream_.release_socket(), server_);
      server_.addSession(session);
      session->run(std::move(request));
      return true;  // the WebSocket session owns the socket now
    }
    const bool head = request.method() == http::verb::head;
    HttpResponse response;
    if (target.starts_with("/api/") || target == "/api") {
      HttpRequest api_request;
      api_request.method = std::string(request.method_string());
      api_request.target = target;
      api_request.body = std::move(request.body());
      api_request.authorization = std::string(request[http::field::authorization]);
      response = server_.api.handle(api_request);
      response.headers.emplace_back("Cache-Control", "no-store");
    } else if (request.method() == http::verb::get || head) {
      response = staticFile(server_.options.web_root, target);
    } else {
      response = errorResponse(405, "only GET for the page's files");
    }
    reply(std::move(response), request.version(), request.keep_alive(), head);
    return true;
  }

  void reply(HttpResponse response, unsigned version, bool keep_alive, bool head) {
    auto message = std::make_shared<http::response<http::string_body>>();
    message->version(version);
    message->result(static_cast<unsigned>(response.status));
    message->set(http::field::server, "costar");
    message->set(http::field::content_type, response.content_type);
    message->set("X-Content-Type-Options", "nosniff");
    message->set("X-Frame-Options", "DENY");
    for (const auto& [name, value] : response.headers) {
      message->set(name, value);
    }
    message->keep_alive(keep_alive);
    const std::size_t length = response.body.size();
    if (!head) {
      message->body() = std::move(response.body);
    }
    message->content_length(length);
    response_ = message;
    http::async_write(stream_, *message, [self = shared_from_this(), keep_alive](beast::error_code error, std::size_t) {
      self->response_.reset();
      if (error || !keep_alive || !guarded("HTTP read", [&] { self->read(); })) {
        self->close();
      }
    });
  }

  void close() noexcept {
    beast::error_code ignored;
    stream_.socket().shutdown(tcp::socket::shutdown_send, ignored);
  }

  beast::tcp_stream stream_;
  HttpServer::Impl& server_;
  beast::flat_buffer buffer_;
  std::optional<http::request_parser<http::string_body>> parser_;
  std::shared_ptr<void> response_;
};

void StreamSession::run(http::request<http::string_body> request) {
  ws_.set_option(websocket::stream_base::timeout::suggested(beast::role_type::server));
  ws_.read_message_max(64 * 1024);
  ws_.text(true);
  ws_.async_accept(request, beast::bind_front_handler(&StreamSession::onAccept, shared_from_this()));
}

void StreamSession::onAccept(beast::error_code error) {
  if (error) {
    return;
  }
  const bool ok = guarded("WebSocket hello", [this] {
    if (!server_.api.options().reads_need_token) {
      enqueue(std::make_shared<const std::string>(server_.backend.helloMessage()));
      ready_ = true;
    }
    read();
  });
  if (!ok) {
    fail();
  }
}

void StreamSession::fail() noexcept {
  closing_ = true;
  beast::get_lowest_layer(ws_).close();
}

void StreamSession::read() {
  ws_.async_read(buffer_, beast::bind_front_handler(&StreamSession::onRead, shared_from_this()));
}

void StreamSession::onRead(beast::error_code error, std::size_t /*bytes*/) {
  if (error) {
    return;  // closed, timed out or oversize: the session ends
  }
  const bool ok = guarded("WebSocket message", [this] {
    const std::string text = beast::buffers_to_string(buffer_.data());
    buffer_.consume(buffer_.size());
    handleMessage(text);
    read();
  });
  if (!ok) {
    fail();
  }
}

void StreamSession::handleMessage(const std::string& text) {
  using nlohmann::json;
  const auto answer = [this](json message) {
    enqueue(std::make_shared<const std::string>(message.dump(-1, ' ', false, json::error_handler_t::replace)));
  };
  json message;
  try {
    message = parseRequestJson(text, 16);
  } catch (const RequestError& e) {
    answer({{"type", "error"}, {"error", e.what()}});
    return;
  }
  if (!message.is_object() || !message.contains("type") || !message["type"].is_string()) {
    answer({{"type", "error"}, {"error", "a message is an object with a 'type'"}});
    return;
  }
  const std::string type = message["type"].get<std::string>();
  if (type == "auth") {
    const bool ok = message.contains("token") && message["token"].is_string() &&
                    server_.api.tokenMatches(message["token"].get_ref<const std::string&>());
    answer({{"type", "auth"}, {"ok", ok}});
    if (ok && !authenticated_) {
      authenticated_ = true;
      if (!ready_) {
        enqueue(std::make_shared<const std::string>(server_.backend.helloMessage()));
        ready_ = true;
      }
    }
    return;
  }
  if (type == "control") {
    if (!authenticated_) {
      answer({{"type", "error"}, {"error", "commands need the token: send {\"type\":\"auth\",\"token\":...} first"}});
      return;
    }
    static const std::map<std::string, RunControl> kActions = {{"pause", RunControl::kPause},
                                                               {"resume", RunControl::kResume},
                                                               {"step", RunControl::kStep},
                                                               {"stop", RunControl::kStop}};
    const auto it = message.contains("action") && message["action"].is_string()
                        ? kActions.find(message["action"].get<std::string>())
                        : kActions.end();
    if (it == kActions.end()) {
      answer({{"type", "error"}, {"error", "action must be pause, resume, step or stop"}});
      return;
    }
    const bool ok = server_.backend.control(it->second);
    answer({{"type", "control"}, {"action", it->first}, {"ok", ok}});
    return;
  }
  if (type == "ping") {
    answer({{"type", "pong"}});
    return;
  }
  answer({{"type", "error"}, {"error", "unknown message type"}});
}

void StreamSession::send(std::shared_ptr<const std::string> message) {
  net::post(ws_.get_executor(), [self = shared_from_this(), message = std::move(message)]() mutable {
    if (!guarded("WebSocket send", [&] { self->enqueue(std::move(message)); })) {
      self->fail();
    }
  });
}

void StreamSession::enqueue(std::shared_ptr<const std::string> message) {
  if (closing_) {
    return;
  }
  if (queue_.size() >= kMaxQueuedMessages) {
    fail();  // too slow: drop it; it reconnects and starts from a fresh hello
    return;
  }
  queue_.push_back(std::move(message));
  if (queue_.size() == 1) {
    write();
  }
}

void StreamSession::write() {
  ws_.async_write(net::buffer(*queue_.front()), beast::bind_front_handler(&StreamSession::onWrite, shared_from_this()));
}

void StreamSession::onWrite(beast::error_code error, std::size_t /*bytes*/) {
  if (error) {
    closing_ = true;
    queue_.clear();
    return;
  }
  server_.sent.fetch_add(1);
  queue_.pop_front();
  if (!queue_.empty() && !guarded("WebSocket write", [this] { write(); })) {
    fail();
  }
}

void HttpServer::Impl::accept() {
  acceptor.async_accept(net::make_strand(ioc), [this](beast::error_code error, tcp::socket socket) {
    if (error == net::error::operation_aborted || !acceptor.is_open()) {
      return;
    }
    if (!error) {
      guarded("accepting a connection", [&] { std::make_shared<HttpSession>(std::move(socket), *this)->run(); });
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
  guarded("stream broadcast", [this] { broadcastOnce(); });
  if (stopped) {
    return;
  }
  guarded("stream timer", [this] { scheduleBroadcast(); });
}

void HttpServer::Impl::broadcastOnce() {
  std::vector<std::shared_ptr<StreamSession>> live;
  {
    const std::lock_guard lock(sessions_mutex);
    std::erase_if(sessions, [](const std::weak_ptr<StreamSession>& session) { return session.expired(); });
    for (const auto& weak : sessions) {
      if (auto session = weak.lock(); session && session->ready()) {
        live.push_back(std::move(session));
      }
    }
  }
  for (std::string& text : backend.drainStream()) {
    auto message = std::make_shared<const std::string>(std::move(text));
    for (const auto& session : live) {
      session->send(message);
    }
  }
}

void HttpServer::Impl::scheduleBroadcast() {
  const auto period = std::chrono::duration_cast<net::steady_timer::duration>(
      std::chrono::duration<double>(0.5 / std::max(1.0, options.stream_hz)));  // twice per snapshot
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
  impl_->loopback = isLoopback(impl_->options.address);
  beast::error_code error;
  const std::string address = impl_->options.address == "localhost" ? "127.0.0.1" : impl_->options.address;
  const net::ip::address ip = net::ip::make_address(address, error);
  if (error) {
    throw std::runtime_error("cannot listen on '" + impl_->options.address + "': not an IP address");
  }
  const tcp::endpoint endpoint(ip, impl_->options.port);
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
    throw std::runtime_error("cannot listen on " + address + ":" + std::to_string(impl_->options.port) + ": " +
                             error.message());
  }
  impl_->port = impl_->acceptor.local_endpoint().port();
}

HttpServer::~HttpServer() { stop(); }

void HttpServer::start() {
  impl_->accept();
  net::post(impl_->ioc, [this] { impl_->broadcast(); });
  for (int i = 0; i < std::max(1, impl_->options.threads); ++i) {
    impl_->threads.emplace_back([this] {
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
}

std::uint16_t HttpServer::port() const { return impl_->port; }

std::size_t HttpServer::streamClients() const {
  const std::lock_guard lock(impl_->sessions_mutex);
  return static_cast<std::size_t>(std::count_if(impl_->sessions.begin(), impl_->sessions.end(),
                                                [](const auto& session) { return !session.expired(); }));
}

std::uint64_t HttpServer::streamMessagesSent() const { return impl_->sent.load(); }

bool HttpServer::isLoopback(const std::string& address) {
  if (address == "localhost") {
    return true;
  }
  beast::error_code error;
  const net::ip::address ip = net::ip::make_address(address, error);
  return !error && ip.is_loopback();
}

}  // namespace costar::server
