#include "server/http_memory.h"

#include <boost/beast/_experimental/test/stream.hpp>

#include "server/http_session.h"

namespace costar::server {

namespace test = boost::beast::test;

struct MemoryHttpServer::Impl {
  Impl(Api& api, Backend& backend, HttpServerOptions options) : core(api, backend, std::move(options)) {
    core.bulk = ioc.get_executor();  // long reads on the same thread, polled like the rest
  }
  detail::ServerCore core;
  detail::net::io_context ioc;
};

MemoryHttpServer::MemoryHttpServer(Api& api, Backend& backend, HttpServerOptions options)
    : impl_(std::make_unique<Impl>(api, backend, std::move(options))) {}

MemoryHttpServer::~MemoryHttpServer() = default;

MemoryHttpServer::Exchange MemoryHttpServer::exchange(std::string_view input, std::size_t read_size) {
  auto& ioc = impl_->ioc;
  // Runs every ready handler (an io_context out of work stops: restart it first).
  const auto poll = [&ioc] {
    ioc.restart();
    ioc.poll();
  };
  Exchange result;
  {
    test::stream server_side(ioc);
    test::stream client(ioc);
    client.connect(server_side);
    if (read_size > 0) {
      server_side.read_size(read_size);
    }
    // The client's bytes, then its end of the stream (a half-close: answers still reach it).
    server_side.append(input);
    server_side.close_remote();
    std::make_shared<detail::HttpSession<test::stream>>(std::move(server_side), impl_->core)->run();

    // Run every ready handler; while a stream client is there, the broadcaster runs after
    // every 16th (as its timer would now and then: not so often that the stream floods).
    ioc.restart();
    for (std::size_t handlers = 1; ioc.poll_one() > 0; ++handlers) {
      if (handlers % 16 == 0 && impl_->core.clients() > 0) {
        impl_->core.broadcastOnce();
      }
    }
    result.output = std::string(client.str());
    client.clear();

    // Closed: a read on the client's side ends at once with the end of the stream.
    bool ended = false;
    char byte = 0;
    client.async_read_some(detail::net::buffer(&byte, 1), [&ended](detail::beast::error_code error, std::size_t) {
      ended = error == detail::net::error::eof;
    });
    poll();
    result.closed = ended;
    client.close();  // ends a session that still waits
    poll();
  }
  poll();
  return result;
}

std::size_t MemoryHttpServer::streamClients() const { return impl_->core.clients(); }

}  // namespace costar::server
