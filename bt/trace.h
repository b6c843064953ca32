#pragma once
// Observers that record a run: JSON lines for replay and tooling.

#include <filesystem>
#include <ostream>
#include <sstream>
#include <string>

#include "bt/node.h"
#include "core/files.h"

namespace costar::bt {

/// Writes one JSON object per status transition and line:
///   {"t":1.25,"uid":4,"path":"main/Sequence[1]/Move \"home\"","node":"Move",
///    "from":"RUNNING","to":"FAILURE","reason":"...","origin":"<path where it arose>"}
/// `reason` and `origin` appear on transitions to FAILURE only. `t` is clock seconds.
class JsonLinesTrace final : public TreeObserver {
 public:
  explicit JsonLinesTrace(std::ostream& out) : out_(out) {}
  void onTransition(TimePoint time, const TreeNode& node, Status from, Status to) override;

 private:
  std::ostream& out_;
};

/// JsonLinesTrace into a file written as the run goes: the lines of the transitions since the
/// last flush() are appended in one write (core/files.h AppendingFile). Call flush() once a tick
/// (the executor's before-tick hook) and close() after the run: a run stopped by a signal keeps
/// its whole trace, one killed (SIGKILL) every tick but the last. A write that fails stops the
/// writing and is kept in error(); the run is not disturbed.
class JsonLinesFileTrace final : public TreeObserver {
 public:
  /// Creates or truncates `file`. @throws std::runtime_error "cannot write 'FILE': ERROR".
  explicit JsonLinesFileTrace(std::filesystem::path file);
  void onTransition(TimePoint time, const TreeNode& node, Status from, Status to) override;
  /// Appends the lines since the last flush. Never throws: a failure goes to error().
  void flush();
  /// flush(), then syncs and closes the file. Never throws: a failure goes to error().
  void close();
  /// Empty while every write succeeded; else "cannot write 'FILE': ERROR".
  const std::string& error() const { return error_; }
  const std::filesystem::path& path() const { return file_.path(); }

 private:
  AppendingFile file_;
  std::ostringstream buffer_;
  JsonLinesTrace lines_{buffer_};
  bool pending_ = false;
  std::string error_;
};

}  // namespace costar::bt
