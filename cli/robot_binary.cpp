#include "cli/robot_binary.h"

#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

namespace costar::cli {

namespace {

int g_argc = 0;
char** g_argv = nullptr;

}  // namespace

void rememberCommandLine(int argc, char** argv) {
  g_argc = argc;
  g_argv = argv;
}

std::filesystem::path executableDir() {
  std::error_code error;
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", error);
  return error ? std::filesystem::path() : self.parent_path();
}

void runInRobotBinary() {
  const std::filesystem::path robot = executableDir() / "costar-robot";
  std::vector<char*> args;
  std::string program = robot.string();
  args.push_back(program.data());
  for (int i = 1; i < g_argc; ++i) {
    args.push_back(g_argv[i]);
  }
  args.push_back(nullptr);
  std::fflush(stdout);
  std::fflush(stderr);
  ::execv(program.c_str(), args.data());
  const int error = errno;
  std::string command = g_argc > 1 ? g_argv[1] : "";
  std::fprintf(stderr,
               "error: 'costar %s' needs the robot libraries (simulator, perception, planning) in %s, which "
               "cannot be started: %s\n",
               command.c_str(), program.c_str(), std::strerror(error));
  std::fflush(stderr);
  ::_exit(2);
}

}  // namespace costar::cli
