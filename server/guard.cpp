#include "server/guard.h"

#include <spdlog/spdlog.h>

#include <cstdio>

namespace costar::server {

void logServerError(std::string_view where, std::string_view what) noexcept {
  try {
    spdlog::error("costar serve: {}: {}", where, what);
  } catch (...) {
    std::fputs("costar serve: an error that could not be logged\n", stderr);
  }
}

}  // namespace costar::server
