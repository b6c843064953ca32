#pragma once
// The editor's store: one SQLite database (WAL journal, synchronous=FULL, one transaction per
// save) holding
//   - plans and every version of each (the XML text `costar run` reads, validated before saving),
//   - saved subtrees (one-tree plan files, versioned the same way),
//   - run logs: each run of a plan with its result, its nodes, and every status transition
//     with its clock time, for replay.
// A save returns only after its transaction is committed, so a crash or kill -9 after a
// save has answered never loses it; a save cut short leaves the previous versions intact.
//
// Waypoints and SmartMove grasps are NOT kept here: their single source of truth stays the
// per-workcell JSON files of arm::WaypointStore and smartmove::GraspLibrary (written
// atomically), which `costar run`, `costar teach` and the trials read too. The server changes
// them only through the arm's operations (Teach, RenameWaypoint, DeleteWaypoint).
//
// Thread-safe: one connection, serialized by a mutex.

#include <cstdint>
#include <filesystem>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

struct sqlite3;

namespace costar::server {

/// What the store keeps versions of.
enum class DocumentKind { kPlan, kSubtree };

struct DocumentVersion {
  std::string name;
  int version = 0;
  std::string xml;
  /// Seconds since the Unix epoch.
  double saved_at = 0;
};

struct DocumentSummary {
  std::string name;
  int latest_version = 0;
  int versions = 0;
  double updated_at = 0;
};

/// One node of a run's tree, as built (uid = pre-order index).
struct RunNode {
  std::uint32_t uid = 0;
  std::int64_t parent = -1;  // -1 for the root
  std::string id;
  std::string name;
  std::string path;
};

struct RunRecord {
  std::int64_t id = 0;
  /// The cell it ran on (`--workcell`), empty for runs logged before cells were recorded.
  std::string workcell;
  /// The plan's name and version when it was saved, else empty / 0.
  std::string plan;
  int version = 0;
  /// The plan file that ran.
  std::string xml;
  double started_at = 0;  // Unix seconds
  /// Empty while running; SUCCESS, FAILURE, STOPPED, or INTERRUPTED (the server died).
  std::string result;
  double ended_at = 0;
  double clock_seconds = 0;  // the run's length in clock time
  std::string failure_path;
  std::string failure_reason;
  std::uint64_t transitions = 0;
  bool truncated = false;  // more transitions happened than were kept
};

struct TransitionRecord {
  std::uint64_t seq = 0;
  double t = 0;  // clock seconds since the run started
  std::uint32_t uid = 0;
  std::string from;
  std::string to;
  std::string reason;  // on FAILURE
  std::string origin;  // on FAILURE: path of the node where it arose
  std::string data;    // JSON text of an operation's result data, or empty
};

/// A snapshot of the cell during a run (the stream's state message, without the waypoints and
/// frames), for replaying the arm, the gripper and the parts.
struct StateRecord {
  double t = 0;       // clock seconds since the run started
  std::string state;  // JSON text
};

struct RunLog {
  RunRecord run;
  std::vector<RunNode> nodes;
  /// The transitions asked for (TransitionPage), in order.
  std::vector<TransitionRecord> transitions;
  /// The seq of the next stored transition after them; nullopt when they were the last.
  std::optional<std::uint64_t> next_seq;
};

/// Which transitions of a run to read: those from seq `from` on, at most `limit` of them, and
/// no more once `max_bytes` of their text (reasons, origins, data) is reached (at least one).
struct TransitionPage {
  std::uint64_t from = 1;
  std::size_t limit = std::numeric_limits<std::size_t>::max();
  std::size_t max_bytes = std::numeric_limits<std::size_t>::max();
};

/// Thrown when the database cannot be opened or written; the message names the file.
class StoreError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class Store {
 public:
  /// Opens (creating if needed) the database at `file`, or an in-memory one for ":memory:".
  /// Runs that were still open when a previous server died are marked INTERRUPTED.
  /// @throws StoreError
  explicit Store(const std::filesystem::path& file);
  ~Store();
  Store(const Store&) = delete;
  Store& operator=(const Store&) = delete;

  /// Saves `xml` as the next version of `name` in one transaction; returns the version.
  int save(DocumentKind kind, const std::string& name, const std::string& xml);
  /// The latest version, or the given one.
  std::optional<DocumentVersion> load(DocumentKind kind, const std::string& name,
                                      std::optional<int> version = std::nullopt) const;
  std::vector<DocumentSummary> list(DocumentKind kind) const;
  /// Every version of `name`, newest first (without the text).
  std::vector<DocumentVersion> versions(DocumentKind kind, const std::string& name) const;
  /// Removes every version; false when there was none.
  bool remove(DocumentKind kind, const std::string& name);

  // --- run logs --------------------------------------------------------------------------
  /// Records a run that starts (record.id chosen by the caller, > maxRunId()).
  void beginRun(const RunRecord& record, const std::vector<RunNode>& nodes);
  /// Appends transitions of a run in one transaction.
  void appendTransitions(std::int64_t run, const std::vector<TransitionRecord>& transitions);
  /// Appends snapshots of the cell during a run in one transaction.
  void appendStates(std::int64_t run, const std::vector<StateRecord>& states);
  /// A run's snapshots, oldest first.
  std::vector<StateRecord> runStates(std::int64_t run) const;
  /// Records how a run ended (result, times, failure, counts).
  void endRun(const RunRecord& record);
  /// The newest runs first.
  std::vector<RunRecord> runs(std::size_t limit = 100) const;
  /// A run with its nodes (unless `with_nodes` is false) and the page of its transitions asked
  /// for (all by default). The store is locked for one page only: a long log is read in pages
  /// while the run-log writer goes on.
  std::optional<RunLog> run(std::int64_t id, const TransitionPage& page = {}, bool with_nodes = true) const;
  std::int64_t maxRunId() const;

  /// SQLite's PRAGMA integrity_check: "ok" when the database is sound.
  std::string integrityCheck() const;
  const std::filesystem::path& file() const { return file_; }

 private:
  void exec(const char* sql) const;
  void addRunWorkcellColumn();
  std::filesystem::path file_;
  sqlite3* db_ = nullptr;
  mutable std::mutex mutex_;
};

/// Seconds since the Unix epoch, now.
double unixNow();

}  // namespace costar::server
