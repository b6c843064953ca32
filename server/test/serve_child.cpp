// TEST ONLY: `costar serve` without the CLI around it, for tests that start a server as a child
// process and kill it (kill_test.cpp). Arguments: --NAME VALUE pairs of ServeOptions
// (workcell, scene, waypoints, store, token-file, pace, port, memory-only) and the flag
// --test-endpoints and --test-oracle-perception. Prints what `costar serve` prints, including "listening on URL".
// --test-terminate-on-sigusr1: on SIGUSR1 an exception escapes a thread (std::terminate), to
// test that the arm is stopped before the process dies (fatal_test.cpp).
// --test-overflow-on-sigusr2: a thread sent SIGUSR2 (tgkill) recurses until its stack
// overflows, to test that the fatal path runs on such a thread too (fatal_test.cpp).

#include <pthread.h>
#include <signal.h>

#include <cstring>
#include <iostream>
#include <stdexcept>
#include <string>
#include <thread>

#include "server/serve.h"

namespace {

/// Recurses until the stack runs out: each frame holds a buffer the compiler cannot drop.
__attribute__((noinline)) int overflowTheStack(int depth) {
  volatile char frame[1024];
  frame[0] = static_cast<char>(depth);
  if (depth < 0) {  // never: keeps the recursion from being proven infinite
    return 0;
  }
  return overflowTheStack(depth + 1) + frame[0];
}

void onSigusr2(int /*signal*/) { overflowTheStack(0); }

}  // namespace

int main(int argc, char** argv) {
  costar::server::ServeOptions options;
  options.port = 0;
  for (int i = 1; i < argc; ++i) {
    const std::string key = argv[i];
    if (key == "--test-endpoints") {
      options.test_endpoints = true;
      continue;
    }
    if (key == "--memory-only") {
      options.workcell.memory_only = true;
      continue;
    }
    if (key == "--test-terminate-on-sigusr1") {
      // Blocked here, so in every thread the server starts; this one waits for it.
      sigset_t usr1;
      sigemptyset(&usr1);
      sigaddset(&usr1, SIGUSR1);
      pthread_sigmask(SIG_BLOCK, &usr1, nullptr);
      std::thread([usr1] {
        int signal = 0;
        sigwait(&usr1, &signal);
        throw std::runtime_error("TEST: an exception escapes a thread");
      }).detach();
      continue;
    }
    if (key == "--test-overflow-on-sigusr2") {
      // Runs on the thread's own stack (no SA_ONSTACK): what overflows is that stack.
      struct sigaction action {};
      action.sa_handler = onSigusr2;
      sigemptyset(&action.sa_mask);
      sigaction(SIGUSR2, &action, nullptr);
      continue;
    }
    if (key == "--test-oracle-perception") {  // TEST ONLY: true part poses as object symbols
      options.workcell.test_oracle_perception = true;
      continue;
    }
    if (i + 1 >= argc) {
      std::cerr << "serve_child: " << key << " needs a value\n";
      return 2;
    }
    const std::string value = argv[++i];
    if (key == "--workcell") {
      options.workcell.name = value;
    } else if (key == "--scene") {
      options.workcell.scene = value;
    } else if (key == "--waypoints") {
      options.workcell.waypoints = value;
    } else if (key == "--store") {
      options.store = value;
    } else if (key == "--token-file") {
      options.token_file = value;
    } else if (key == "--pace") {
      options.pace = std::stod(value);
    } else if (key == "--port") {
      options.port = static_cast<std::uint16_t>(std::stoi(value));
    } else {
      std::cerr << "serve_child: unknown option " << key << "\n";
      return 2;
    }
  }
  return costar::server::runServe(options, std::cout, std::cerr);
}
