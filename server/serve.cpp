#include "server/serve.h"

#include <pthread.h>

#include <csignal>
#include <ostream>

#include "core/paths.h"
#include "server/api.h"
#include "server/auth.h"
#include "server/engine.h"
#include "server/fatal.h"
#include "server/http_server.h"
#include "server/store.h"

namespace costar::server {

std::filesystem::path defaultStoreFile(const std::string& workcell) {
  return workcell::defaultWaypointFile(workcell).parent_path() / "editor.sqlite";
}

Server::Server(ServeOptions options) : options_(std::move(options)) {
  token_ = options_.token_file.empty() ? randomToken() : tokenFromFile(options_.token_file);
  std::unique_ptr<workcell::Workcell> cell = workcell::makeWorkcell(options_.workcell);
  name_ = cell->name();
  description_ = cell->description();
  store_ = std::make_unique<Store>(options_.store.empty() ? defaultStoreFile(name_) : options_.store);
  EngineOptions engine_options;
  engine_options.pace = options_.pace;
  engine_options.stream_hz = options_.stream_hz;
  if (cell->simulation() != nullptr) {
    engine_options.grasp_defaults = dataRoot() / "data/grasps.json";
    if (!options_.workcell.memory_only) {
      engine_options.grasp_taught = workcell::defaultGraspFile(name_);
    }
    // Reset scene: the same cell made again from the same options (scene file, seed).
    engine_options.make_cell = [workcell_options = options_.workcell] {
      return workcell::makeWorkcell(workcell_options);
    };
  }
  engine_ = std::make_unique<Engine>(std::move(cell), store_.get(), engine_options);
  ApiOptions api_options;
  api_options.token = token_;
  api_options.reads_need_token = !HttpServer::isLoopback(options_.address);
  api_options.test_endpoints = options_.test_endpoints;
  api_ = std::make_unique<Api>(*engine_, *store_, api_options);
  HttpServerOptions http_options;
  http_options.address = options_.address;
  http_options.port = options_.port;
  http_options.web_root = options_.web_root.empty() ? dataRoot() / "web/dist" : options_.web_root;
  http_options.threads = options_.threads;
  http_options.stream_hz = options_.stream_hz;
  http_options.max_body_bytes = api_options.max_body_bytes;
  http_ = std::make_unique<HttpServer>(*api_, *engine_, http_options);
  engine_->startThread();
  http_->start();
}

Server::~Server() { stop(); }

void Server::stop() {
  if (http_) {
    http_->stop();
  }
  if (engine_) {
    engine_->shutdown();
  }
}

std::uint16_t Server::port() const { return http_->port(); }

std::string Server::url() const {
  const std::string host =
      options_.address.find(':') != std::string::npos ? "[" + options_.address + "]" : options_.address;
  return "http://" + host + ":" + std::to_string(port()) + "/";
}

int runServe(const ServeOptions& options, std::ostream& out, std::ostream& err) {
  // Every thread started from here on inherits the blocked signals; this one waits for them.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);

  std::unique_ptr<Server> server;
  try {
    server = std::make_unique<Server>(options);
  } catch (const std::exception& e) {
    err << "error: " << e.what() << "\n";
    return 2;
  }
  const bool loopback = HttpServer::isLoopback(options.address);
  out << "costar serve: " << server->description() << "\n";
  out << "  store: " << server->store().file().string() << "\n";
  if (!loopback) {
    err << "warning: listening on " << options.address
        << ", beyond this machine: anyone who can reach it needs the token for every request\n";
  }
  if (options.test_endpoints) {
    err << "warning: TEST ONLY endpoints are on (--test-endpoints): never use this on a robot\n";
  }
  // As notebook servers do: the address to open carries the token (in the fragment, which a
  // browser never sends to the server), whether the token was made now or read from a file.
  out << "  open the editor at " << server->url() << "#token=" << server->token() << "\n";
  if (!options.token_file.empty()) {
    out << "  token from " << options.token_file.string() << "\n";
  }
  // From here on, a crash stops the arm before the process dies. Installed before the address
  // is announced, so that whoever reads it (a person, a test) finds the handlers in place.
  const FatalStop fatal_stop(server->engine());
  out << "listening on " << server->url() << "\n" << std::flush;
  int signal = 0;
  sigwait(&signals, &signal);
  out << "costar serve: stopping (signal " << signal << ")\n" << std::flush;
  server->stop();
  return 0;
}

}  // namespace costar::server
