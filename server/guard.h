#pragma once
// The server's last line against exceptions: every thread body and every asynchronous handler
// of the server runs inside guarded(), so an exception becomes a logged error (and, where
// there is a request, an error answer), never std::terminate.

#include <exception>
#include <string_view>

namespace costar::server {

/// Prepares the calling thread for the fatal path (fatal.h): an alternate signal stack, so that
/// the handler that stops the arm runs even when this thread's own stack is what overflowed,
/// and a role the fatal message names (`io`, `engine`; threads other than the main one are
/// named `costar-<role>` too, as `top -H` shows them). Call it first in every thread the server
/// starts; the stack is freed when the thread ends. A thread that has an alternate stack
/// already (a sanitizer's) keeps it. `role` must be a string literal.
void prepareServerThread(const char* role) noexcept;

/// The calling thread's role given to prepareServerThread(), or nullptr. Async-signal-safe.
const char* serverThreadRole() noexcept;

/// Whether `address` lies within a page or so of the end of the calling thread's stack (as
/// recorded by prepareServerThread): a fault there is a stack overflow. Async-signal-safe.
bool nearStackLimit(const void* address) noexcept;

/// Logs "costar serve: <where>: <what>" as an error. Never throws.
void logServerError(std::string_view where, std::string_view what) noexcept;

/// Runs `body`; an exception it throws is logged (naming `where`) and swallowed.
/// Returns false when it threw.
template <typename F>
bool guarded(std::string_view where, F&& body) noexcept {
  try {
    body();
    return true;
  } catch (const std::exception& error) {
    logServerError(where, error.what());
  } catch (...) {
    logServerError(where, "an exception that is not a std::exception");
  }
  return false;
}

}  // namespace costar::server
