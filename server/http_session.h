#pragma once
// INTERNAL to the server's network side (http_server.cpp, http_memory.cpp; Boost.Beast stays
// out of every other file): one HTTP connection and one WebSocket client of the live stream,
// generic over the byte stream they run on. `costar serve` runs them on TCP sockets
// (beast::tcp_stream, with its request timeouts); the end-to-end fuzz target runs the very same
// code on an in-memory stream (beast::test::stream) on one io_context, without a socket or a
// thread hop. What differs between streams is in the three overloads of StreamTraits below.
//
// The behaviour (limits, Host and upgrade checks, answers, the stream's messages) is described
// in http_server.h.

#include <algorithm>
#include <atomic>
#include <boost/asio/dispatch.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/post.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <cctype>
#include <chrono>
#include <deque>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "server/api.h"
#include "server/backend.h"
#include "server/guard.h"
#include "server/http_server.h"

namespace costar::server::detail {

namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
namespace net = boost::asio;

/// A client of the live stream, whatever stream it runs on.
class StreamClient {
 public:
  virtual ~StreamClient() = default;
  /// Thread-safe: queues a message.
  virtual void send(std::shared_ptr<const std::string> message) = 0;
  /// It has had its hello (the stream may go to it).
  virtual bool ready() const = 0;
};

/// What every session of one server shares: the API, the stream's source, the options and the
/// stream's clients. Thread-safe.
struct ServerCore {
  ServerCore(Api& api_, Backend& backend_, HttpServerOptions options_)
      : api(api_), backend(backend_), options(std::move(options_)), loopback(HttpServer::isLoopback(options.address)) {}

  Api& api;
  Backend& backend;
  HttpServerOptions options;
  /// Listening on loopback: only requests addressed to this machine are answered.
  bool loopback = true;
  std::atomic<std::uint64_t> sent{0};
  /// Where long reads (Api::isBulkRead) are answered: a thread of their own for TCP, so that
  /// the I/O threads stay free for the stream and for commands; the sessions' own io_context
  /// in memory. Set by the owner before the first session.
  net::any_io_executor bulk;

  void addClient(const std::shared_ptr<StreamClient>& client);
  /// Sends what the backend has for the stream to every ready client.
  void broadcastOnce();
  /// Clients connected now.
  std::size_t clients() const;
  /// Loopback servers answer only requests addressed to this machine (DNS rebinding).
  bool hostAllowed(const std::string& host_header) const;

 private:
  mutable std::mutex mutex_;
  std::vector<std::weak_ptr<StreamClient>> clients_;
};

/// A Host header's value or an Origin's authority: `host[:port]`.
struct Authority {
  /// Lower case; an IPv6 literal without its brackets, in its shortest form ("::1").
  std::string host;
  std::optional<std::uint16_t> port;
  bool ipv6 = false;
};
/// Parses `name`, `a.b.c.d` or `[v6]`, each with an optional `:port` (1-65535); nullopt when
/// it is anything else ("127.0.0.1evil" parses, as a name; "[::1].evil.com" does not).
std::optional<Authority> parseAuthority(std::string_view text);
/// `localhost`, an IPv4 literal in 127.0.0.0/8 (four decimal parts), or ::1.
bool isLoopback(const Authority& authority);
/// An Origin header: `http://AUTHORITY` or `https://AUTHORITY`; nullopt for anything else
/// ("null", other schemes, a path).
struct Origin {
  std::string scheme;
  Authority authority;
};
std::optional<Origin> parseOrigin(std::string_view text);
/// Whether a WebSocket upgrade may open the stream: no Origin (not a browser), or the page's
/// own origin, i.e. http(s) with the host and port the request's Host names (on a loopback
/// server, a loopback host). A page of another site, or of another port of this machine, is
/// refused; a page served through a proxy (the editor's development server) is its own origin.
bool originAllowed(std::string_view origin, std::string_view host_header, bool loopback);
/// A file of the page under `root` (or 404, or the page saying how to build it).
HttpResponse staticFile(const std::filesystem::path& root, const std::string& target);
/// The answers to one WebSocket message from a client (auth, control, ping; else an error
/// message), as JSON text. An accepted auth sets `authenticated`.
std::vector<std::string> answerStreamMessage(ServerCore& core, const std::string& text, bool& authenticated);

constexpr std::size_t kMaxQueuedMessages = 256;
constexpr auto kRequestTimeout = std::chrono::seconds(30);

// What differs between streams: request timeouts (TCP only: in memory nothing waits) and how
// the server ends its side of a connection.
inline void startRequestTimer(beast::tcp_stream& stream) { stream.expires_after(kRequestTimeout); }
inline void stopRequestTimer(beast::tcp_stream& stream) { stream.expires_never(); }
inline void shutdownSend(beast::tcp_stream& stream) noexcept {
  beast::error_code ignored;
  stream.socket().shutdown(net::ip::tcp::socket::shutdown_send, ignored);
}
template <class Stream>
void startRequestTimer(Stream&) {}
template <class Stream>
void stopRequestTimer(Stream&) {}
template <class Stream>
void shutdownSend(Stream& stream) noexcept {
  stream.close();
}

/// One WebSocket client of the live stream.
template <class Stream>
class StreamSession final : public StreamClient, public std::enable_shared_from_this<StreamSession<Stream>> {
 public:
  StreamSession(Stream&& stream, ServerCore& core) : ws_(std::move(stream)), core_(core) {}

