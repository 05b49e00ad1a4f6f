#include "job_store.h"

#include <fmt/format.h>

#include "sqlite_handle.h"

namespace seep::service {
namespace {

// Schema migrations, applied in order inside one write transaction each; index i brings the
// database from user_version i to i + 1.
constexpr const char* kMigrations[] = {
    R"sql(
CREATE TABLE jobs (
  id TEXT PRIMARY KEY,
  request_id TEXT UNIQUE,
  name TEXT NOT NULL,
  state TEXT NOT NULL CHECK (state IN ('QUEUED','RUNNING','SUCCEEDED','FAILED','CANCELLED')),
  scene BLOB NOT NULL,
  build_id TEXT NOT NULL,
  created_at_ms INTEGER NOT NULL,
  started_at_ms INTEGER,
  finished_at_ms INTEGER,
  step INTEGER NOT NULL DEFAULT 0,
  time_s REAL NOT NULL DEFAULT 0,
  fraction_done REAL NOT NULL DEFAULT 0,
  error_code TEXT NOT NULL DEFAULT '',
  error_message TEXT NOT NULL DEFAULT '',
  wall_time_s REAL NOT NULL DEFAULT 0
) STRICT;
CREATE INDEX jobs_by_state ON jobs(state);
CREATE TABLE results (
  job_id TEXT NOT NULL REFERENCES jobs(id) ON DELETE CASCADE,
  name TEXT NOT NULL,
  value REAL NOT NULL,
  PRIMARY KEY (job_id, name)
) STRICT;
)sql",
};
constexpr int kMigrationCount = static_cast<int>(std::size(kMigrations));
static_assert(kMigrationCount == JobStore::kSchemaVersion);

constexpr const char* kJobColumns =
    "rowid, id, request_id, name, state, build_id, created_at_ms, started_at_ms, "
    "finished_at_ms, step, time_s, fraction_done, error_code, error_message, wall_time_s";

JobRecord ReadJobRow(const Stmt& s) {
  JobRecord job;
  job.id = s.ColumnText(1);
  if (!s.ColumnIsNull(2)) job.request_id = s.ColumnText(2);
  job.name = s.ColumnText(3);
  job.state = ParseJobState(s.ColumnText(4)).value_or(JobState::kFailed);
  job.build_id = s.ColumnText(5);
  job.created_at_ms = s.ColumnInt(6);
  if (!s.ColumnIsNull(7)) job.started_at_ms = s.ColumnInt(7);
  if (!s.ColumnIsNull(8)) job.finished_at_ms = s.ColumnInt(8);
  job.progress.step = static_cast<std::uint64_t>(s.ColumnInt(9));
  job.progress.time_s = s.ColumnDouble(10);
  job.progress.fraction_done = s.ColumnDouble(11);
  job.error_code = s.ColumnText(12);
  job.error_message = s.ColumnText(13);
  job.wall_time_s = s.ColumnDouble(14);
  return job;
}

}  // namespace

Result<std::unique_ptr<JobStore>> JobStore::Open(const std::string& path) {
  SEEP_ASSIGN_OR_RETURN(Db db, Db::Open(path));
  // WAL for concurrent readers; FULL so that an acknowledged submit or a terminal state survives
  // power loss, not only a process crash.
  SEEP_RETURN_IF_ERROR(
      db.Exec("PRAGMA busy_timeout=5000; PRAGMA journal_mode=WAL; PRAGMA synchronous=FULL; "
              "PRAGMA foreign_keys=ON;"));
  std::unique_ptr<JobStore> store(new JobStore(std::make_unique<Db>(std::move(db))));
  SEEP_RETURN_IF_ERROR(store->Migrate());
  return store;
}

JobStore::JobStore(std::unique_ptr<Db> db) : db_(std::move(db)) {}
JobStore::~JobStore() = default;

