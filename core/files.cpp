#include "core/files.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string>

#include "core/paths.h"

namespace costar {

namespace {

[[noreturn]] void fail(const std::string& what, const std::filesystem::path& path) {
  throw std::runtime_error(what + " '" + path.string() + "': " + std::strerror(errno));
}

/// Writes all of `content` to `fd`; false with errno set when a write fails.
bool writeAll(int fd, std::string_view content) {
  std::size_t written = 0;
  while (written < content.size()) {
    const ssize_t n = ::write(fd, content.data() + written, content.size() - written);
    if (n < 0) {
      if (errno == EINTR) {
        continue;
      }
      return false;
    }
    written += static_cast<std::size_t>(n);
  }
  return true;
}

/// Closes `fd`, keeping the errno of a failure that came before.
void closeKeepingErrno(int fd) {
  const int error = errno;
  ::close(fd);
  errno = error;
}

/// open(2) for writing that never waits: a pipe with no reader is an error (ENXIO, "No such
/// device or address") instead of blocking the program before it starts. The descriptor is made
/// blocking again, so that writes wait for a slow reader rather than fail.
int openForWriting(const std::filesystem::path& path, int flags) {
  const int fd = ::open(path.c_str(), flags | O_NONBLOCK, 0644);
  if (fd >= 0) {
    ::fcntl(fd, F_SETFL, ::fcntl(fd, F_GETFL) & ~O_NONBLOCK);
  }
  return fd;
}

std::string sizeText(std::uintmax_t bytes) {
  return bytes >= (1U << 20) ? std::to_string(bytes >> 20) + " MiB" : std::to_string(bytes) + " bytes";
}

}  // namespace

void writeFileAtomically(const std::filesystem::path& path, std::string_view content) {
  std::filesystem::path temporary = path;
  temporary += ".tmp." + std::to_string(::getpid());
  const int fd = ::open(temporary.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) {
    fail("cannot write", path);  // named as the caller named it, not the temporary
  }
  if (!writeAll(fd, content)) {
    closeKeepingErrno(fd);
    ::unlink(temporary.c_str());
    fail("cannot write", path);
  }
  if (::fsync(fd) != 0) {
    closeKeepingErrno(fd);
    ::unlink(temporary.c_str());
    fail("cannot write", path);
  }
  if (::close(fd) != 0) {
    ::unlink(temporary.c_str());
    fail("cannot write", path);
  }
  if (::rename(temporary.c_str(), path.c_str()) != 0) {
    const int error = errno;
    ::unlink(temporary.c_str());
    errno = error;
    fail("cannot replace", path);
  }
  const std::filesystem::path folder = path.has_parent_path() ? path.parent_path() : ".";
  const int dir = ::open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dir >= 0) {
    ::fsync(dir);
    ::close(dir);
  }
}

void writeOutputFile(const std::filesystem::path& path, std::string_view content) {
  if (path.empty()) {
    throw std::runtime_error("cannot write '': the file name is empty");
  }
  struct stat info {};
  if (::stat(path.c_str(), &info) != 0 || S_ISREG(info.st_mode)) {
    writeFileAtomically(path, content);  // a new file, or one to replace whole
    return;
  }
  if (S_ISDIR(info.st_mode)) {
    throw std::runtime_error("cannot write '" + path.string() + "': it is a folder");
  }
  const int fd = openForWriting(path, O_WRONLY | O_CLOEXEC);
  if (fd < 0) {
    fail("cannot write", path);
  }
  if (!writeAll(fd, content)) {
    closeKeepingErrno(fd);
    fail("cannot write", path);
  }
  if (::close(fd) != 0) {
    fail("cannot write", path);
  }
}

void checkOutputFile(const std::filesystem::path& file, const std::string& what) {
  const std::string label = what + " '" + file.string() + "'";
  if (file.empty()) {
    throw std::invalid_argument(what + ": the file name is empty");
  }
  std::error_code error;
  const auto status = std::filesystem::status(file, error);
  if (std::filesystem::is_directory(status)) {
    throw std::invalid_argument("cannot write " + label + ": it is a folder");
  }
  const std::filesystem::path folder = file.has_parent_path() ? file.parent_path() : ".";
  if (!std::filesystem::is_directory(folder, error)) {
    throw std::invalid_argument("cannot write " + label + ": there is no folder '" + folder.string() + "'");
  }
  // A regular file is replaced by a new one written in its folder; a device is written to.
  const bool exists = std::filesystem::exists(status);
  const std::filesystem::path written = exists && !std::filesystem::is_regular_file(status) ? file : folder;
  if (::access(written.c_str(), W_OK) != 0) {
    throw std::invalid_argument("cannot write " + label + ": " + std::strerror(errno));
  }
}

