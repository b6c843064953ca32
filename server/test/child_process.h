#pragma once
// TEST ONLY: a server child process (serve_child) for tests that kill it or make it crash.

#include <fcntl.h>
#include <signal.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace costar::server::testing {

/// A child process whose stdout is read through a pipe and whose stderr goes to a file (if
/// given); killed with SIGKILL on destruction if still alive.
class Child {
 public:
  explicit Child(const std::vector<std::string>& args, const std::filesystem::path& stderr_file = {}) {
    int out[2];
    if (::pipe2(out, O_CLOEXEC) != 0) {
      throw std::runtime_error("pipe");
    }
    pid_ = ::fork();
    if (pid_ == 0) {
      ::dup2(out[1], STDOUT_FILENO);
      if (!stderr_file.empty()) {
        const int err = ::open(stderr_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
        if (err >= 0) {
          ::dup2(err, STDERR_FILENO);
        }
      }
      std::vector<char*> argv;
      for (const auto& arg : args) {
        argv.push_back(const_cast<char*>(arg.c_str()));
      }
      argv.push_back(nullptr);
      ::execv(argv[0], argv.data());
      ::_exit(127);
    }
    ::close(out[1]);
    out_ = out[0];
  }
  ~Child() {
    kill();
    ::close(out_);
  }
  Child(const Child&) = delete;
  Child& operator=(const Child&) = delete;

  /// Reads stdout until "listening on http://127.0.0.1:PORT/"; 0 if the child ended first.
  std::uint16_t waitForPort() {
    std::string text;
    char buffer[4096];
    while (true) {
      const ssize_t n = ::read(out_, buffer, sizeof(buffer));
      if (n <= 0) {
        return 0;
      }
      text.append(buffer, static_cast<std::size_t>(n));
      const auto at = text.find("listening on http://127.0.0.1:");
      if (at != std::string::npos) {
        const auto start = at + std::string("listening on http://127.0.0.1:").size();
        const auto end = text.find('/', start);
        if (end != std::string::npos) {
          return static_cast<std::uint16_t>(std::stoi(text.substr(start, end - start)));
        }
      }
    }
  }
  void signal(int number) const {
    if (pid_ > 0) {
      ::kill(pid_, number);
    }
  }
  /// Sends a signal to one thread of the child, the first named `name` (/proc/PID/task/*/comm);
  /// false when it has none.
  bool signalThread(const std::string& name, int number) const {
    std::error_code error;
    for (const auto& task : std::filesystem::directory_iterator("/proc/" + std::to_string(pid_) + "/task", error)) {
      std::string comm;
      std::getline(std::ifstream(task.path() / "comm"), comm);
      if (comm == name) {
        return ::syscall(SYS_tgkill, pid_, std::stoi(task.path().filename().string()), number) == 0;
      }
    }
    return false;
  }
  /// Waits for the child to end (up to `timeout_ms`); its wait status, or -1 if still running.
  int wait(int timeout_ms) {
    for (int waited = 0; pid_ > 0; waited += 10) {
      int status = 0;
      if (::waitpid(pid_, &status, WNOHANG) == pid_) {
        pid_ = -1;
        return status;
      }
      if (waited >= timeout_ms) {
        return -1;
      }
      ::usleep(10'000);
    }
    return -1;
  }
  void kill() {
    if (pid_ > 0) {
      ::kill(pid_, SIGKILL);
      ::waitpid(pid_, nullptr, 0);
      pid_ = -1;
    }
  }

 private:
  pid_t pid_ = -1;
  int out_ = -1;
};

}  // namespace costar::server::testing
