#include "server/fatal.h"

#include <signal.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <stdexcept>
#include <string>

#include "server/engine.h"
#include "server/guard.h"

namespace costar::server {
namespace {

constexpr int kSignals[] = {SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT};
constexpr int kSignalCount = sizeof(kSignals) / sizeof(kSignals[0]);

std::atomic<Engine*> g_engine{nullptr};
std::atomic<long> g_wait_ms{3000};
std::atomic<bool> g_dying{false};
std::terminate_handler g_previous_terminate = nullptr;
struct sigaction g_previous[kSignalCount];

void say(const char* text) noexcept {
  const std::size_t length = std::strlen(text);
  std::size_t written = 0;
  while (written < length) {
    const ssize_t n = ::write(STDERR_FILENO, text + written, length - written);
    if (n <= 0) {
      return;
    }
    written += static_cast<std::size_t>(n);
  }
}

void sleepMs(long ms) noexcept {
  timespec duration{ms / 1000, (ms % 1000) * 1'000'000L};
  while (::nanosleep(&duration, &duration) != 0) {
  }
}

/// Stops the arm through the engine (once per process). Async-signal-safe.
void stopTheArm() noexcept {
  if (g_dying.exchange(true)) {
    return;
  }
  Engine* engine = g_engine.load();
  if (engine == nullptr) {
    return;
  }
  if (!engine->runActive()) {
    say("costar serve: no run was active: the arm was not moving under a plan\n");
    return;
  }
  if (const char* role = serverThreadRole(); role != nullptr && std::strcmp(role, "engine") == 0) {
    // The thread that would stop the run is this one: waiting for it would only delay dying.
    say("costar serve: the engine thread, which commands the arm, is the one that failed: it commands nothing "
        "more (the simulated cell stops with it)\n");
    return;
  }
  say("costar serve: stopping the active run first (the arm decelerates and stops)\n");
  // Ask again while waiting: a run that starts meanwhile is stopped too. Ended: not active in
  // three checks in a row.
  const long steps = std::max(1L, g_wait_ms.load() / 10);
  int idle_checks = 0;
  for (long i = 0; i < steps && idle_checks < 3; ++i) {
    engine->requestStop();
    sleepMs(10);
    idle_checks = engine->runActive() ? 0 : idle_checks + 1;
  }
  say(idle_checks >= 3 ? "costar serve: the active run was stopped (its operations cancelled)\n"
                       : "costar serve: the active run did not end in time; the arm may still move\n");
}

int indexOf(int signal) noexcept {
  for (int i = 0; i < kSignalCount; ++i) {
    if (kSignals[i] == signal) {
      return i;
    }
  }
  return -1;
}

void onSignal(int signal, siginfo_t* info, void* /*context*/) {
  say("costar serve: fatal signal ");
  say(signal == SIGSEGV   ? "SIGSEGV"
      : signal == SIGBUS  ? "SIGBUS"
      : signal == SIGFPE  ? "SIGFPE"
      : signal == SIGILL  ? "SIGILL"
      : signal == SIGABRT ? "SIGABRT"
                          : "?");
  // This handler runs on the thread's alternate stack (prepareServerThread), so it runs even
  // when the thread's own stack is what overflowed.
  if (signal == SIGSEGV && info != nullptr && info->si_code > 0 && nearStackLimit(info->si_addr)) {
    say(" (a stack overflow)");
  }
  if (const char* role = serverThreadRole()) {
    say(" in the ");
    say(role);
    say(" thread");
  }
  say("\n");
  stopTheArm();
  // Die as the process would have: the previous action (the default, or e.g. a sanitizer's).
  const int index = indexOf(signal);
  if (index >= 0) {
    ::sigaction(signal, &g_previous[index], nullptr);
  } else {
    ::signal(signal, SIG_DFL);
  }
  if (info == nullptr || info->si_code <= 0) {
    ::raise(signal);  // sent (kill, raise, abort): send it again
  }
  // A fault: returning runs the faulting instruction again, which the previous action sees
  // with its true address.
}

void onTerminate() {
  say("costar serve: fatal error (std::terminate)");
  if (const std::exception_ptr current = std::current_exception()) {
    try {
      std::rethrow_exception(current);
    } catch (const std::exception& error) {
      say(": ");
      say(error.what());
    } catch (...) {
      say(": an exception that is not a std::exception");
    }
  }
  say("\n");
  stopTheArm();
  std::abort();  // the SIGABRT handler knows the arm is handled
}

}  // namespace

FatalStop::FatalStop(Engine& engine, std::chrono::milliseconds wait) {
  if (g_engine.exchange(&engine) != nullptr) {
    throw std::logic_error("FatalStop: one at a time");
  }
  prepareServerThread("main");
  g_wait_ms = static_cast<long>(wait.count());
  g_dying = false;
  g_previous_terminate = std::set_terminate(onTerminate);
  struct sigaction action {};
  action.sa_sigaction = onSignal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_SIGINFO | SA_ONSTACK;  // on the alternate stack where the thread has one
  for (int i = 0; i < kSignalCount; ++i) {
    ::sigaction(kSignals[i], &action, &g_previous[i]);
  }
}

FatalStop::~FatalStop() {
  for (int i = 0; i < kSignalCount; ++i) {
    ::sigaction(kSignals[i], &g_previous[i], nullptr);
  }
  std::set_terminate(g_previous_terminate);
  g_engine = nullptr;
}

}  // namespace costar::server
