#pragma once
// SIGINT (Ctrl-C), SIGTERM (what a batch scheduler sends at its time limit) and SIGHUP (the
// terminal or the ssh session closed) while a run or a batch of trials goes on: the handler only
// records the signal; the work polls stopRequested(), cancels what runs (the arm stops) and keeps
// what is done. The exit code is 128 + the signal (130, 143, 129), as a shell reports a process
// the signal ended.

#include <atomic>
#include <csignal>
#include <string>

namespace costar::cli {

/// SIGPIPE ignored for the whole process (and the costar-robot it runs): a standard output
/// nobody reads any more (`costar trials ... | head -3`) makes writes fail (EPIPE) instead of
/// killing the process mid-motion, before its --json is written.
void ignoreBrokenPipes();

class StopSignals {
 public:
  /// Catches SIGINT, SIGTERM and SIGHUP until destroyed (the previous handlers are put back then).
  StopSignals();
  StopSignals(const StopSignals&) = delete;
  StopSignals& operator=(const StopSignals&) = delete;
  ~StopSignals();

  /// Set by the first signal (stays set); for the work to poll.
  static const std::atomic<bool>& stopRequested();
  /// The first signal received, 0 when none.
  static int received();
  /// "SIGINT (Ctrl-C)", "SIGTERM" or "SIGHUP (the terminal closed)".
  static std::string name(int signal);
  /// 128 + the signal.
  static int exitCode(int signal) { return 128 + signal; }

 private:
  struct sigaction previous_int_ {};
  struct sigaction previous_term_ {};
  struct sigaction previous_hup_ {};
};

}  // namespace costar::cli
