#include "server/store.h"

#include <sqlite3.h>

#include <algorithm>
#include <chrono>
#include <cstring>

namespace costar::server {

double unixNow() { return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count(); }

namespace {

/// A prepared statement, finalized when it goes out of scope.
class Statement {
 public:
  Statement(sqlite3* db, const char* sql) : db_(db) {
    if (sqlite3_prepare_v2(db, sql, -1, &statement_, nullptr) != SQLITE_OK) {
      throw StoreError(std::string("store: cannot prepare statement: ") + sqlite3_errmsg(db));
    }
  }
  ~Statement() { sqlite3_finalize(statement_); }
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;

  Statement& bind(int index, const std::string& text) {
    check(sqlite3_bind_text(statement_, index, text.data(), static_cast<int>(text.size()), SQLITE_TRANSIENT));
    return *this;
  }
  Statement& bind(int index, std::int64_t value) {
    check(sqlite3_bind_int64(statement_, index, value));
    return *this;
  }
  Statement& bind(int index, int value) { return bind(index, static_cast<std::int64_t>(value)); }
  Statement& bind(int index, double value) {
    check(sqlite3_bind_double(statement_, index, value));
    return *this;
  }
  Statement& bindNull(int index) {
    check(sqlite3_bind_null(statement_, index));
    return *this;
  }

  /// True while a row is available.
  bool step() {
    const int rc = sqlite3_step(statement_);
    if (rc == SQLITE_ROW) {
      return true;
    }
    if (rc == SQLITE_DONE) {
      return false;
    }
    throw StoreError(std::string("store: ") + sqlite3_errmsg(db_));
  }
  void run() {
    while (step()) {
    }
  }
  void reset() {
    sqlite3_reset(statement_);
    sqlite3_clear_bindings(statement_);
  }

  std::int64_t integer(int column) const { return sqlite3_column_int64(statement_, column); }
  double real(int column) const { return sqlite3_column_double(statement_, column); }
  bool isNull(int column) const { return sqlite3_column_type(statement_, column) == SQLITE_NULL; }
  std::string text(int column) const {
    const auto* data = sqlite3_column_text(statement_, column);
    const int size = sqlite3_column_bytes(statement_, column);
    return data == nullptr ? std::string() : std::string(reinterpret_cast<const char*>(data), size);
  }

 private:
  void check(int rc) const {
    if (rc != SQLITE_OK) {
      throw StoreError(std::string("store: cannot bind: ") + sqlite3_errmsg(db_));
    }
  }
  sqlite3* db_;
  sqlite3_stmt* statement_ = nullptr;
};

/// BEGIN IMMEDIATE ... COMMIT, rolled back if the scope is left by an exception.
class Transaction {
 public:
  explicit Transaction(sqlite3* db) : db_(db) { execute("BEGIN IMMEDIATE"); }
  ~Transaction() {
    if (!committed_) {
      sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr);
    }
  }
  void commit() {
    execute("COMMIT");
    committed_ = true;
  }

 private:
  void execute(const char* sql) {
    char* error = nullptr;
    if (sqlite3_exec(db_, sql, nullptr, nullptr, &error) != SQLITE_OK) {
      std::string message = error != nullptr ? error : "unknown error";
      sqlite3_free(error);
      throw StoreError(std::string("store: ") + sql + ": " + message);
    }
  }
  sqlite3* db_;
  bool committed_ = false;
};

const char* table(DocumentKind kind) { return kind == DocumentKind::kPlan ? "plan_versions" : "subtree_versions"; }

constexpr const char* kSchema = R"sql(
CREATE TABLE IF NOT EXISTS plan_versions (
  name TEXT NOT NULL, version INTEGER NOT NULL, xml TEXT NOT NULL, saved_at REAL NOT NULL,
  PRIMARY KEY (name, version));
CREATE TABLE IF NOT EXISTS subtree_versions (
  name TEXT NOT NULL, version INTEGER NOT NULL, xml TEXT NOT NULL, saved_at REAL NOT NULL,
  PRIMARY KEY (name, version));
CREATE TABLE IF NOT EXISTS runs (
  id INTEGER PRIMARY KEY, plan TEXT NOT NULL, version INTEGER NOT NULL, xml TEXT NOT NULL,
  started_at REAL NOT NULL, result TEXT NOT NULL DEFAULT '', ended_at REAL NOT NULL DEFAULT 0,
  clock_seconds REAL NOT NULL DEFAULT 0, failure_path TEXT NOT NULL DEFAULT '',
  failure_reason TEXT NOT NULL DEFAULT '', transitions INTEGER NOT NULL DEFAULT 0,
  truncated INTEGER NOT NULL DEFAULT 0);
CREATE TABLE IF NOT EXISTS run_nodes (
  run INTEGER NOT NULL REFERENCES runs(id) ON DELETE CASCADE, uid INTEGER NOT NULL,
  parent INTEGER NOT NULL, id TEXT NOT NULL, name TEXT NOT NULL, path TEXT NOT NULL,
  PRIMARY KEY (run, uid));
CREATE TABLE IF NOT EXISTS transitions (
  run INTEGER NOT NULL REFERENCES runs(id) ON DELETE CASCADE, seq INTEGER NOT NULL,
  t REAL NOT NULL, uid INTEGER NOT NULL, from_status TEXT NOT NULL, to_status TEXT NOT NULL,
  reason TEXT NOT NULL DEFAULT '', origin TEXT NOT NULL DEFAULT '', data TEXT NOT NULL DEFAULT '',
  PRIMARY KEY (run, seq));
CREATE TABLE IF NOT EXISTS run_states (
  run INTEGER NOT NULL REFERENCES runs(id) ON DELETE CASCADE, seq INTEGER NOT NULL,
  t REAL NOT NULL, state TEXT NOT NULL, PRIMARY KEY (run, seq));
)sql";

