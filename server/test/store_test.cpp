// The SQLite store: versions of plans and subtrees, run logs, reopening.

#include "server/store.h"

#include <gtest/gtest.h>
#include <sqlite3.h>

#include <filesystem>

#include "server/auth.h"

namespace costar::server {
namespace {

class StoreTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() / ("costar_store_test_" + randomToken().substr(0, 8));
    std::filesystem::create_directories(dir_);
    file_ = dir_ / "editor.sqlite";
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::filesystem::path dir_;
  std::filesystem::path file_;
};

TEST_F(StoreTest, SavesVersionsAndLoadsThem) {
  Store store(file_);
  EXPECT_EQ(store.save(DocumentKind::kPlan, "pick", "<root>1</root>"), 1);
  EXPECT_EQ(store.save(DocumentKind::kPlan, "pick", "<root>2</root>"), 2);
  EXPECT_EQ(store.save(DocumentKind::kPlan, "place", "<root>a</root>"), 1);
  EXPECT_EQ(store.save(DocumentKind::kSubtree, "pick", "<root>s</root>"), 1);  // another kind, own versions

  EXPECT_EQ(store.load(DocumentKind::kPlan, "pick")->xml, "<root>2</root>");
  EXPECT_EQ(store.load(DocumentKind::kPlan, "pick", 1)->xml, "<root>1</root>");
  EXPECT_FALSE(store.load(DocumentKind::kPlan, "pick", 3));
  EXPECT_FALSE(store.load(DocumentKind::kPlan, "nothing"));
  EXPECT_EQ(store.load(DocumentKind::kSubtree, "pick")->xml, "<root>s</root>");

  const auto plans = store.list(DocumentKind::kPlan);
  ASSERT_EQ(plans.size(), 2u);
  EXPECT_EQ(plans[0].name, "pick");
  EXPECT_EQ(plans[0].latest_version, 2);
  EXPECT_EQ(plans[0].versions, 2);
  const auto versions = store.versions(DocumentKind::kPlan, "pick");
  ASSERT_EQ(versions.size(), 2u);
  EXPECT_EQ(versions[0].version, 2);

  EXPECT_TRUE(store.remove(DocumentKind::kPlan, "pick"));
  EXPECT_FALSE(store.remove(DocumentKind::kPlan, "pick"));
  EXPECT_FALSE(store.load(DocumentKind::kPlan, "pick"));
  EXPECT_EQ(store.integrityCheck(), "ok");
}

TEST_F(StoreTest, KeepsEverythingAcrossReopeningAndUsesWal) {
  {
    Store store(file_);
    store.save(DocumentKind::kPlan, "pick", "<root/>");
    EXPECT_TRUE(std::filesystem::exists(file_.string() + "-wal"));
  }
  Store again(file_);
  EXPECT_EQ(again.load(DocumentKind::kPlan, "pick")->version, 1);
  EXPECT_EQ(again.save(DocumentKind::kPlan, "pick", "<root/>"), 2);
}

TEST_F(StoreTest, RunLogsKeepNodesAndTransitions) {
  Store store(file_);
  EXPECT_EQ(store.maxRunId(), 0);
  RunRecord run;
  run.id = 7;
  run.plan = "pick";
  run.version = 2;
  run.xml = "<root/>";
  run.started_at = 100.0;
  store.beginRun(run,
                 {{0, -1, "Sequence", "main seq", "main/Sequence \"main seq\""}, {1, 0, "Open", "", "main/x/Open[1]"}});
  store.appendTransitions(7, {{1, 0.0, 0, "IDLE", "RUNNING", "", "", ""}, {2, 0.01, 1, "IDLE", "RUNNING", "", "", ""}});
  store.appendTransitions(7, {{3, 0.5, 1, "RUNNING", "FAILURE", "fingers stuck", "main/x/Open[1]", R"({"a":1})"}});
  run.result = "FAILURE";
  run.ended_at = 101.0;
  run.clock_seconds = 0.5;
  run.failure_path = "main/x/Open[1]";
  run.failure_reason = "fingers stuck";
  run.transitions = 3;
  store.endRun(run);

  EXPECT_EQ(store.maxRunId(), 7);
  const auto log = store.run(7);
  ASSERT_TRUE(log);
  EXPECT_EQ(log->run.plan, "pick");
  EXPECT_EQ(log->run.result, "FAILURE");
  EXPECT_EQ(log->run.failure_reason, "fingers stuck");
  ASSERT_EQ(log->nodes.size(), 2u);
  EXPECT_EQ(log->nodes[1].parent, 0);
  EXPECT_EQ(log->nodes[0].name, "main seq");
  ASSERT_EQ(log->transitions.size(), 3u);
  EXPECT_EQ(log->transitions[2].to, "FAILURE");
  EXPECT_EQ(log->transitions[2].data, R"({"a":1})");
  EXPECT_DOUBLE_EQ(log->transitions[2].t, 0.5);
  EXPECT_FALSE(store.run(8));

  const auto runs = store.runs();
  ASSERT_EQ(runs.size(), 1u);
  EXPECT_TRUE(runs[0].xml.empty());  // listings leave the text out
}

TEST_F(StoreTest, ARunLogIsReadAPageAtATime) {
  Store store(file_);
  RunRecord run;
  run.id = 3;
  run.xml = "<root/>";
  store.beginRun(run, {{0, -1, "Sequence", "", "main/Sequence[1]"}});
  std::vector<TransitionRecord> transitions;
  for (std::uint64_t seq = 1; seq <= 10; ++seq) {
    transitions.push_back({seq, 0.0, 0, "IDLE", "RUNNING", "", "", std::string(seq == 7 ? 1000 : 10, 'x')});
  }
  store.appendTransitions(3, transitions);
  EXPECT_FALSE(store.run(3)->next_seq);  // all of it by default
  EXPECT_EQ(store.run(3)->transitions.size(), 10u);
  const auto first = store.run(3, {.from = 1, .limit = 4});
  ASSERT_EQ(first->transitions.size(), 4u);
  EXPECT_EQ(first->transitions.front().seq, 1u);
  EXPECT_EQ(first->next_seq, 5u);
  EXPECT_EQ(first->nodes.size(), 1u);
  const auto last = store.run(3, {.from = 9, .limit = 4}, /*with_nodes=*/false);
  ASSERT_EQ(last->transitions.size(), 2u);
  EXPECT_EQ(last->transitions.back().seq, 10u);
  EXPECT_FALSE(last->next_seq);
  EXPECT_TRUE(last->nodes.empty());
  // The byte limit ends a page after the transition that reaches it (at least one).
  const auto by_bytes = store.run(3, {.from = 5, .max_bytes = 500});
  ASSERT_EQ(by_bytes->transitions.size(), 3u);  // 5, 6 and 7 (1,000 bytes of data)
  EXPECT_EQ(by_bytes->next_seq, 8u);
  EXPECT_EQ(store.run(3, {.from = 7, .max_bytes = 1})->transitions.size(), 1u);
  EXPECT_TRUE(store.run(3, {.from = 11})->transitions.empty());
}

TEST_F(StoreTest, RunsLeftOpenByADeadServerAreMarkedInterrupted) {
  {
    Store store(file_);
    RunRecord run;
    run.id = 1;
    run.xml = "<root/>";
    store.beginRun(run, {});
  }
  Store again(file_);
  EXPECT_EQ(again.run(1)->run.result, "INTERRUPTED");
}

// Runs name their cell and keep snapshots of it, oldest first.
TEST_F(StoreTest, RunsKeepTheirCellAndSnapshotsInOrder) {
  Store store(file_);
  RunRecord run;
  run.id = 3;
  run.workcell = "iiwa-3f-sim";
  store.beginRun(run, {});
  store.appendStates(3, {{0.0, R"({"t":0})"}, {0.2, R"({"t":0.2})"}});
  store.appendStates(3, {{0.4, R"({"t":0.4})"}});
  const auto states = store.runStates(3);
  ASSERT_EQ(states.size(), 3u);
  EXPECT_DOUBLE_EQ(states[2].t, 0.4);
  EXPECT_EQ(states[1].state, R"({"t":0.2})");
  EXPECT_TRUE(store.runStates(4).empty());
  EXPECT_EQ(store.runs()[0].workcell, "iiwa-3f-sim");
  EXPECT_EQ(store.run(3)->run.workcell, "iiwa-3f-sim");
}

// A store written before runs named their cell opens with its runs intact (an empty cell name)
// and logs new runs with theirs.
TEST_F(StoreTest, AStoreFromBeforeRunsNamedTheirCellGetsTheColumn) {
  {
    sqlite3* db = nullptr;
    ASSERT_EQ(sqlite3_open(file_.c_str(), &db), SQLITE_OK);
    ASSERT_EQ(sqlite3_exec(db,
                           "CREATE TABLE runs (id INTEGER PRIMARY KEY, plan TEXT NOT NULL, version INTEGER NOT NULL, "
                           "xml TEXT NOT NULL, started_at REAL NOT NULL, result TEXT NOT NULL DEFAULT '', ended_at "
                           "REAL NOT NULL DEFAULT 0, clock_seconds REAL NOT NULL DEFAULT 0, failure_path TEXT NOT NULL "
                           "DEFAULT '', failure_reason TEXT NOT NULL DEFAULT '', transitions INTEGER NOT NULL DEFAULT "
                           "0, truncated INTEGER NOT NULL DEFAULT 0);"
                           "INSERT INTO runs (id, plan, version, xml, started_at, result) "
                           "VALUES (1, 'old', 2, '<root/>', 1.0, 'SUCCESS');",
                           nullptr, nullptr, nullptr),
              SQLITE_OK);
    sqlite3_close(db);
  }
  Store store(file_);
  const auto old = store.run(1);
  ASSERT_TRUE(old);
  EXPECT_EQ(old->run.plan, "old");
  EXPECT_EQ(old->run.result, "SUCCESS");
  EXPECT_EQ(old->run.workcell, "");
  RunRecord next;
  next.id = 2;
  next.workcell = "ur5-sim";
  store.beginRun(next, {});
  EXPECT_EQ(store.runs()[0].workcell, "ur5-sim");
  Store again(file_);  // opening it again adds nothing twice
  EXPECT_EQ(again.runs().size(), 2u);
}

TEST_F(StoreTest, RefusesAFileItCannotOpen) {
  std::filesystem::create_directories(dir_ / "a_folder");
  EXPECT_THROW(Store(dir_ / "a_folder"), StoreError);
}

}  // namespace
}  // namespace costar::server
