// The store's side of the operations a job service needs: checkpoint paths that survive a move of
// the data folder, errors that never show SQL, labels, deletion, retention and the event log.
#include <gtest/gtest.h>
#include <sqlite3.h>

#include <filesystem>
#include <string>

#include "store/job_store.h"
#include "store/job_store_fixture.h"

namespace seep::service {
namespace {

// What migrations v14, v13, v12, v11 and v10 did, undone again (before a PRAGMA user_version).
// (The tests of v13 and earlier leave results as v14 made them: v14 run again on it copies it.)
constexpr const char* kWithoutV14 =
    "CREATE TABLE results_rowid (job_id TEXT NOT NULL REFERENCES jobs(id) ON DELETE CASCADE, "
    "name TEXT NOT NULL, value REAL NOT NULL, PRIMARY KEY (job_id, name)) STRICT; "
    "INSERT INTO results_rowid SELECT job_id, name, value FROM results; DROP TABLE results; "
    "ALTER TABLE results_rowid RENAME TO results; ";
constexpr const char* kWithoutV13 =
    "ALTER TABLE checkpoints DROP COLUMN content; CREATE INDEX jobs_by_state ON jobs(state); ";
constexpr const char* kWithoutV12 =
    "DROP TABLE batch_jobs; DROP INDEX jobs_by_batch_job; ALTER TABLE jobs DROP COLUMN "
    "batch_job_id; ALTER TABLE jobs DROP COLUMN batch_node; ";
constexpr const char* kWithoutV11 =
    "DROP INDEX jobs_by_parent; ALTER TABLE jobs DROP COLUMN parent_job_id; "
    "ALTER TABLE jobs DROP COLUMN parent_step; ";
constexpr const char* kWithoutV10 =
    "ALTER TABLE jobs DROP COLUMN stage_index; ALTER TABLE jobs DROP COLUMN stage_count; "
    "ALTER TABLE jobs DROP COLUMN stage_name; ";

class StoreOperations : public JobStoreTest {
 protected:
  // Claims job `id` (queued alone) and records checkpoints at `steps`, `bytes` each, under the
  // data folder's checkpoints/<id>/; returns the lease epoch.
  std::int64_t ClaimWithCheckpoints(const std::string& id,
                                    std::initializer_list<std::uint64_t> steps,
                                    std::int64_t bytes = 100, std::int64_t created_at_ms = 0) {
    auto claimed = store_->ClaimNextQueued("w", 100, 1'000'000);
    EXPECT_TRUE(claimed.ok() && claimed->has_value());
    if (!claimed.ok() || !claimed->has_value()) return 0;
    EXPECT_EQ((*claimed)->id, id);
    const std::int64_t epoch = (*claimed)->lease_epoch;
    for (const std::uint64_t step : steps) {
      CheckpointRecord c;
      c.step = step;
      c.path = CheckpointPath(id, step).string();
      c.bytes = bytes;
      c.created_at_ms = created_at_ms + static_cast<std::int64_t>(step);
      EXPECT_TRUE(store_->RecordCheckpoint(id, epoch, c, /*keep=*/100).ok());
    }
    return epoch;
  }
  std::filesystem::path CheckpointPath(const std::string& id, std::uint64_t step) const {
    return dir_ / "checkpoints" / id / ("ckpt-" + std::to_string(step) + ".bin");
  }
  // One column of one row, read with SQLite directly (what the store keeps, not what it returns).
  std::string RawText(const std::string& sql) const {
    sqlite3* db = nullptr;
    EXPECT_EQ(sqlite3_open(path_.c_str(), &db), SQLITE_OK);
    sqlite3_stmt* stmt = nullptr;
    std::string out;
    if (sqlite3_prepare_v2(db, sql.c_str(), -1, &stmt, nullptr) == SQLITE_OK &&
        sqlite3_step(stmt) == SQLITE_ROW) {
      const auto* text = sqlite3_column_text(stmt, 0);
      out = text != nullptr ? reinterpret_cast<const char*>(text) : "";
    }
    sqlite3_finalize(stmt);
    sqlite3_close(db);
    return out;
  }
  // Closes the store, runs `sql` on its database (to make it what an older seepd left) and opens
  // it again, which migrates it to the current schema.
  void ReopenAfter(const std::string& sql) {
    store_.reset();
    RawExec(sql);
    auto reopened = JobStore::Open(path_);
    ASSERT_TRUE(reopened.ok()) << reopened.status().ToString();
    store_ = std::move(*reopened);
    EXPECT_EQ(RawText("PRAGMA user_version"), std::to_string(JobStore::kSchemaVersion));
  }
  void RawExec(const std::string& sql) const {
    sqlite3* db = nullptr;
    ASSERT_EQ(sqlite3_open(path_.c_str(), &db), SQLITE_OK);
    ASSERT_EQ(sqlite3_exec(db, sql.c_str(), nullptr, nullptr, nullptr), SQLITE_OK)
        << sqlite3_errmsg(db);
    sqlite3_close(db);
  }
};

TEST_F(StoreOperations, CheckpointPathsAreStoredRelativeAndFollowAMovedDataFolder) {
  ASSERT_TRUE(store_->Insert(NewJob("a")).ok());
  ClaimWithCheckpoints("a", {10});
  EXPECT_EQ(RawText("SELECT path FROM checkpoints"), "checkpoints/a/ckpt-10.bin");
  EXPECT_EQ(store_->ListCheckpoints("a")->at(0).path, CheckpointPath("a", 10).string());

  // A path outside the data folder stays absolute.
  CheckpointRecord outside;
  outside.step = 20;
  outside.path = "/elsewhere/ckpt-20.bin";
  const std::int64_t epoch = store_->Get("a")->lease_epoch;
  ASSERT_TRUE(store_->RecordCheckpoint("a", epoch, outside, 100).ok());
  EXPECT_EQ(store_->ListCheckpoints("a")->at(0).path, "/elsewhere/ckpt-20.bin");

  store_.reset();
  const std::filesystem::path moved = dir_.string() + "-moved";
  std::filesystem::remove_all(moved);
  std::filesystem::rename(dir_, moved);
  auto reopened = JobStore::Open((moved / "seep.db").string());
  ASSERT_TRUE(reopened.ok()) << reopened.status().ToString();
  const auto listed = (*reopened)->ListCheckpoints("a");
  ASSERT_TRUE(listed.ok());
  ASSERT_EQ(listed->size(), 2u);
  EXPECT_EQ((*listed)[1].path, (moved / "checkpoints" / "a" / "ckpt-10.bin").string());
  EXPECT_EQ((*reopened)->AllCheckpointPaths()->size(), 2u);
  reopened->reset();
  std::filesystem::rename(moved, dir_);
}

// Databases written before v7 hold the paths seepd was given: absolute, or relative to the folder
// seepd ran in. The migration makes those of the checkpoint layout relative to the data folder.
TEST_F(StoreOperations, MigrationSevenMakesOldCheckpointPathsRelative) {
  ASSERT_TRUE(store_->Insert(NewJob("j-1")).ok());
  ClaimWithCheckpoints("j-1", {5});
  ASSERT_NO_FATAL_FAILURE(ReopenAfter(
      std::string(kWithoutV13) +
      std::string(
          "INSERT INTO jobs (id, name, state, scene, build_id, created_at_ms) VALUES ('j-2', "
          "'n', 'FAILED', x'00', 'b', 1);"
          "UPDATE checkpoints SET path = "
          "'/old/place/seep-data/checkpoints/j-1/ckpt-000000000005.bin';"
          "INSERT INTO checkpoints VALUES ('j-1', 7, 0, "
          "'seep-data/checkpoints/j-1/ckpt-000000000007.bin', 1, 1, 1);"
          "INSERT INTO checkpoints VALUES ('j-2', 9, 0, '/somewhere/else.bin', 1, 1, 1);") +
      kWithoutV12 + kWithoutV11 + kWithoutV10 +
      "DROP TABLE sweep_jobs; DROP TABLE sweeps; DROP TABLE job_labels; DROP INDEX "
      "jobs_by_finished; PRAGMA user_version = 6;"));
  EXPECT_EQ(RawText("SELECT path FROM checkpoints WHERE step = 5"),
            "checkpoints/j-1/ckpt-000000000005.bin");
  EXPECT_EQ(RawText("SELECT path FROM checkpoints WHERE step = 7"),
            "checkpoints/j-1/ckpt-000000000007.bin");
  EXPECT_EQ(RawText("SELECT path FROM checkpoints WHERE step = 9"), "/somewhere/else.bin");
  EXPECT_EQ(store_->ListCheckpoints("j-1")->at(1).path,
            (dir_ / "checkpoints" / "j-1" / "ckpt-000000000005.bin").string());
}

// A database from before v10 has no stage columns: its jobs read back without a stage, and a
// running job's progress stores one after the migration.
TEST_F(StoreOperations, MigrationTenAddsTheStageColumns) {
  ASSERT_TRUE(store_->Insert(NewJob("j-1")).ok());
  const std::int64_t epoch = ClaimWithCheckpoints("j-1", {});
  ASSERT_TRUE(store_->UpdateProgress("j-1", epoch, JobProgress::At(4, 0.5, 0.25, 0)).ok());
  ASSERT_NO_FATAL_FAILURE(ReopenAfter(std::string(kWithoutV13) + kWithoutV12 + kWithoutV11 +
                                      kWithoutV10 + "PRAGMA user_version = 9;"));
  auto old = store_->Get("j-1");
  ASSERT_TRUE(old.ok()) << old.status().ToString();
  EXPECT_EQ(old->progress.step, 4u);
  EXPECT_EQ(old->progress.stage_index, 0u);
  EXPECT_EQ(old->progress.stage_count, 0u);
  EXPECT_EQ(old->progress.stage_name, "");

  JobProgress staged = JobProgress::At(5, 0.6, 0.3, 0);
  staged.stage_index = 1;
  staged.stage_count = 2;
  staged.stage_name = "confine";
  ASSERT_TRUE(store_->UpdateProgress("j-1", epoch, staged).ok());
  EXPECT_EQ(RawText("SELECT stage_index || '/' || stage_count || ' ' || stage_name FROM jobs"),
            "1/2 confine");
  EXPECT_EQ(store_->Get("j-1")->progress.stage_name, "confine");
}

// A database from before v11 has no parent columns: its jobs read back as no fork's, and a fork
// can be stored after the migration.
TEST_F(StoreOperations, MigrationElevenAddsTheParentColumns) {
  ASSERT_TRUE(store_->Insert(NewJob("j-1")).ok());
  ASSERT_NO_FATAL_FAILURE(ReopenAfter(std::string(kWithoutV13) + kWithoutV12 + kWithoutV11 +
                                      "PRAGMA user_version = 10;"));
  auto old = store_->Get("j-1");
  ASSERT_TRUE(old.ok()) << old.status().ToString();
  EXPECT_FALSE(old->parent_job_id.has_value());
  EXPECT_TRUE(old->child_job_ids.empty());
  JobRecord fork = NewJob("j-2");
  fork.parent_job_id = "j-1";
  fork.parent_step = 40;
  CheckpointRecord start;
  start.step = 40;
  start.path = CheckpointPath("j-2", 40).string();
  ASSERT_TRUE(store_->InsertFork(fork, start).ok());
  EXPECT_EQ(store_->Get("j-1")->child_job_ids, std::vector<std::string>{"j-2"});
  EXPECT_EQ(RawText("SELECT parent_job_id || ' ' || parent_step FROM jobs WHERE id = 'j-2'"),
            "j-1 40");
}

// A database from before v12 has no batch columns or table: its running job reads back without
// a placement, and after the migration a claim records one and a batch job is kept.
TEST_F(StoreOperations, MigrationTwelveAddsTheBatchJobs) {
  ASSERT_TRUE(store_->Insert(NewJob("j-1")).ok());
  ASSERT_TRUE(store_->Insert(NewJob("j-2")).ok());
  ClaimWithCheckpoints("j-1", {});
  ASSERT_NO_FATAL_FAILURE(
      ReopenAfter(std::string(kWithoutV13) + kWithoutV12 + "PRAGMA user_version = 11;"));
  auto old = store_->Get("j-1");
  ASSERT_TRUE(old.ok()) << old.status().ToString();
  EXPECT_EQ(old->state, JobState::kRunning);
  EXPECT_FALSE(old->placement.has_value());
  auto claimed =
      store_->ClaimNextQueued("w", 100, 1000, JobKind::kSimulation, WorkerPlacement{"31", "n1"});
  ASSERT_TRUE(claimed.ok() && claimed->has_value());
  EXPECT_EQ(RawText("SELECT batch_job_id || ' ' || batch_node FROM jobs WHERE id = 'j-2'"),
            "31 n1");
  BatchJobRecord batch;
  batch.id = "31";
  batch.state = "RUNNING";
  ASSERT_TRUE(store_->InsertBatchJob(batch).ok());
  EXPECT_EQ(store_->LiveBatchJobs()->size(), 1u);
}

// A database from before v13 keeps every checkpoint in a file and has jobs_by_state: its records
// read back as files, the index is gone after the migration, and a success can then keep its
// final state in the store.
TEST_F(StoreOperations, MigrationThirteenLetsARecordHoldItsCheckpoint) {
  ASSERT_TRUE(store_->Insert(NewJob("j-1")).ok());
  const std::int64_t epoch = ClaimWithCheckpoints("j-1", {5});
  ASSERT_NO_FATAL_FAILURE(ReopenAfter(std::string(kWithoutV13) + "PRAGMA user_version = 12;"));
  EXPECT_EQ(RawText("SELECT count(*) FROM sqlite_master WHERE name = 'jobs_by_state'"), "0");
  auto old = store_->ListCheckpoints("j-1");
  ASSERT_TRUE(old.ok()) << old.status().ToString();
  ASSERT_EQ(old->size(), 1u);
  EXPECT_EQ((*old)[0].path, CheckpointPath("j-1", 5).string());
  EXPECT_EQ((*old)[0].content, "");

  CheckpointRecord final_state;
  final_state.step = 9;
  final_state.content = "state";
  RunSuccess run;
  run.series_columns = {"time_s"};
  run.series_values = {0.0};
  ASSERT_TRUE(store_->RecordSuccess("j-1", epoch, run, &final_state, 3, 50).ok());
  EXPECT_EQ(RawText("SELECT path || '|' || content FROM checkpoints WHERE step = 9"), "|state");
  EXPECT_EQ(store_->Get("j-1")->state, JobState::kSucceeded);
}

// A database from before v14 keeps each metric as a row and an entry of its key's index: after
// the migration every metric is there, in one b-tree without rowids, and new ones go in too.
TEST_F(StoreOperations, MigrationFourteenKeepsEveryMetricInOneBTree) {
  ASSERT_TRUE(store_->Insert(NewJob("j-1")).ok());
  RunSuccess run;
  run.series_columns = {"time_s"};
  run.series_values = {0.0};
  run.metrics = {{"k", 2.5}, {"q", -1.0}};
  ASSERT_TRUE(
      store_->RecordSuccess("j-1", ClaimWithCheckpoints("j-1", {}), run, nullptr, 3, 50).ok());
  store_.reset();
  RawExec(std::string(kWithoutV14) + "PRAGMA user_version = 13;");
  const std::string kAutoindex =
      "SELECT count(*) FROM sqlite_master WHERE name = 'sqlite_autoindex_results_1'";
  ASSERT_EQ(RawText(kAutoindex), "1");  // what v13 had: a rowid table and its key's index
  ASSERT_NO_FATAL_FAILURE(ReopenAfter(""));
  EXPECT_EQ(RawText(kAutoindex), "0");
  EXPECT_NE(RawText("SELECT sql FROM sqlite_master WHERE name = 'results'").find("WITHOUT ROWID"),
            std::string::npos);
  const std::vector<std::pair<std::string, double>> expected = {{"k", 2.5}, {"q", -1.0}};
  EXPECT_EQ(store_->Get("j-1")->metrics, expected);

  ASSERT_TRUE(store_->Insert(NewJob("j-2")).ok());
  run.metrics = {{"z", 7.0}, {"a", 1.0}};
  ASSERT_TRUE(
      store_->RecordSuccess("j-2", ClaimWithCheckpoints("j-2", {}), run, nullptr, 3, 60).ok());
  const std::vector<std::pair<std::string, double>> sorted = {{"a", 1.0}, {"z", 7.0}};
  EXPECT_EQ(store_->Get("j-2")->metrics, sorted);
  ASSERT_TRUE(store_->Delete("j-1").ok());
  EXPECT_EQ(RawText("SELECT count(*) FROM results"), "2");  // j-1's went with it
}

// A failing statement: the Status names the operation and SQLite's generic reason, never the SQL
// or the schema (tables, columns) SQLite's own message would name.
TEST_F(StoreOperations, ASqlFailureNamesTheOperationAndNoSql) {
  ASSERT_TRUE(store_->Insert(NewJob("a")).ok());
  RawExec("DROP TABLE events");
  const core::Status s = store_->AddEvent("a", 1, "X", "y");
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.code(), core::StatusCode::kInternal);
  EXPECT_EQ(s.message().rfind("store: add event failed: ", 0), 0u) << s.message();
  for (const char* leak : {"INSERT", "SELECT", "events", "no such table", "job_id"}) {
    EXPECT_EQ(s.message().find(leak), std::string::npos) << leak << " in: " << s.message();
  }
}

TEST_F(StoreOperations, LabelsComeBackSortedAndEveryFilterLabelMustMatch) {
  JobRecord a = NewJob("a");
  a.labels = {{"team", "flow"}, {"owner", "ana"}};
  JobRecord b = NewJob("b");
  b.labels = {{"owner", "ana"}};
  JobRecord c = NewJob("c");
  c.labels = {{"owner", "bo"}, {"team", "flow"}};
  for (const JobRecord& job : {a, b, c}) ASSERT_TRUE(store_->Insert(job).ok());
  EXPECT_EQ(store_->Get("a")->labels,
            (std::vector<std::pair<std::string, std::string>>{{"owner", "ana"}, {"team", "flow"}}));
  const auto ids = [&](std::vector<std::pair<std::string, std::string>> labels) {
    JobFilter filter;
    filter.labels = std::move(labels);
    std::vector<std::string> out;
    const auto page = store_->List(10, std::nullopt, filter);
    EXPECT_TRUE(page.ok()) << page.status().ToString();
    if (!page.ok()) return out;
    for (const JobRecord& job : page->jobs) out.push_back(job.id);
    return out;
  };
  EXPECT_EQ(ids({{"owner", "ana"}}), (std::vector<std::string>{"b", "a"}));
  EXPECT_EQ(ids({{"owner", "ana"}, {"team", "flow"}}), (std::vector<std::string>{"a"}));
  EXPECT_EQ(ids({{"team", "flow"}}), (std::vector<std::string>{"c", "a"}));
  EXPECT_TRUE(ids({{"owner", "carl"}}).empty());
  EXPECT_TRUE(ids({{"Owner", "ana"}}).empty());  // keys match exactly
  // A listing carries the labels too.
  EXPECT_EQ(store_->List(1, std::nullopt)->jobs.at(0).labels.size(), 2u);

  // The same request id with other labels is not the same submission.
  JobRecord first = NewJob("d", "req");
  first.labels = {{"k", "1"}};
  ASSERT_TRUE(store_->Insert(first).ok());
  JobRecord other = NewJob("e", "req");
  other.labels = {{"k", "2"}};
  const auto clash = store_->Insert(other);
  EXPECT_EQ(clash.status().code(), core::StatusCode::kAlreadyExists);
  EXPECT_NE(clash.status().message().find("with a different scene or labels"), std::string::npos);
  JobRecord again = NewJob("f", "req");
  again.labels = {{"k", "1"}};
  EXPECT_FALSE(store_->Insert(again)->created);
}

TEST_F(StoreOperations, DeleteRemovesAFinishedJobWithEverythingAndRefusesAnActiveOne) {
  ASSERT_TRUE(store_->Insert(NewJob("done")).ok());
  const std::int64_t epoch = ClaimWithCheckpoints("done", {10, 20});
  ASSERT_TRUE(store_->StoreResultSeries("done", epoch, {"time_s"}, {0.0}, "ab").ok());
  ASSERT_TRUE(
      store_->Finish("done", epoch, JobState::kSucceeded, "", "", {{"k", 1.0}}, 1.0, 500).ok());
  JobRecord labelled = NewJob("queued");
  labelled.labels = {{"a", "b"}};
  ASSERT_TRUE(store_->Insert(labelled).ok());

  const auto refused = store_->Delete("queued");
  EXPECT_EQ(refused.status().code(), core::StatusCode::kFailedPrecondition);
  EXPECT_NE(refused.status().message().find("job queued is QUEUED; only a finished job"),
            std::string::npos)
      << refused.status().message();
  EXPECT_EQ(store_->Delete("missing").status().code(), core::StatusCode::kNotFound);

  const auto removed = store_->Delete("done");
  ASSERT_TRUE(removed.ok()) << removed.status().ToString();
  ASSERT_EQ(removed->size(), 2u);
  EXPECT_EQ((*removed)[0].path, CheckpointPath("done", 20).string());
  EXPECT_EQ(store_->Get("done").status().code(), core::StatusCode::kNotFound);
  for (const char* table : {"results", "result_series", "checkpoints", "events"}) {
    EXPECT_EQ(RawText(std::string("SELECT COUNT(*) FROM ") + table + " WHERE job_id = 'done'"), "0")
        << table;
  }
  // The other job and its labels are untouched.
  EXPECT_EQ(store_->Get("queued")->labels.size(), 1u);
  EXPECT_EQ(RawText("SELECT COUNT(*) FROM events WHERE job_id = 'queued'"), "1");
}

// Retention by age deletes the finished jobs older than the limit only; the byte budget removes
// finished jobs' checkpoints, superseded ones first, oldest first, and stops as soon as the total
// fits; queued and running jobs keep every checkpoint.
TEST_F(StoreOperations, RetentionDeletesWhatItShouldAndNothingElse) {
  const auto finish = [&](const std::string& id, std::int64_t epoch, std::int64_t at_ms) {
    ASSERT_TRUE(store_->Finish(id, epoch, JobState::kFailed, "INTERNAL", "x", {}, 1.0, at_ms).ok());
  };
  ASSERT_TRUE(store_->Insert(NewJob("old")).ok());
  finish("old", ClaimWithCheckpoints("old", {1, 2}, 100, 0), 1'000);
  ASSERT_TRUE(store_->Insert(NewJob("recent")).ok());
  finish("recent", ClaimWithCheckpoints("recent", {1, 2, 3}, 100, 10'000), 50'000);
  ASSERT_TRUE(store_->Insert(NewJob("recent2")).ok());
  finish("recent2", ClaimWithCheckpoints("recent2", {1, 2}, 100, 5'000), 50'000);
  ASSERT_TRUE(store_->Insert(NewJob("running")).ok());
  ClaimWithCheckpoints("running", {1, 2}, 100, 0);     // the oldest files of all
  ASSERT_TRUE(store_->Insert(NewJob("queued")).ok());  // cancelled, then resumed: QUEUED
  const std::int64_t queued_epoch = ClaimWithCheckpoints("queued", {1}, 100, 0);
  ASSERT_TRUE(
      store_->Finish("queued", queued_epoch, JobState::kCancelled, "CANCELLED", "", {}, 1.0, 1'000)
          .ok());
  ASSERT_EQ(store_->Resume("queued")->state, JobState::kQueued);

  RetentionPolicy policy;
  policy.max_age_ms = 10'000;
  // 8 files of 100 bytes after "old" is gone. A budget of 550 takes recent2 step 1, then recent
  // steps 1 and 2 (the superseded ones, oldest first) and stops at 500.
  policy.max_checkpoint_bytes = 550;
  const auto outcome = store_->ApplyRetention(policy, 60'000);
  ASSERT_TRUE(outcome.ok()) << outcome.status().ToString();
  EXPECT_EQ(outcome->deleted_jobs, std::vector<std::string>{"old"});
  EXPECT_EQ(outcome->checkpoints_over_budget, 3);
  EXPECT_EQ(outcome->checkpoint_bytes_left, 500);
  std::vector<std::string> removed;
  for (const CheckpointRecord& c : outcome->removed_checkpoints) {
    removed.push_back(c.job_id + "/" + std::to_string(c.step));
  }
  EXPECT_EQ(removed,
            (std::vector<std::string>{"old/1", "old/2", "recent2/1", "recent/1", "recent/2"}));
  EXPECT_EQ(outcome->removed_checkpoints.at(2).path, CheckpointPath("recent2", 1).string());
  EXPECT_EQ(store_->Get("old").status().code(), core::StatusCode::kNotFound);
  EXPECT_EQ(store_->ListCheckpoints("recent")->size(), 1u);
  EXPECT_EQ(store_->ListCheckpoints("recent2")->size(), 1u);
  EXPECT_EQ(store_->ListCheckpoints("running")->size(), 2u);
  EXPECT_EQ(store_->ListCheckpoints("queued")->size(), 1u);
  const auto events = store_->ListEvents("recent").value();
  EXPECT_EQ(events.back().kind, "CHECKPOINTS_RETAINED");
  EXPECT_NE(events.back().message.find("2 checkpoint(s), 200 bytes, removed"), std::string::npos);

  // A budget no finished job can meet: every finished job's checkpoint goes, the active ones stay.
  policy.max_age_ms = 0;
  policy.max_checkpoint_bytes = 1;
  const auto tight = store_->ApplyRetention(policy, 60'000);
  ASSERT_TRUE(tight.ok());
  EXPECT_EQ(tight->checkpoints_over_budget, 2);  // the final ones of recent and recent2
  EXPECT_EQ(tight->checkpoint_bytes_left, 300);
  EXPECT_TRUE(store_->ListCheckpoints("recent")->empty());
  EXPECT_EQ(store_->ListCheckpoints("running")->size(), 2u);
  EXPECT_EQ(store_->ListCheckpoints("queued")->size(), 1u);
  EXPECT_EQ(store_->Get("recent")->state, JobState::kFailed);  // the job itself stays
}

TEST_F(StoreOperations, EventsRecordTheJobsLifeAndPageByCursor) {
  ASSERT_TRUE(store_->Insert(NewJob("a")).ok());
  const std::int64_t epoch = ClaimWithCheckpoints("a", {10});
  ASSERT_TRUE(store_->Cancel("a", 200).ok());
  ASSERT_TRUE(
      store_->Finish("a", epoch, JobState::kCancelled, "CANCELLED", "by the user", {}, 1.0, 300)
          .ok());
  ASSERT_TRUE(store_->Resume("a").ok());
  const auto events = store_->ListEvents("a").value();
  std::vector<std::string> kinds;
  for (const JobEventRecord& e : events) kinds.push_back(e.kind);
  EXPECT_EQ(kinds, (std::vector<std::string>{"SUBMITTED", "CLAIMED", "CHECKPOINT",
                                             "CANCEL_REQUESTED", "CANCELLED", "RESUME_REQUESTED"}));
  // The claim records itself, in its own transaction.
  EXPECT_EQ(events[1].message, "attempt 1 by w (lease epoch 1)");
  EXPECT_EQ(events[1].at_ms, 100);
  EXPECT_EQ(events[2].message, "step 10 (t = 0 s), 100 bytes, attempt 1");
  EXPECT_EQ(events[4].message, "CANCELLED: by the user");
  EXPECT_EQ(events[4].at_ms, 300);
  EXPECT_EQ(events[5].message, "attempt 2 queued (was CANCELLED)");
  const auto page = store_->ListEvents("a", events[2].id, 2).value();
  ASSERT_EQ(page.size(), 2u);
  EXPECT_EQ(page[0].kind, "CANCEL_REQUESTED");
  EXPECT_EQ(page[1].kind, "CANCELLED");
  EXPECT_EQ(store_->ListEvents("missing").status().code(), core::StatusCode::kNotFound);

  // A restart that finds it running queues it again and says so.
  ASSERT_TRUE(store_->ClaimNextQueued("old-process", 400, 1000).value().has_value());
  ASSERT_EQ(store_->RequeueRunning("new-process").value(), 1);
  EXPECT_EQ(store_->ListEvents("a").value().back().kind, "RECOVERED");
}

}  // namespace
}  // namespace seep::service
