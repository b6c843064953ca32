#include "server/auth.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <random>
#include <sstream>
#include <stdexcept>

namespace costar::server {

std::string randomToken() {
  std::random_device device;  // getrandom(2) on Linux
  static constexpr char kHex[] = "0123456789abcdef";
  std::string token;
  for (int i = 0; i < 8; ++i) {
    std::uint32_t word = device();
    for (int nibble = 0; nibble < 8; ++nibble) {
      token += kHex[word & 0xF];
      word >>= 4;
    }
  }
  return token;
}

namespace {

std::string trim(std::string text) {
  const auto first = text.find_first_not_of(" \t\r\n");
  if (first == std::string::npos) {
    return {};
  }
  const auto last = text.find_last_not_of(" \t\r\n");
  return text.substr(first, last - first + 1);
}

}  // namespace

std::string tokenFromFile(const std::filesystem::path& file) {
  struct stat info {};
  if (::lstat(file.c_str(), &info) == 0) {
    if (!S_ISREG(info.st_mode)) {
      throw std::runtime_error("token file '" + file.string() + "' is not a regular file");
    }
    if ((info.st_mode & 077) != 0) {
      throw std::runtime_error("token file '" + file.string() +
                               "' may be read or written by others: make it private with chmod 600");
    }
    if (info.st_uid != ::geteuid()) {
      throw std::runtime_error("token file '" + file.string() + "' belongs to another user");
    }
    std::ifstream in(file);
    std::stringstream text;
    text << in.rdbuf();
    if (!in) {
      throw std::runtime_error("cannot read token file '" + file.string() + "'");
    }
    std::string token = trim(text.str());
    if (token.size() < 16 || token.find_first_of(" \t\r\n") != std::string::npos) {
      throw std::runtime_error("token file '" + file.string() + "' must hold one token of at least 16 characters");
    }
    return token;
  }
  if (errno != ENOENT) {
    throw std::runtime_error("cannot read token file '" + file.string() + "': " + std::strerror(errno));
  }
  const std::string token = randomToken();
  const int fd = ::open(file.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
  if (fd < 0) {
    throw std::runtime_error("cannot create token file '" + file.string() + "': " + std::strerror(errno));
  }
  const std::string line = token + "\n";
  const bool written = ::write(fd, line.data(), line.size()) == static_cast<ssize_t>(line.size()) && ::fsync(fd) == 0;
  ::close(fd);
  if (!written) {
    throw std::runtime_error("cannot write token file '" + file.string() + "'");
  }
  return token;
}

bool sameToken(std::string_view given, std::string_view expected) {
  if (expected.empty()) {
    return false;
  }
  unsigned char difference = given.size() == expected.size() ? 0 : 1;
  for (std::size_t i = 0; i < given.size(); ++i) {
    difference |= static_cast<unsigned char>(given[i] ^ expected[i % expected.size()]);
  }
  return difference == 0;
}

std::string_view bearerToken(std::string_view authorization) {
  constexpr std::string_view kPrefix = "Bearer ";
  if (authorization.size() <= kPrefix.size()) {
    return {};
  }
  for (std::size_t i = 0; i < kPrefix.size(); ++i) {
    const char a = authorization[i];
    const char b = kPrefix[i];
    if ((a | 0x20) != (b | 0x20)) {
      return {};
    }
  }
  std::string_view token = authorization.substr(kPrefix.size());
  while (!token.empty() && (token.back() == ' ' || token.back() == '\t')) {
    token.remove_suffix(1);
  }
  return token;
}

}  // namespace costar::server