  void run(http::request<http::string_body> request) {
    ws_.set_option(websocket::stream_base::timeout::suggested(beast::role_type::server));
    ws_.read_message_max(64 * 1024);
    ws_.text(true);
    ws_.async_accept(request, beast::bind_front_handler(&StreamSession::onAccept, this->shared_from_this()));
  }

  void send(std::shared_ptr<const std::string> message) override {
    net::post(ws_.get_executor(), [self = this->shared_from_this(), message = std::move(message)]() mutable {
      if (!guarded("WebSocket send", [&] { self->enqueue(std::move(message)); })) {
        self->fail();
      }
    });
  }
  bool ready() const override { return ready_.load(); }

 private:
  void onAccept(beast::error_code error) {
    if (error) {
      return;
    }
    const bool ok = guarded("WebSocket hello", [this] {
      if (!core_.api.options().reads_need_token) {
        enqueue(std::make_shared<const std::string>(core_.backend.helloMessage()));
        ready_ = true;
      }
      read();
    });
    if (!ok) {
      fail();
    }
  }

  void read() { ws_.async_read(buffer_, beast::bind_front_handler(&StreamSession::onRead, this->shared_from_this())); }

  void onRead(beast::error_code error, std::size_t /*bytes*/) {
    if (error) {
      return;  // closed, timed out or oversize: the session ends
    }
    const bool ok = guarded("WebSocket message", [this] {
      const std::string text = beast::buffers_to_string(buffer_.data());
      buffer_.consume(buffer_.size());
      const bool was_authenticated = authenticated_;
      for (std::string& answer : answerStreamMessage(core_, text, authenticated_)) {
        enqueue(std::make_shared<const std::string>(std::move(answer)));
      }
      if (authenticated_ && !was_authenticated && !ready_) {
        enqueue(std::make_shared<const std::string>(core_.backend.helloMessage()));
        ready_ = true;
      }
      read();
    });
    if (!ok) {
      fail();
    }
  }

  void enqueue(std::shared_ptr<const std::string> message) {
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

  /// Ends the session after an error: closes the stream, sends nothing more.
  void fail() noexcept {
    closing_ = true;
    beast::get_lowest_layer(ws_).close();
  }

  void write() {
    ws_.async_write(net::buffer(*queue_.front()),
                    beast::bind_front_handler(&StreamSession::onWrite, this->shared_from_this()));
  }

  void onWrite(beast::error_code error, std::size_t /*bytes*/) {
    if (error) {
      closing_ = true;
      queue_.clear();
      return;
    }
    core_.sent.fetch_add(1);
    queue_.pop_front();
    if (!queue_.empty() && !guarded("WebSocket write", [this] { write(); })) {
      fail();
    }
  }

  websocket::stream<Stream> ws_;
  ServerCore& core_;
  beast::flat_buffer buffer_;
  std::deque<std::shared_ptr<const std::string>> queue_;
  bool authenticated_ = false;
  std::atomic<bool> ready_{false};
  bool closing_ = false;
};

/// One HTTP connection: requests in, answers out, until the client closes, a request says
/// "close", or it upgrades to the live stream.
template <class Stream>
class HttpSession final : public std::enable_shared_from_this<HttpSession<Stream>> {
 public:
  HttpSession(Stream&& stream, ServerCore& core) : stream_(std::move(stream)), core_(core) {}

