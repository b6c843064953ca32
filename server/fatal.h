#pragma once
// The last act of a dying server: stop the arm. While a FatalStop exists, std::terminate and
// the fatal signals (SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT) first ask the engine to stop
// the active run (which cancels its operations: the arm decelerates and stops) and wait up to
// `wait` for the run to end, saying so on stderr; then the process dies as it would have (the
// signal's previous handler, or abort()). The signal path is async-signal-safe: it only sets
// and reads the engine's atomics, sleeps and write()s. It runs on the faulting thread's
// alternate signal stack (guard.h: prepareServerThread, which every thread of the server calls
// first), so a stack overflow stops the arm too, and it says so ("a stack overflow in the io
// thread"). When the failing thread is the engine's, which would stop the run, it says that
// nothing commands the arm any more and does not wait.

#include <chrono>

namespace costar::server {

class Engine;

class FatalStop {
 public:
  /// One at a time (the handlers are process-wide). `engine` must outlive this object.
  explicit FatalStop(Engine& engine, std::chrono::milliseconds wait = std::chrono::seconds(3));
  /// Restores the previous terminate handler and signal actions.
  ~FatalStop();
  FatalStop(const FatalStop&) = delete;
  FatalStop& operator=(const FatalStop&) = delete;
};

}  // namespace costar::server