AppendingFile::AppendingFile(std::filesystem::path path, Mode mode) : path_(std::move(path)) {
  const int flags = O_WRONLY | O_CREAT | O_CLOEXEC | (mode == Mode::kAppend ? O_APPEND : O_TRUNC);
  fd_ = openForWriting(path_, flags);
  if (fd_ < 0) {
    fail("cannot write", path_);
  }
}

AppendingFile::~AppendingFile() {
  if (fd_ >= 0) {
    ::close(fd_);
  }
}

void AppendingFile::append(std::string_view text) {
  if (fd_ < 0) {
    throw std::runtime_error("cannot write '" + path_.string() + "': it was closed");
  }
  if (!writeAll(fd_, text)) {
    fail("cannot write", path_);
  }
}

void AppendingFile::close() {
  if (fd_ < 0) {
    return;
  }
  const int fd = fd_;
  fd_ = -1;
  // A device or a pipe cannot be synced (EINVAL, EROFS): what it took is all it gets.
  if (::fsync(fd) != 0 && errno != EINVAL && errno != EROFS) {
    closeKeepingErrno(fd);
    fail("cannot write", path_);
  }
  if (::close(fd) != 0) {
    fail("cannot write", path_);
  }
}

std::string readFile(const std::filesystem::path& path, std::string_view what, std::size_t max_bytes) {
  const std::string action = what.empty() ? "cannot read" : "cannot read " + std::string(what);
  // Non-blocking, so that opening a pipe with no writer does not wait forever; a regular file's
  // reads never block anyway.
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
  if (fd < 0) {
    fail(action, path);
  }
  const auto refuse = [&](const std::string& problem) {
    ::close(fd);
    throw std::runtime_error(action + " '" + path.string() + "': " + problem);
  };
  struct stat info {};
  if (::fstat(fd, &info) != 0) {
    const std::string problem = std::strerror(errno);
    refuse(problem);
  }
  if (S_ISDIR(info.st_mode)) {
    refuse("it is a folder");
  }
  if (!S_ISREG(info.st_mode)) {
    refuse("not a regular file (a device, pipe or socket)");
  }
  if (static_cast<std::uintmax_t>(info.st_size) > max_bytes) {
    refuse("it holds " + sizeText(static_cast<std::uintmax_t>(info.st_size)) + ", more than the " +
           sizeText(max_bytes) + " a data file may have");
  }
  std::string content;
  content.reserve(static_cast<std::size_t>(info.st_size));
  char buffer[65536];
  for (;;) {
    const ssize_t n = ::read(fd, buffer, sizeof buffer);
    if (n < 0) {
      if (errno == EINTR) {
        continue;
      }
      const std::string problem = std::strerror(errno);
      refuse(problem);
    }
    if (n == 0) {
      break;
    }
    if (content.size() + static_cast<std::size_t>(n) > max_bytes) {
      refuse("it grew past the " + sizeText(max_bytes) + " a data file may have");
    }
    content.append(buffer, static_cast<std::size_t>(n));
  }
  ::close(fd);
  return content;
}

std::string fingerprint(std::string_view content) {
  std::uint64_t hash = 14695981039346656037ULL;  // FNV-1a, 64 bits
  for (const char c : content) {
    hash ^= static_cast<unsigned char>(c);
    hash *= 1099511628211ULL;
  }
  char text[32];
  std::snprintf(text, sizeof text, "fnv1a64:%016llx", static_cast<unsigned long long>(hash));
  return text;
}

void checkGeneratedFrom(const std::filesystem::path& source, const std::filesystem::path& fingerprint_file) {
  std::error_code error;
  const std::filesystem::path relative = std::filesystem::relative(source, dataRoot(), error);
  const std::string shown =
      !error && !relative.empty() && *relative.begin() != ".." ? relative.string() : source.string();
  std::string recorded;
  try {
    recorded = readFile(fingerprint_file, "", 256);
  } catch (const std::runtime_error&) {
    throw std::runtime_error(shown + ": the models generated from it carry no fingerprint ('" +
                             fingerprint_file.string() + "' is missing): rebuild (cmake --build build)");
  }
  while (!recorded.empty() && (recorded.back() == '\n' || recorded.back() == ' ')) {
    recorded.pop_back();
  }
  if (recorded != fingerprint(readFile(source))) {
    throw std::runtime_error(shown + " changed after the build: rebuild (cmake --build build)");
  }
}

}  // namespace costar
