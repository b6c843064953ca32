#pragma once
// Files, checked: durable writes (nothing already saved is lost when the process dies
// mid-save), outputs whose every write is checked (a full disk is an error, never a "wrote"),
// files written as a program runs, and data files read with a size cap.

#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>

namespace costar {

/// Writes `content` to a temporary file beside `path`, fsyncs it, renames it over `path`
/// and fsyncs the folder. Readers see the old or the new content, never a mix.
/// @throws std::runtime_error naming the file and the system error.
void writeFileAtomically(const std::filesystem::path& path, std::string_view content);

/// Writes `content` to an output file the user named (--json, --out, ...): atomically
/// (writeFileAtomically) to a regular file or a new one; straight through, every write checked
/// and the file closed before returning, to anything else that exists (/dev/stdout, a pipe,
/// /dev/full).
/// @throws std::runtime_error "cannot write 'PATH': ERROR" (the system's words), so that no
/// caller reports a file written that is not.
void writeOutputFile(const std::filesystem::path& path, std::string_view content);

/// Checks, before any work is done, that the output `file` can be written at the end: its
/// folder exists, it is not a folder itself, and it may be written. `what` names it ("--json").
/// @throws std::invalid_argument "cannot write WHAT 'FILE': PROBLEM".
void checkOutputFile(const std::filesystem::path& file, const std::string& what);

/// A file written as a program runs (a run's trace, a campaign's JSON lines): every append() is
/// handed to the system at once with write(2), no buffer in this process, so a process killed
/// even by SIGKILL has lost nothing appended before. Every write is checked. Not thread-safe.
class AppendingFile {
 public:
  enum class Mode { kTruncate, kAppend };
  /// Opens (creating) `path`. @throws std::runtime_error "cannot write 'PATH': ERROR".
  AppendingFile(std::filesystem::path path, Mode mode);
  AppendingFile(const AppendingFile&) = delete;
  AppendingFile& operator=(const AppendingFile&) = delete;
  /// Closes the file if close() was not called (an error there goes unreported).
  ~AppendingFile();

  /// Writes `text` whole. @throws std::runtime_error "cannot write 'PATH': ERROR".
  void append(std::string_view text);
  /// Syncs what was written to the disk (a device or pipe that cannot be synced is not an
  /// error) and closes. @throws std::runtime_error "cannot write 'PATH': ERROR".
  void close();
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
  int fd_ = -1;
};

/// The largest data file (scene, description, waypoints, model) readFile() accepts.
inline constexpr std::size_t kMaxDataFileBytes = std::size_t{64} << 20;

/// Reads a whole data file. Only a regular file (not /dev/zero, a pipe or a folder) of at most
/// `max_bytes` is read, so a wrong path fails at once instead of reading forever.
/// @throws std::runtime_error "cannot read WHAT 'PATH': PROBLEM" (`what`: "scene file"; may be
/// empty).
std::string readFile(const std::filesystem::path& path, std::string_view what = {},
                     std::size_t max_bytes = kMaxDataFileBytes);

/// A short fingerprint of `content` ("fnv1a64:" and 16 hex digits) to tell whether two files
/// differ (a trial batch's plan, a description edited after the build). Not for security.
std::string fingerprint(std::string_view content);

/// Checks that models generated at build time from the description `source` came from its
/// present contents: `fingerprint_file` (the generator writes it beside the models) holds
/// fingerprint() of the bytes it read. A description edited after the build would otherwise be
/// applied in part (the runtime reads the file, the simulator the models generated from the old
/// one).
/// @throws std::runtime_error "robots/iiwa14/iiwa14.json changed after the build: rebuild (cmake
/// --build build)" (the source relative to the data root when under it), or naming a missing
/// fingerprint file.
void checkGeneratedFrom(const std::filesystem::path& source, const std::filesystem::path& fingerprint_file);

}  // namespace costar