Status JobStore::Migrate() {
  std::lock_guard lock(mutex_);
  SEEP_ASSIGN_OR_RETURN(Stmt version_stmt, db_->Prepare("PRAGMA user_version"));
  SEEP_ASSIGN_OR_RETURN(const bool has_row, version_stmt.Step());
  const int version = has_row ? static_cast<int>(version_stmt.ColumnInt(0)) : 0;
  if (version > kSchemaVersion) {
    return core::FailedPrecondition(fmt::format(
        "store: database schema version {} is newer than this seepd understands ({}); use a newer "
        "seepd or another --data-dir",
        version, kSchemaVersion));
  }
  for (int v = version; v < kSchemaVersion; ++v) {
    SEEP_ASSIGN_OR_RETURN(WriteTx tx, WriteTx::Begin(*db_));
    SEEP_RETURN_IF_ERROR(db_->Exec(kMigrations[v]));
    SEEP_RETURN_IF_ERROR(db_->Exec(fmt::format("PRAGMA user_version={}", v + 1)));
    SEEP_RETURN_IF_ERROR(tx.Commit());
  }
  return Status::Ok();
}

Result<std::optional<std::string>> JobStore::FindByRequestIdLocked(const std::string& request_id) {
  SEEP_ASSIGN_OR_RETURN(Stmt s, db_->Prepare("SELECT id FROM jobs WHERE request_id = ?"));
  s.Bind(1, std::string_view(request_id));
  SEEP_ASSIGN_OR_RETURN(const bool row, s.Step());
  if (!row) return std::optional<std::string>();
  return std::optional<std::string>(s.ColumnText(0));
}

Result<InsertOutcome> JobStore::Insert(const JobRecord& job) {
  std::lock_guard lock(mutex_);
  SEEP_ASSIGN_OR_RETURN(WriteTx tx, WriteTx::Begin(*db_));
  if (job.request_id) {
    SEEP_ASSIGN_OR_RETURN(const auto existing, FindByRequestIdLocked(*job.request_id));
    if (existing) {
      SEEP_ASSIGN_OR_RETURN(JobRecord found, GetLocked(*existing, /*with_scene=*/true));
      return InsertOutcome{std::move(found), false};
    }
  }
  SEEP_ASSIGN_OR_RETURN(
      Stmt s, db_->Prepare("INSERT INTO jobs (id, request_id, name, state, scene, build_id, "
                           "created_at_ms) VALUES (?, ?, ?, 'QUEUED', ?, ?, ?)"));
  s.Bind(1, std::string_view(job.id))
      .Bind(2, job.request_id)
      .Bind(3, std::string_view(job.name))
      .BindBlob(4, job.scene)
      .Bind(5, std::string_view(job.build_id))
      .Bind(6, job.created_at_ms);
  SEEP_RETURN_IF_ERROR(s.Run());
  SEEP_RETURN_IF_ERROR(tx.Commit());
  JobRecord stored = job;
  stored.state = JobState::kQueued;
  return InsertOutcome{std::move(stored), true};
}

Result<JobRecord> JobStore::GetLocked(const std::string& id, bool with_scene) {
  SEEP_ASSIGN_OR_RETURN(
      Stmt s, db_->Prepare(fmt::format("SELECT {}, scene FROM jobs WHERE id = ?", kJobColumns)));
  s.Bind(1, std::string_view(id));
  SEEP_ASSIGN_OR_RETURN(const bool row, s.Step());
  if (!row) return core::NotFound(fmt::format("job {} not found", id));
  JobRecord job = ReadJobRow(s);
  if (with_scene) job.scene = s.ColumnBlob(15);
  SEEP_ASSIGN_OR_RETURN(
      Stmt m, db_->Prepare("SELECT name, value FROM results WHERE job_id = ? ORDER BY name"));
  m.Bind(1, std::string_view(id));
  for (;;) {
    SEEP_ASSIGN_OR_RETURN(const bool more, m.Step());
    if (!more) break;
    job.metrics.emplace_back(m.ColumnText(0), m.ColumnDouble(1));
  }
  return job;
}

Result<JobRecord> JobStore::Get(const std::string& id) {
  std::lock_guard lock(mutex_);
  return GetLocked(id, /*with_scene=*/true);
}

Result<JobPage> JobStore::List(std::uint32_t limit, std::optional<std::int64_t> cursor) {
  std::lock_guard lock(mutex_);
  SEEP_ASSIGN_OR_RETURN(
      Stmt s, db_->Prepare(fmt::format(
                  "SELECT {} FROM jobs WHERE rowid < ? ORDER BY rowid DESC LIMIT ?", kJobColumns)));
  s.Bind(1, cursor.value_or(INT64_MAX)).Bind(2, static_cast<std::int64_t>(limit) + 1);
  JobPage page;
  std::int64_t last_rowid = 0;
  for (;;) {
    SEEP_ASSIGN_OR_RETURN(const bool row, s.Step());
    if (!row) break;
    if (page.jobs.size() == limit) {
      page.next_cursor = last_rowid;
      break;
    }
    last_rowid = s.ColumnInt(0);
    page.jobs.push_back(ReadJobRow(s));
  }
  return page;
}

