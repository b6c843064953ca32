#pragma once
// `costar serve`: the workcell, the store, the engine, the API and the network, put together.

#include <cstdint>
#include <filesystem>
#include <iosfwd>
#include <memory>
#include <string>

#include "workcell/workcell.h"

namespace costar::server {

class Engine;
class Store;
class HttpServer;
class Api;

struct ServeOptions {
  workcell::WorkcellOptions workcell;
  /// Where to listen: loopback unless asked otherwise.
  std::string address = "127.0.0.1";
  /// 0: any free port.
  std::uint16_t port = 8080;
  /// The SQLite store (default: beside the workcell's waypoint file, editor.sqlite).
  std::filesystem::path store;
  /// Read the token from this file (mode 0600), or create it there; empty: a random token,
  /// printed.
  std::filesystem::path token_file;
  /// The built page (default: web/dist under the data root).
  std::filesystem::path web_root;
  /// Simulated seconds per wall second (simulated cells); 0: runs as fast as possible.
  double pace = 1.0;
  double stream_hz = 20.0;
  /// I/O threads (a request waiting for the engine holds one).
  int threads = 4;
  /// TEST ONLY: GET /api/test/ground_truth (the simulator's true state), for end-to-end tests.
  bool test_endpoints = false;
};

/// A running server. Construction opens the workcell and the store and binds the address;
/// the server runs until stop() or destruction.
class Server {
 public:
  /// @throws std::exception with a message for the user (unknown workcell, bad token file,
  /// address in use, unreadable store).
  explicit Server(ServeOptions options);
  ~Server();
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;

  std::uint16_t port() const;
  const std::string& token() const { return token_; }
  /// http://ADDRESS:PORT/
  std::string url() const;
  const ServeOptions& options() const { return options_; }
  Engine& engine() { return *engine_; }
  Store& store() { return *store_; }
  HttpServer& http() { return *http_; }
  /// The cell's name and its description (the engine owns the cell: a scene reset makes it anew).
  const std::string& name() const { return name_; }
  const std::string& description() const { return description_; }
  /// Stops serving and ticking (the active run is stopped; its operations cancelled).
  void stop();

 private:
  ServeOptions options_;
  std::string token_;
  std::string name_;
  std::string description_;
  std::unique_ptr<Store> store_;
  std::unique_ptr<Engine> engine_;
  std::unique_ptr<Api> api_;
  std::unique_ptr<HttpServer> http_;
};

/// The default store file for a workcell.
std::filesystem::path defaultStoreFile(const std::string& workcell);

/// Runs a server until SIGINT or SIGTERM, printing where to open the editor to `out`.
/// Returns the process exit code (0, or 2 when it cannot start).
int runServe(const ServeOptions& options, std::ostream& out, std::ostream& err);

}  // namespace costar::server