  void run() {
    net::dispatch(stream_.get_executor(), beast::bind_front_handler(&HttpSession::read, this->shared_from_this()));
  }

 private:
  void read() {
    parser_.emplace();
    parser_->body_limit(core_.options.max_body_bytes);
    parser_->header_limit(8 * 1024);
    startRequestTimer(stream_);
    http::async_read(stream_, buffer_, *parser_,
                     beast::bind_front_handler(&HttpSession::onRead, this->shared_from_this()));
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
      shutdownSend(stream_);
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
      reply(errorResponse(413, "the body is larger than " + std::to_string(core_.options.max_body_bytes) + " bytes"),
            11, false, false);
      return true;
    }
    if (error) {
      reply(errorResponse(400, "malformed HTTP request: " + error.message()), 11, false, false);
      return true;
    }
    http::request<http::string_body> request = parser_->release();
    const std::string host(request[http::field::host]);
    if (!core_.hostAllowed(host)) {
      reply(errorResponse(421,
                          "this server answers only requests whose Host is localhost, 127.x.y.z or [::1] (with "
                          "an optional port): another name for this machine may be a site rebinding its DNS"),
            request.version(), false, false);
      return true;
    }
    const std::string target(request.target());
    if (websocket::is_upgrade(request)) {
      const bool origin_ok = originAllowed(request[http::field::origin], host, core_.loopback);
      if (target.substr(0, target.find('?')) != "/api/stream" || !origin_ok) {
        reply(errorResponse(origin_ok ? 404 : 403,
                            origin_ok ? "the stream is at /api/stream"
                                      : "WebSocket refused: its Origin is not this server's page (http(s), the "
                                        "host and port this request was sent to)"),
              request.version(), false, false);
        return true;
      }
      stopRequestTimer(stream_);
      auto session = std::make_shared<StreamSession<Stream>>(std::move(stream_), core_);
      core_.addClient(session);
      session->run(std::move(request));
      return true;  // the WebSocket session owns the stream now
    }
    const bool head = request.method() == http::verb::head;
    HttpResponse response;
    if (target.starts_with("/api/") || target == "/api") {
      HttpRequest api_request;
      api_request.method = std::string(request.method_string());
      api_request.target = target;
      api_request.body = std::move(request.body());
      api_request.authorization = std::string(request[http::field::authorization]);
      if (Api::isBulkRead(api_request)) {
        answerElsewhere(std::move(api_request), request.version(), request.keep_alive(), head);
        return true;
      }
      response = core_.api.handle(api_request);
      response.headers.emplace_back("Cache-Control", "no-store");
    } else if (request.method() == http::verb::get || head) {
      response = staticFile(core_.options.web_root, target);
    } else {
      response = errorResponse(405, "only GET for the page's files");
    }
    reply(std::move(response), request.version(), request.keep_alive(), head);
    return true;
  }

  /// Answers a long read on the bulk executor, then writes the answer from this session's
  /// own executor. The session lives on in the handlers.
  void answerElsewhere(HttpRequest api_request, unsigned version, bool keep_alive, bool head) {
    net::post(core_.bulk, [self = this->shared_from_this(), api_request = std::move(api_request), version, keep_alive,
                           head]() mutable {
      auto response = std::make_shared<HttpResponse>();
      const bool ok = guarded("HTTP long read", [&] {
        *response = self->core_.api.handle(api_request);
        response->headers.emplace_back("Cache-Control", "no-store");
      });
      if (!ok) {
        *response = errorResponse(500, "internal error while answering the request");
      }
      net::post(self->stream_.get_executor(), [self, response, version, keep_alive, head] {
        if (!guarded("HTTP answer", [&] { self->reply(std::move(*response), version, keep_alive, head); })) {
          shutdownSend(self->stream_);
        }
      });
    });
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
    http::async_write(stream_, *message,
                      [self = this->shared_from_this(), keep_alive](beast::error_code error, std::size_t) {
                        self->response_.reset();
                        if (error || !keep_alive || !guarded("HTTP read", [&] { self->read(); })) {
                          shutdownSend(self->stream_);
                        }
                      });
  }

  Stream stream_;
  ServerCore& core_;
  beast::flat_buffer buffer_;
  std::optional<http::request_parser<http::string_body>> parser_;
  std::shared_ptr<void> response_;
};

}  // namespace costar::server::detail