RunRecord readRun(const Statement& row) {
  RunRecord run;
  run.id = row.integer(0);
  run.plan = row.text(1);
  run.version = static_cast<int>(row.integer(2));
  run.xml = row.text(3);
  run.started_at = row.real(4);
  run.result = row.text(5);
  run.ended_at = row.real(6);
  run.clock_seconds = row.real(7);
  run.failure_path = row.text(8);
  run.failure_reason = row.text(9);
  run.transitions = static_cast<std::uint64_t>(row.integer(10));
  run.truncated = row.integer(11) != 0;
  run.workcell = row.text(12);
  return run;
}

constexpr const char* kRunColumns =
    "id, plan, version, xml, started_at, result, ended_at, clock_seconds, failure_path, failure_reason, "
    "transitions, truncated, workcell";

}  // namespace

Store::Store(const std::filesystem::path& file) : file_(file) {
  if (file != ":memory:" && file.has_parent_path()) {
    std::error_code error;
    std::filesystem::create_directories(file.parent_path(), error);
  }
  if (sqlite3_open_v2(file.c_str(), &db_, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE | SQLITE_OPEN_FULLMUTEX,
                      nullptr) != SQLITE_OK) {
    const std::string message = db_ != nullptr ? sqlite3_errmsg(db_) : "out of memory";
    sqlite3_close(db_);
    db_ = nullptr;
    throw StoreError("store: cannot open '" + file.string() + "': " + message);
  }
  try {
    sqlite3_busy_timeout(db_, 5000);
    exec("PRAGMA journal_mode=WAL");
    exec("PRAGMA synchronous=FULL");
    exec("PRAGMA foreign_keys=ON");
    exec(kSchema);
    addRunWorkcellColumn();
    exec("UPDATE runs SET result = 'INTERRUPTED' WHERE result = ''");
  } catch (...) {
    sqlite3_close(db_);
    db_ = nullptr;
    throw;
  }
}

Store::~Store() { sqlite3_close(db_); }

void Store::addRunWorkcellColumn() {
  // Stores made before runs named their cell get the column (empty for their old runs).
  Statement columns(db_, "SELECT COUNT(*) FROM pragma_table_info('runs') WHERE name = 'workcell'");
  columns.step();
  if (columns.integer(0) == 0) {
    exec("ALTER TABLE runs ADD COLUMN workcell TEXT NOT NULL DEFAULT ''");
  }
}

void Store::exec(const char* sql) const {
  char* error = nullptr;
  if (sqlite3_exec(db_, sql, nullptr, nullptr, &error) != SQLITE_OK) {
    std::string message = error != nullptr ? error : "unknown error";
    sqlite3_free(error);
    throw StoreError("store '" + file_.string() + "': " + message);
  }
}

int Store::save(DocumentKind kind, const std::string& name, const std::string& xml) {
  const std::lock_guard lock(mutex_);
  Transaction transaction(db_);
  Statement latest(db_,
                   (std::string("SELECT COALESCE(MAX(version), 0) FROM ") + table(kind) + " WHERE name = ?").c_str());
  latest.bind(1, name);
  latest.step();
  const int version = static_cast<int>(latest.integer(0)) + 1;
  Statement insert(
      db_, (std::string("INSERT INTO ") + table(kind) + " (name, version, xml, saved_at) VALUES (?, ?, ?, ?)").c_str());
  insert.bind(1, name).bind(2, version).bind(3, xml).bind(4, unixNow()).run();
  transaction.commit();
  return version;
}

