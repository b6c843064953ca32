#pragma once
// The server's last line against exceptions: every thread body and every asynchronous handler
// of the server runs inside guarded(), so an exception becomes a logged error (and, where
// there is a request, an error answer), never std::terminate.

#include <exception>
#include <string_view>

namespace costar::server {

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