Result<std::optional<JobRecord>> JobStore::ClaimNextQueued(std::int64_t now_ms) {
  std::lock_guard lock(mutex_);
  SEEP_ASSIGN_OR_RETURN(WriteTx tx, WriteTx::Begin(*db_));
  SEEP_ASSIGN_OR_RETURN(
      Stmt s, db_->Prepare("UPDATE jobs SET state = 'RUNNING', started_at_ms = ? WHERE rowid = "
                           "(SELECT rowid FROM jobs WHERE state = 'QUEUED' ORDER BY rowid LIMIT 1) "
                           "RETURNING id"));
  s.Bind(1, now_ms);
  SEEP_ASSIGN_OR_RETURN(const bool row, s.Step());
  if (!row) return std::optional<JobRecord>();
  const std::string id = s.ColumnText(0);
  SEEP_RETURN_IF_ERROR(s.Run());
  SEEP_RETURN_IF_ERROR(tx.Commit());
  SEEP_ASSIGN_OR_RETURN(JobRecord job, GetLocked(id, /*with_scene=*/true));
  return std::optional<JobRecord>(std::move(job));
}

Status JobStore::UpdateProgress(const std::string& id, const JobProgress& progress) {
  std::lock_guard lock(mutex_);
  SEEP_ASSIGN_OR_RETURN(Stmt s,
                        db_->Prepare("UPDATE jobs SET step = ?, time_s = ?, fraction_done = "
                                     "? WHERE id = ? AND state = 'RUNNING'"));
  s.Bind(1, static_cast<std::int64_t>(progress.step))
      .Bind(2, progress.time_s)
      .Bind(3, progress.fraction_done)
      .Bind(4, std::string_view(id));
  return s.Run();
}

Status JobStore::Finish(const std::string& id, JobState state, const std::string& error_code,
                        const std::string& error_message,
                        const std::vector<std::pair<std::string, double>>& metrics,
                        double wall_time_s, std::int64_t now_ms) {
  if (!IsTerminal(state)) {
    return core::Internal(
        fmt::format("store: Finish needs a terminal state, got {}", JobStateName(state)));
  }
  std::lock_guard lock(mutex_);
  SEEP_ASSIGN_OR_RETURN(WriteTx tx, WriteTx::Begin(*db_));
  SEEP_ASSIGN_OR_RETURN(
      Stmt s,
      db_->Prepare("UPDATE jobs SET state = ?, error_code = ?, error_message = ?, "
                   "wall_time_s = ?, finished_at_ms = ? WHERE id = ? AND state = 'RUNNING'"));
  s.Bind(1, std::string_view(JobStateName(state)))
      .Bind(2, std::string_view(error_code))
      .Bind(3, std::string_view(error_message))
      .Bind(4, wall_time_s)
      .Bind(5, now_ms)
      .Bind(6, std::string_view(id));
  SEEP_RETURN_IF_ERROR(s.Run());
  if (db_->Changes() != 1) {
    return core::FailedPrecondition(fmt::format("store: job {} is not running", id));
  }
  SEEP_ASSIGN_OR_RETURN(Stmt insert,
                        db_->Prepare("INSERT INTO results (job_id, name, value) VALUES (?, ?, ?)"));
  for (const auto& [name, value] : metrics) {
    insert.Reset();
    insert.Bind(1, std::string_view(id)).Bind(2, std::string_view(name)).Bind(3, value);
    SEEP_RETURN_IF_ERROR(insert.Run());
  }
  return tx.Commit();
}

Result<int> JobStore::RequeueRunning() {
  std::lock_guard lock(mutex_);
  SEEP_ASSIGN_OR_RETURN(WriteTx tx, WriteTx::Begin(*db_));
  SEEP_RETURN_IF_ERROR(
      db_->Exec("UPDATE jobs SET state = 'QUEUED', step = 0, time_s = 0, fraction_done = 0 "
                "WHERE state = 'RUNNING'"));
  const int n = static_cast<int>(db_->Changes());
  SEEP_RETURN_IF_ERROR(tx.Commit());
  return n;
}

}  // namespace seep::service