std::optional<DocumentVersion> Store::load(DocumentKind kind, const std::string& name,
                                           std::optional<int> version) const {
  const std::lock_guard lock(mutex_);
  const std::string sql =
      std::string("SELECT name, version, xml, saved_at FROM ") + table(kind) +
      (version ? " WHERE name = ? AND version = ?" : " WHERE name = ? ORDER BY version DESC LIMIT 1");
  Statement query(db_, sql.c_str());
  query.bind(1, name);
  if (version) {
    query.bind(2, *version);
  }
  if (!query.step()) {
    return std::nullopt;
  }
  return DocumentVersion{query.text(0), static_cast<int>(query.integer(1)), query.text(2), query.real(3)};
}

std::vector<DocumentSummary> Store::list(DocumentKind kind) const {
  const std::lock_guard lock(mutex_);
  Statement query(db_, (std::string("SELECT name, MAX(version), COUNT(*), MAX(saved_at) FROM ") + table(kind) +
                        " GROUP BY name ORDER BY name")
                           .c_str());
  std::vector<DocumentSummary> out;
  while (query.step()) {
    out.push_back(
        {query.text(0), static_cast<int>(query.integer(1)), static_cast<int>(query.integer(2)), query.real(3)});
  }
  return out;
}

std::vector<DocumentVersion> Store::versions(DocumentKind kind, const std::string& name) const {
  const std::lock_guard lock(mutex_);
  Statement query(
      db_, (std::string("SELECT name, version, saved_at FROM ") + table(kind) + " WHERE name = ? ORDER BY version DESC")
               .c_str());
  query.bind(1, name);
  std::vector<DocumentVersion> out;
  while (query.step()) {
    out.push_back({query.text(0), static_cast<int>(query.integer(1)), {}, query.real(2)});
  }
  return out;
}

bool Store::remove(DocumentKind kind, const std::string& name) {
  const std::lock_guard lock(mutex_);
  Transaction transaction(db_);
  Statement erase(db_, (std::string("DELETE FROM ") + table(kind) + " WHERE name = ?").c_str());
  erase.bind(1, name).run();
  const bool removed = sqlite3_changes(db_) > 0;
  transaction.commit();
  return removed;
}

void Store::beginRun(const RunRecord& record, const std::vector<RunNode>& nodes) {
  const std::lock_guard lock(mutex_);
  Transaction transaction(db_);
  Statement insert(db_, "INSERT INTO runs (id, plan, version, xml, started_at, workcell) VALUES (?, ?, ?, ?, ?, ?)");
  insert.bind(1, record.id).bind(2, record.plan).bind(3, record.version).bind(4, record.xml);
  insert.bind(5, record.started_at).bind(6, record.workcell).run();
  Statement node(db_, "INSERT INTO run_nodes (run, uid, parent, id, name, path) VALUES (?, ?, ?, ?, ?, ?)");
  for (const RunNode& n : nodes) {
    node.reset();
    node.bind(1, record.id).bind(2, static_cast<std::int64_t>(n.uid)).bind(3, n.parent).bind(4, n.id);
    node.bind(5, n.name).bind(6, n.path).run();
  }
  transaction.commit();
}

void Store::appendTransitions(std::int64_t run, const std::vector<TransitionRecord>& transitions) {
  if (transitions.empty()) {
    return;
  }
  const std::lock_guard lock(mutex_);
  Transaction transaction(db_);
  Statement insert(db_,
                   "INSERT INTO transitions (run, seq, t, uid, from_status, to_status, reason, origin, data) "
                   "VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?)");
  for (const TransitionRecord& t : transitions) {
    insert.reset();
    insert.bind(1, run)
        .bind(2, static_cast<std::int64_t>(t.seq))
        .bind(3, t.t)
        .bind(4, static_cast<std::int64_t>(t.uid));
    insert.bind(5, t.from).bind(6, t.to).bind(7, t.reason).bind(8, t.origin).bind(9, t.data).run();
  }
  transaction.commit();
}

void Store::appendStates(std::int64_t run, const std::vector<StateRecord>& states) {
  if (states.empty()) {
    return;
  }
  const std::lock_guard lock(mutex_);
  Transaction transaction(db_);
  Statement next(db_, "SELECT COALESCE(MAX(seq), 0) FROM run_states WHERE run = ?");
  next.bind(1, run);
  next.step();
  std::int64_t seq = next.integer(0);
  Statement insert(db_, "INSERT INTO run_states (run, seq, t, state) VALUES (?, ?, ?, ?)");
  for (const StateRecord& state : states) {
    insert.reset();
    insert.bind(1, run).bind(2, ++seq).bind(3, state.t).bind(4, state.state).run();
  }
  transaction.commit();
}

std::vector<StateRecord> Store::runStates(std::int64_t run) const {
  const std::lock_guard lock(mutex_);
  Statement query(db_, "SELECT t, state FROM run_states WHERE run = ? ORDER BY seq");
  query.bind(1, run);
  std::vector<StateRecord> out;
  while (query.step()) {
    out.push_back({query.real(0), query.text(1)});
  }
  return out;
}

void Store::endRun(const RunRecord& record) {
  const std::lock_guard lock(mutex_);
  Statement update(db_,
                   "UPDATE runs SET result = ?, ended_at = ?, clock_seconds = ?, failure_path = ?, "
                   "failure_reason = ?, transitions = ?, truncated = ? WHERE id = ?");
  update.bind(1, record.result).bind(2, record.ended_at).bind(3, record.clock_seconds).bind(4, record.failure_path);
  update.bind(5, record.failure_reason).bind(6, static_cast<std::int64_t>(record.transitions));
  update.bind(7, record.truncated ? 1 : 0).bind(8, record.id).run();
}

std::vector<RunRecord> Store::runs(std::size_t limit) const {
  const std::lock_guard lock(mutex_);
  Statement query(db_, (std::string("SELECT ") + kRunColumns + " FROM runs ORDER BY id DESC LIMIT ?").c_str());
  query.bind(1, static_cast<std::int64_t>(limit));
  std::vector<RunRecord> out;
  while (query.step()) {
    out.push_back(readRun(query));
    out.back().xml.clear();  // listings do not carry the plan text
  }
  return out;
}

std::optional<RunLog> Store::run(std::int64_t id, const TransitionPage& page, bool with_nodes) const {
  const std::lock_guard lock(mutex_);
  Statement query(db_, (std::string("SELECT ") + kRunColumns + " FROM runs WHERE id = ?").c_str());
  query.bind(1, id);
  if (!query.step()) {
    return std::nullopt;
  }
  RunLog log;
  log.run = readRun(query);
  if (with_nodes) {
    Statement nodes(db_, "SELECT uid, parent, id, name, path FROM run_nodes WHERE run = ? ORDER BY uid");
    nodes.bind(1, id);
    while (nodes.step()) {
      log.nodes.push_back({static_cast<std::uint32_t>(nodes.integer(0)), nodes.integer(1), nodes.text(2), nodes.text(3),
                           nodes.text(4)});
    }
  }
  // One row more than the page holds says where the next page starts.
  Statement transitions(db_,
                        "SELECT seq, t, uid, from_status, to_status, reason, origin, data FROM transitions "
                        "WHERE run = ? AND seq >= ? ORDER BY seq LIMIT ?");
  const auto clamp = [](std::uint64_t value) {
    return static_cast<std::int64_t>(std::min<std::uint64_t>(value, std::numeric_limits<std::int64_t>::max()));
  };
  const std::size_t limit = std::max<std::size_t>(page.limit, 1);
  transitions.bind(1, id).bind(2, clamp(page.from));
  transitions.bind(3, limit == std::numeric_limits<std::size_t>::max() ? clamp(limit) : clamp(limit + 1));
  std::size_t bytes = 0;
  while (transitions.step()) {
    const auto seq = static_cast<std::uint64_t>(transitions.integer(0));
    if (log.transitions.size() >= limit || bytes >= page.max_bytes) {
      log.next_seq = seq;
      break;
    }
    log.transitions.push_back({seq, transitions.real(1), static_cast<std::uint32_t>(transitions.integer(2)),
                               transitions.text(3), transitions.text(4), transitions.text(5), transitions.text(6),
                               transitions.text(7)});
    const TransitionRecord& added = log.transitions.back();
    bytes += added.reason.size() + added.origin.size() + added.data.size() + 64;
  }
  return log;
}

std::int64_t Store::maxRunId() const {
  const std::lock_guard lock(mutex_);
  Statement query(db_, "SELECT COALESCE(MAX(id), 0) FROM runs");
  query.step();
  return query.integer(0);
}

std::string Store::integrityCheck() const {
  const std::lock_guard lock(mutex_);
  Statement query(db_, "PRAGMA integrity_check");
  std::string out;
  while (query.step()) {
    out += (out.empty() ? "" : "; ") + query.text(0);
  }
  return out;
}

}  // namespace costar::server
