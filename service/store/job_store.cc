#include "job_store.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "job_store_internal.h"
#include "sqlite_handle.h"
#include "wal_checkpointer.h"

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
    // v2: attempts, cancel requests and worker leases (owner, fencing epoch, expiry).
    R"sql(
ALTER TABLE jobs ADD COLUMN attempt INTEGER NOT NULL DEFAULT 1;
ALTER TABLE jobs ADD COLUMN cancel_requested INTEGER NOT NULL DEFAULT 0;
ALTER TABLE jobs ADD COLUMN lease_owner TEXT;
ALTER TABLE jobs ADD COLUMN lease_epoch INTEGER NOT NULL DEFAULT 0;
ALTER TABLE jobs ADD COLUMN lease_expires_at_ms INTEGER;
)sql",
    // v3: checkpoint files, a finished run's time series and final-state hash, and a per-job
    // event log (claims, resumes, skipped checkpoints, shutdown interruptions).
    R"sql(
CREATE TABLE checkpoints (
  job_id TEXT NOT NULL REFERENCES jobs(id) ON DELETE CASCADE,
  step INTEGER NOT NULL,
  time_s REAL NOT NULL,
  path TEXT NOT NULL,
  bytes INTEGER NOT NULL,
  attempt INTEGER NOT NULL,
  created_at_ms INTEGER NOT NULL,
  PRIMARY KEY (job_id, step)
) STRICT;
CREATE TABLE result_series (
  job_id TEXT PRIMARY KEY REFERENCES jobs(id) ON DELETE CASCADE,
  columns TEXT NOT NULL,
  vals BLOB NOT NULL,
  state_sha256 TEXT NOT NULL
) STRICT;
CREATE TABLE events (
  id INTEGER PRIMARY KEY,
  job_id TEXT NOT NULL REFERENCES jobs(id) ON DELETE CASCADE,
  at_ms INTEGER NOT NULL,
  kind TEXT NOT NULL,
  message TEXT NOT NULL
) STRICT;
CREATE INDEX events_by_job ON events(job_id, id);
)sql",
    // v4: job kinds, and the calibration records (one row per calibrated target, with the
    // packing, fluid, aperture law and stress it holds for) and their tags
    // (job_store_calibrations.cc). A job's tags are rows, so "has every tag" is one COUNT.
    R"sql(
ALTER TABLE jobs ADD COLUMN kind TEXT NOT NULL DEFAULT 'SIMULATION'
  CHECK (kind IN ('SIMULATION','CALIBRATION'));
CREATE INDEX jobs_by_kind ON jobs(kind);
CREATE TABLE calibrations (
  id INTEGER PRIMARY KEY,
  job_id TEXT NOT NULL REFERENCES jobs(id) ON DELETE CASCADE,
  target_index INTEGER NOT NULL,
  target_permeability_m2 REAL NOT NULL,
  residual_aperture_m REAL NOT NULL,
  permeability_m2 REAL NOT NULL,
  relative_error REAL NOT NULL,
  converged INTEGER NOT NULL,
  tolerance REAL NOT NULL,
  iterations INTEGER NOT NULL,
  corrections INTEGER NOT NULL,
  first_guess_residual_aperture_m REAL NOT NULL,
  first_guess_permeability_m2 REAL NOT NULL,
  first_guess_relative_error REAL NOT NULL,
  particle_count INTEGER NOT NULL,
  contact_count INTEGER NOT NULL,
  domain_count INTEGER NOT NULL,
  pipe_count INTEGER NOT NULL,
  porosity_2d REAL NOT NULL,
  mean_radius_m REAL NOT NULL,
  radius_std_dev_m REAL NOT NULL,
  min_radius_m REAL NOT NULL,
  max_radius_m REAL NOT NULL,
  coordination_number REAL NOT NULL,
  viscosity_pa_s REAL NOT NULL,
  bulk_modulus_pa REAL NOT NULL,
  reference_force_n REAL NOT NULL,
  gap_multiplier REAL NOT NULL,
  max_aperture_m REAL NOT NULL,
  uniform_normal_force_n REAL NOT NULL,
  listed_contact_forces INTEGER NOT NULL,
  pipes_in_compression INTEGER NOT NULL,
  pipes_closed_unloaded INTEGER NOT NULL,
  pipes_open INTEGER NOT NULL,
  pipes_capped INTEGER NOT NULL,
  min_normal_force_n REAL NOT NULL,
  mean_normal_force_n REAL NOT NULL,
  max_normal_force_n REAL NOT NULL,
  aperture_proportional_to_a0 INTEGER NOT NULL,
  flow_axis TEXT NOT NULL CHECK (flow_axis IN ('X','Y')),
  pressure_drop_pa REAL NOT NULL,
  sample_length_m REAL NOT NULL,
  sample_width_m REAL NOT NULL,
  scene_sha256 TEXT NOT NULL,
  build_id TEXT NOT NULL,
  created_at_ms INTEGER NOT NULL,
  UNIQUE (job_id, target_index)
) STRICT;
CREATE INDEX calibrations_by_k ON calibrations(target_permeability_m2);
CREATE INDEX calibrations_by_porosity ON calibrations(porosity_2d);
CREATE INDEX calibrations_by_created ON calibrations(created_at_ms);
CREATE INDEX calibrations_by_setup ON calibrations(scene_sha256, target_permeability_m2);
CREATE TABLE calibration_tags (
  job_id TEXT NOT NULL REFERENCES jobs(id) ON DELETE CASCADE,
  tag TEXT NOT NULL,
  PRIMARY KEY (job_id, tag)
) STRICT;
CREATE INDEX calibration_tags_by_tag ON calibration_tags(tag, job_id);
)sql",
    // v5: interruptions without progress (crash loops): how many in a row, and the newest
    // checkpoint step at the last one (-1: none yet).
    R"sql(
ALTER TABLE jobs ADD COLUMN interruptions INTEGER NOT NULL DEFAULT 0;
ALTER TABLE jobs ADD COLUMN interrupted_at_step INTEGER NOT NULL DEFAULT -1;
)sql",
    // v6: job priorities (the queue is claimed by priority, then by age).
    R"sql(
ALTER TABLE jobs ADD COLUMN priority INTEGER NOT NULL DEFAULT 0;
CREATE INDEX jobs_queue ON jobs(state, priority DESC);  -- rowid is in every index
)sql",
    // v7: checkpoint paths relative to the data folder, so that it can be moved. Earlier seepd
    // versions stored <data-dir>/checkpoints/<job>/ckpt-<step>.bin as they were given it
    // (absolute or relative to seepd's working folder); every path of that layout becomes
    // checkpoints/<job>/ckpt-<step>.bin. Any other path stays as it is and is read as before.
    R"sql(
UPDATE checkpoints SET path = substr(printf('/checkpoints/%s/ckpt-%012d.bin', job_id, step), 2)
WHERE substr(path, -length(printf('/checkpoints/%s/ckpt-%012d.bin', job_id, step)))
      = printf('/checkpoints/%s/ckpt-%012d.bin', job_id, step);
)sql",
    // v8: labels (key=value pairs given at submit, found again by ListJobs), and the finished
    // jobs by age for the retention policy.
    R"sql(
CREATE TABLE job_labels (
  job_id TEXT NOT NULL REFERENCES jobs(id) ON DELETE CASCADE,
  key TEXT NOT NULL,
  value TEXT NOT NULL,
  PRIMARY KEY (job_id, key)
) STRICT;
CREATE INDEX job_labels_by_pair ON job_labels(key, value);
CREATE INDEX jobs_by_finished ON jobs(finished_at_ms) WHERE finished_at_ms IS NOT NULL;
)sql",
    // v9: sweeps (job_store_sweeps.cc): the submitted seep.v1.Sweep, and which job is which of
    // its points. A job deleted on its own (or by retention) leaves its sweep.
    R"sql(
CREATE TABLE sweeps (
  id TEXT PRIMARY KEY,
  request_id TEXT UNIQUE,
  name TEXT NOT NULL,
  definition BLOB NOT NULL,
  created_at_ms INTEGER NOT NULL
) STRICT;
CREATE TABLE sweep_jobs (
  sweep_id TEXT NOT NULL REFERENCES sweeps(id) ON DELETE CASCADE,
  position INTEGER NOT NULL,
  job_id TEXT NOT NULL UNIQUE REFERENCES jobs(id) ON DELETE CASCADE,
  PRIMARY KEY (sweep_id, position)
) STRICT;
)sql",
    // v10: the stage a staged run is in (1-based, 0 = the scene has no stages), of how many, and
    // its name, kept with the progress so that `seep show` names it after the run.
    R"sql(
ALTER TABLE jobs ADD COLUMN stage_index INTEGER NOT NULL DEFAULT 0;
ALTER TABLE jobs ADD COLUMN stage_count INTEGER NOT NULL DEFAULT 0;
ALTER TABLE jobs ADD COLUMN stage_name TEXT NOT NULL DEFAULT '';
)sql",
    // v11: forks (SubmitJobRequest.from_job_id): the job a fork continues and the checkpoint step
    // it started from. No foreign key: a deleted parent's id stays in its forks' records.
    R"sql(
ALTER TABLE jobs ADD COLUMN parent_job_id TEXT;
ALTER TABLE jobs ADD COLUMN parent_step INTEGER NOT NULL DEFAULT 0;
CREATE INDEX jobs_by_parent ON jobs(parent_job_id) WHERE parent_job_id IS NOT NULL;
)sql",
    // v12: batch executors (job_store_batch.cc). Where the remote worker that claimed a job last
    // runs (its batch job, e.g. a Slurm allocation, and node; NULL for seepd's own workers), and
    // the batch jobs seepd submitted to start workers, with their state as last seen.
    R"sql(
ALTER TABLE jobs ADD COLUMN batch_job_id TEXT;
ALTER TABLE jobs ADD COLUMN batch_node TEXT;
CREATE INDEX jobs_by_batch_job ON jobs(batch_job_id) WHERE batch_job_id IS NOT NULL;
CREATE TABLE batch_jobs (
  id TEXT PRIMARY KEY,
  workers INTEGER NOT NULL,
  max_jobs INTEGER NOT NULL,
  state TEXT NOT NULL,
  node TEXT NOT NULL DEFAULT '',
  submitted_at_ms INTEGER NOT NULL,
  ended_at_ms INTEGER
) STRICT;
CREATE INDEX batch_jobs_live ON batch_jobs(submitted_at_ms) WHERE ended_at_ms IS NULL;
)sql",
    // v13: a checkpoint's bytes kept in its record (content; path '') for a run's small final
    // state, written with the run's outcome (checkpoint_io.h, kStoredCheckpointMaxBytes). And
    // jobs_by_state goes: jobs_queue (state, priority) serves every lookup by state, and one index
    // fewer to rewrite at each claim and outcome.
    R"sql(
ALTER TABLE checkpoints ADD COLUMN content BLOB;
DROP INDEX jobs_by_state;
)sql",
    // v14: results WITHOUT ROWID. A run's thirty-odd metrics were each a row and an entry of the
    // primary key's index; now each is one entry of the key's b-tree: half the inserts of a
    // success, and fewer pages for its commit to write.
    R"sql(
CREATE TABLE results_v14 (
  job_id TEXT NOT NULL REFERENCES jobs(id) ON DELETE CASCADE,
  name TEXT NOT NULL,
  value REAL NOT NULL,
  PRIMARY KEY (job_id, name)
) STRICT, WITHOUT ROWID;
INSERT INTO results_v14 (job_id, name, value) SELECT job_id, name, value FROM results;
DROP TABLE results;
ALTER TABLE results_v14 RENAME TO results;
)sql",
};
constexpr int kMigrationCount = static_cast<int>(std::size(kMigrations));

// What a job's run produced; cleared when it is resumed or ends other than SUCCEEDED.
constexpr const char* kResultTables[] = {"results", "result_series", "calibrations",
                                         "calibration_tags"};
static_assert(kMigrationCount == JobStore::kSchemaVersion);

constexpr const char* kJobColumns =
    "rowid, id, request_id, name, state, build_id, created_at_ms, started_at_ms, "
    "finished_at_ms, step, time_s, fraction_done, error_code, error_message, wall_time_s, attempt, "
    "cancel_requested, lease_owner, lease_epoch, lease_expires_at_ms, kind, priority, "
    "stage_index, stage_count, stage_name, parent_job_id, parent_step, batch_job_id, batch_node";
constexpr int kSceneColumn = 29;  // after kJobColumns

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
  job.attempt = static_cast<std::uint32_t>(s.ColumnInt(15));
  job.cancel_requested = s.ColumnInt(16) != 0;
  if (!s.ColumnIsNull(17)) job.lease_owner = s.ColumnText(17);
  job.lease_epoch = s.ColumnInt(18);
  if (!s.ColumnIsNull(19)) job.lease_expires_at_ms = s.ColumnInt(19);
  job.kind = ParseJobKind(s.ColumnText(20)).value_or(JobKind::kSimulation);
  job.priority = static_cast<std::int32_t>(s.ColumnInt(21));
  job.progress.stage_index = static_cast<std::uint32_t>(s.ColumnInt(22));
  job.progress.stage_count = static_cast<std::uint32_t>(s.ColumnInt(23));
  job.progress.stage_name = s.ColumnText(24);
  if (!s.ColumnIsNull(25)) job.parent_job_id = s.ColumnText(25);
  job.parent_step = static_cast<std::uint64_t>(s.ColumnInt(26));
  if (!s.ColumnIsNull(27)) {
    job.placement = WorkerPlacement{s.ColumnText(27), s.ColumnIsNull(28) ? "" : s.ColumnText(28)};
  }
  return job;
}

}  // namespace

Status LeaseLost(const std::string& id, std::int64_t epoch) {
  return core::Aborted(fmt::format(
      "store: job {} is no longer running under lease epoch {}; this worker must stop", id, epoch));
}

std::int64_t StoreNowMs() {
  return std::chrono::duration_cast<std::chrono::milliseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

Status AddEventLocked(Db& db, std::string_view id, std::int64_t at_ms, std::string_view kind,
                      std::string_view message) {
  SEEP_ASSIGN_OR_RETURN(
      Stmt s, db.Prepare("INSERT INTO events (job_id, at_ms, kind, message) SELECT id, ?, ?, ? "
                         "FROM jobs WHERE id = ?"));
  s.Bind(1, at_ms).Bind(2, kind).Bind(3, message).Bind(4, id);
  SEEP_RETURN_IF_ERROR(s.Run());
  if (db.Changes() != 1) return core::NotFound(fmt::format("job {} not found", id));
  return Status::Ok();
}

Status CheckFiniteMetrics(const std::vector<std::pair<std::string, double>>& metrics,
                          std::string_view what) {
  for (const auto& [name, value] : metrics) {
    if (!std::isfinite(value)) {
      return core::InvalidArgument(
          fmt::format("{}: metric '{}' is not a finite number (got {})", what, name, value));
    }
  }
  return Status::Ok();
}

Result<std::unique_ptr<JobStore>> JobStore::Open(const std::string& path,
                                                 FreeSpacePolicy free_space) {
  const StoreOperation operation("open the database");
  SEEP_ASSIGN_OR_RETURN(Db db, Db::Open(path));
  // WAL for concurrent readers; FULL so that an acknowledged submit or a terminal state survives
  // power loss, not only a process crash.
  SEEP_RETURN_IF_ERROR(
      db.Exec("PRAGMA busy_timeout=5000; PRAGMA journal_mode=WAL; PRAGMA synchronous=FULL; "
              "PRAGMA foreign_keys=ON;"));
  std::error_code ec;
  std::filesystem::path data_dir = std::filesystem::absolute(path, ec).lexically_normal();
  data_dir = data_dir.has_parent_path() ? data_dir.parent_path() : data_dir;
  std::unique_ptr<JobStore> store(new JobStore(std::make_unique<Db>(std::move(db)),
                                               std::move(data_dir), std::move(free_space)));
  SEEP_RETURN_IF_ERROR(store->Migrate());
  // SQLite names the WAL after the database; reading in WAL mode (Migrate did) created it.
  SEEP_ASSIGN_OR_RETURN(store->durability_window_,
                        DurabilityWindow::Open(path + "-wal", kDurabilityWindow));
  SEEP_ASSIGN_OR_RETURN(store->wal_checkpointer_,
                        WalCheckpointer::Start(store->db_->handle(), path));
  return store;
}

std::uint64_t JobStore::WindowedSyncs() const { return durability_window_->syncs(); }
bool JobStore::WindowedCommitPending() const { return durability_window_->pending(); }

JobStore::JobStore(std::unique_ptr<Db> db, std::filesystem::path data_dir,
                   FreeSpacePolicy free_space)
    : data_dir_(std::move(data_dir)),
      free_space_(data_dir_, std::move(free_space)),
      db_(std::move(db)) {
  db_->set_free_space(&free_space_);
}

Status JobStore::FitWalToDisk(bool low) {
  const StoreOperation operation("fit the WAL to the disk");
  std::lock_guard lock(mutex_);
  SEEP_RETURN_IF_ERROR(
      db_->Run(low ? "PRAGMA journal_size_limit=0" : "PRAGMA journal_size_limit=-1"));
  if (!low) return Status::Ok();
  SEEP_ASSIGN_OR_RETURN(Stmt truncate, db_->Prepare("PRAGMA wal_checkpoint(TRUNCATE)"));
  SEEP_ASSIGN_OR_RETURN(const bool row, truncate.Step());
  // Its row: busy (a reader or writer kept it from finishing), WAL frames, frames copied.
  if (row && truncate.ColumnInt(0) != 0) {
    return core::Unavailable("store: the WAL is in use; it is truncated at the next try");
  }
  return Status::Ok();
}
JobStore::~JobStore() = default;

Status JobStore::Migrate() {
  const StoreOperation operation("migrate the schema");
  std::lock_guard lock(mutex_);
  int version = 0;
  {  // finalized before the migrations run: an open statement keeps DROP INDEX from running
    SEEP_ASSIGN_OR_RETURN(Stmt version_stmt, db_->Prepare("PRAGMA user_version"));
    SEEP_ASSIGN_OR_RETURN(const bool has_row, version_stmt.Step());
    if (has_row) version = static_cast<int>(version_stmt.ColumnInt(0));
  }
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
  SEEP_RETURN_IF_ERROR(free_space_.CheckRoom(kNoNewJobs));
  const StoreOperation operation("insert job");
  std::lock_guard lock(mutex_);
  SEEP_ASSIGN_OR_RETURN(WriteTx tx, WriteTx::Begin(*db_));
  SEEP_ASSIGN_OR_RETURN(InsertOutcome outcome, InsertLocked(job));
  if (outcome.created) SEEP_RETURN_IF_ERROR(tx.Commit());
  return outcome;
}

Result<InsertOutcome> JobStore::InsertLocked(const JobRecord& job) {
  auto labels = job.labels;
  std::sort(labels.begin(), labels.end());
  if (job.request_id) {
    SEEP_ASSIGN_OR_RETURN(const auto existing, FindByRequestIdLocked(*job.request_id));
    if (existing) {
      SEEP_ASSIGN_OR_RETURN(JobRecord found, GetLocked(*existing, /*with_scene=*/true));
      if (found.scene != job.scene || found.kind != job.kind || found.labels != labels ||
          found.parent_job_id != job.parent_job_id || found.parent_step != job.parent_step) {
        return core::AlreadyExists(fmt::format(
            "request_id: '{}' was already used for job {} with a different scene or labels (or "
            "another job or step to fork from)",
            *job.request_id, found.id));
      }
      return InsertOutcome{std::move(found), false};
    }
  }
  SEEP_ASSIGN_OR_RETURN(
      Stmt s,
      db_->Prepare("INSERT INTO jobs (id, request_id, name, state, scene, build_id, "
                   "created_at_ms, kind, priority, parent_job_id, parent_step) VALUES (?, ?, ?, "
                   "'QUEUED', ?, ?, ?, ?, ?, ?, ?)"));
  s.Bind(1, std::string_view(job.id))
      .Bind(2, job.request_id)
      .Bind(3, std::string_view(job.name))
      .BindBlob(4, job.scene)
      .Bind(5, std::string_view(job.build_id))
      .Bind(6, job.created_at_ms)
      .Bind(7, std::string_view(JobKindName(job.kind)))
      .Bind(8, static_cast<std::int64_t>(job.priority))
      .Bind(9, job.parent_job_id)
      .Bind(10, static_cast<std::int64_t>(job.parent_step));
  SEEP_RETURN_IF_ERROR(s.Run());
  SEEP_ASSIGN_OR_RETURN(
      Stmt label, db_->Prepare("INSERT INTO job_labels (job_id, key, value) VALUES (?, ?, ?)"));
  for (const auto& [key, value] : labels) {
    label.Reset();
    label.Bind(1, std::string_view(job.id))
        .Bind(2, std::string_view(key))
        .Bind(3, std::string_view(value));
    SEEP_RETURN_IF_ERROR(label.Run());
  }
  std::string submitted = fmt::format("{} job, priority {}, {} label(s)", JobKindName(job.kind),
                                      job.priority, labels.size());
  if (job.parent_job_id) {
    submitted +=
        fmt::format(", forked from job {} at step {}", *job.parent_job_id, job.parent_step);
  }
  SEEP_RETURN_IF_ERROR(AddEventLocked(*db_, job.id, job.created_at_ms, "SUBMITTED", submitted));
  JobRecord stored = job;
  stored.labels = std::move(labels);
  stored.state = JobState::kQueued;
  return InsertOutcome{std::move(stored), true};
}

Result<JobRecord> JobStore::GetLocked(const std::string& id, bool with_scene) {
  // Without the scene, its column is not even read (it can be megabytes).
  SEEP_ASSIGN_OR_RETURN(Stmt s,
                        db_->Prepare(fmt::format("SELECT {}{} FROM jobs WHERE id = ?", kJobColumns,
                                                 with_scene ? ", scene" : "")));
  s.Bind(1, std::string_view(id));
  SEEP_ASSIGN_OR_RETURN(const bool row, s.Step());
  if (!row) return core::NotFound(fmt::format("job {} not found", id));
  JobRecord job = ReadJobRow(s);
  if (with_scene) job.scene = s.ColumnBlob(kSceneColumn);
  SEEP_ASSIGN_OR_RETURN(
      Stmt m, db_->Prepare("SELECT name, value FROM results WHERE job_id = ? ORDER BY name"));
  m.Bind(1, std::string_view(id));
  for (;;) {
    SEEP_ASSIGN_OR_RETURN(const bool more, m.Step());
    if (!more) break;
    job.metrics.emplace_back(m.ColumnText(0), m.ColumnDouble(1));
  }
  SEEP_RETURN_IF_ERROR(ReadResultSeriesLocked(job));
  SEEP_ASSIGN_OR_RETURN(job.child_job_ids, ChildJobIdsLocked(id));
  std::vector<JobRecord> one;
  one.push_back(std::move(job));
  SEEP_RETURN_IF_ERROR(ReadLabelsLocked(one));
  return std::move(one.front());
}

Status JobStore::ReadLabelsLocked(std::vector<JobRecord>& jobs) {
  SEEP_ASSIGN_OR_RETURN(
      Stmt s, db_->Prepare("SELECT key, value FROM job_labels WHERE job_id = ? ORDER BY key"));
  for (JobRecord& job : jobs) {
    s.Reset();
    s.Bind(1, std::string_view(job.id));
    job.labels.clear();
    for (;;) {
      SEEP_ASSIGN_OR_RETURN(const bool row, s.Step());
      if (!row) break;
      job.labels.emplace_back(s.ColumnText(0), s.ColumnText(1));
    }
  }
  return Status::Ok();
}

Result<JobRecord> JobStore::Get(const std::string& id) {
  const StoreOperation operation("get job");
  std::lock_guard lock(mutex_);
  return GetLocked(id, /*with_scene=*/true);
}

Result<JobRecord> JobStore::GetWithoutScene(const std::string& id) {
  std::lock_guard lock(mutex_);
  return GetLocked(id, /*with_scene=*/false);
}

Result<JobPage> JobStore::List(std::uint32_t limit, std::optional<std::int64_t> cursor,
                               const JobFilter& filter) {
  const StoreOperation operation("list jobs");
  std::lock_guard lock(mutex_);
  std::string where = "rowid < ?";
  if (!filter.states.empty()) {
    where += " AND state IN (";
    for (std::size_t i = 0; i < filter.states.size(); ++i) where += i == 0 ? "?" : ", ?";
    where += ")";
  }
  if (!filter.name_contains.empty()) where += " AND instr(name, ?) > 0";
  if (!filter.kinds.empty()) {
    where += " AND kind IN (";
    for (std::size_t i = 0; i < filter.kinds.size(); ++i) where += i == 0 ? "?" : ", ?";
    where += ")";
  }
  for (std::size_t i = 0; i < filter.labels.size(); ++i) {
    where +=
        " AND EXISTS (SELECT 1 FROM job_labels l WHERE l.job_id = jobs.id AND l.key = ? AND "
        "l.value = ?)";
  }
  SEEP_ASSIGN_OR_RETURN(
      Stmt s, db_->Prepare(fmt::format("SELECT {} FROM jobs WHERE {} ORDER BY rowid DESC LIMIT ?",
                                       kJobColumns, where)));
  int index = 1;
  s.Bind(index++, cursor.value_or(INT64_MAX));
  for (const JobState state : filter.states) {
    s.Bind(index++, std::string_view(JobStateName(state)));
  }
  if (!filter.name_contains.empty()) s.Bind(index++, std::string_view(filter.name_contains));
  for (const JobKind kind : filter.kinds) s.Bind(index++, std::string_view(JobKindName(kind)));
  for (const auto& [key, value] : filter.labels) {
    s.Bind(index, std::string_view(key)).Bind(index + 1, std::string_view(value));
    index += 2;
  }
  s.Bind(index, static_cast<std::int64_t>(limit) + 1);
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
  SEEP_RETURN_IF_ERROR(ReadLabelsLocked(page.jobs));
  return page;
}

Result<std::optional<JobRecord>> JobStore::ClaimNextQueued(
    const std::string& owner, std::int64_t now_ms, std::int64_t lease_ms,
    std::optional<JobKind> kind, const std::optional<WorkerPlacement>& placement, CommitSync sync) {
  // A job started on a low disk would fail at its first checkpoint: none starts, and the queued
  // ones say why (SeepService's held_reason) until space is freed.
  if (free_space_.Low()) return std::optional<JobRecord>();
  const StoreOperation operation("claim a queued job");
  std::lock_guard lock(mutex_);
  const RelaxedCommit relaxed(*db_, sync == CommitSync::kRelaxed);
  SEEP_ASSIGN_OR_RETURN(WriteTx tx, WriteTx::Begin(*db_));
  SEEP_ASSIGN_OR_RETURN(
      Stmt s,
      db_->Prepare("UPDATE jobs SET state = 'RUNNING', started_at_ms = ?, lease_owner = ?, "
                   "lease_epoch = lease_epoch + 1, lease_expires_at_ms = ?, batch_job_id = ?, "
                   "batch_node = ? WHERE rowid = "
                   "(SELECT rowid FROM jobs WHERE state = 'QUEUED' AND (? IS NULL OR kind = ?) "
                   "ORDER BY priority DESC, rowid LIMIT 1) "
                   "RETURNING id"));
  s.Bind(1, now_ms).Bind(2, std::string_view(owner)).Bind(3, now_ms + lease_ms);
  if (placement) {
    s.Bind(4, std::string_view(placement->batch_job_id)).Bind(5, std::string_view(placement->node));
  } else {
    s.BindNull(4).BindNull(5);
  }
  if (kind) {
    s.Bind(6, std::string_view(JobKindName(*kind))).Bind(7, std::string_view(JobKindName(*kind)));
  } else {
    s.BindNull(6).BindNull(7);
  }
  SEEP_ASSIGN_OR_RETURN(const bool row, s.Step());
  if (!row) return std::optional<JobRecord>();
  const std::string id = s.ColumnText(0);
  SEEP_RETURN_IF_ERROR(s.Run());
  SEEP_ASSIGN_OR_RETURN(JobRecord job, GetLocked(id, /*with_scene=*/true));
  SEEP_RETURN_IF_ERROR(AddEventLocked(
      *db_, id, now_ms, "CLAIMED",
      fmt::format("attempt {} by {} (lease epoch {})", job.attempt, owner, job.lease_epoch)));
  SEEP_RETURN_IF_ERROR(tx.Commit());
  return std::optional<JobRecord>(std::move(job));
}

Result<bool> JobStore::Heartbeat(const std::string& id, std::int64_t epoch,
                                 std::int64_t expires_at_ms,
                                 std::optional<std::int64_t> keep_beyond_ms) {
  const StoreOperation operation("renew a lease");
  std::lock_guard lock(mutex_);
  if (keep_beyond_ms) {
    SEEP_ASSIGN_OR_RETURN(Stmt read, db_->Prepare("SELECT cancel_requested, lease_expires_at_ms "
                                                  "FROM jobs WHERE id = ? AND lease_epoch = ? "
                                                  "AND state = 'RUNNING'"));
    read.Bind(1, std::string_view(id)).Bind(2, epoch);
    SEEP_ASSIGN_OR_RETURN(const bool row, read.Step());
    if (!row) return LeaseLost(id, epoch);
    if (!read.ColumnIsNull(1) && read.ColumnInt(1) >= *keep_beyond_ms) {
      return read.ColumnInt(0) != 0;
    }
  }
  const RelaxedCommit relaxed(*db_);  // liveness only: a restart requeues RUNNING jobs
  SEEP_ASSIGN_OR_RETURN(
      Stmt s, db_->Prepare("UPDATE jobs SET lease_expires_at_ms = ? WHERE id = ? AND lease_epoch = "
                           "? AND state = 'RUNNING' RETURNING cancel_requested"));
  s.Bind(1, expires_at_ms).Bind(2, std::string_view(id)).Bind(3, epoch);
  SEEP_ASSIGN_OR_RETURN(const bool row, s.Step());
  if (!row) return LeaseLost(id, epoch);
  const bool cancel_requested = s.ColumnInt(0) != 0;
  SEEP_RETURN_IF_ERROR(s.Run());
  return cancel_requested;
}

Status JobStore::ReleaseLease(const std::string& id, std::int64_t epoch) {
  const StoreOperation operation("release a lease");
  std::lock_guard lock(mutex_);
  SEEP_ASSIGN_OR_RETURN(Stmt s, db_->Prepare("UPDATE jobs SET lease_expires_at_ms = NULL WHERE id "
                                             "= ? AND lease_epoch = ? AND state = 'RUNNING'"));
  s.Bind(1, std::string_view(id)).Bind(2, epoch);
  SEEP_RETURN_IF_ERROR(s.Run());
  if (db_->Changes() != 1) return LeaseLost(id, epoch);
  return Status::Ok();
}

Status JobStore::UpdateProgress(const std::string& id, std::int64_t epoch,
                                const JobProgress& progress) {
  const StoreOperation operation("update progress");
  std::lock_guard lock(mutex_);
  const RelaxedCommit relaxed(*db_);  // live progress; a resume restores it from a checkpoint
  return UpdateProgressLocked(id, epoch, progress);
}

Status JobStore::UpdateProgressLocked(const std::string& id, std::int64_t epoch,
                                      const JobProgress& progress) {
  SEEP_ASSIGN_OR_RETURN(Stmt s,
                        db_->Prepare("UPDATE jobs SET step = ?, time_s = ?, fraction_done = "
                                     "?, stage_index = ?, stage_count = ?, stage_name = ? WHERE "
                                     "id = ? AND lease_epoch = ? AND state = 'RUNNING'"));
  s.Bind(1, static_cast<std::int64_t>(progress.step))
      .Bind(2, progress.time_s)
      .Bind(3, progress.fraction_done)
      .Bind(4, static_cast<std::int64_t>(progress.stage_index))
      .Bind(5, static_cast<std::int64_t>(progress.stage_count))
      .Bind(6, std::string_view(progress.stage_name))
      .Bind(7, std::string_view(id))
      .Bind(8, epoch);
  SEEP_RETURN_IF_ERROR(s.Run());
  if (db_->Changes() != 1) return LeaseLost(id, epoch);
  return Status::Ok();
}

Status JobStore::Finish(const std::string& id, std::int64_t epoch, JobState state,
                        const std::string& error_code, const std::string& error_message,
                        const std::vector<std::pair<std::string, double>>& metrics,
                        double wall_time_s, std::int64_t now_ms) {
  if (!IsTerminal(state)) {
    return core::Internal(
        fmt::format("store: Finish needs a terminal state, got {}", JobStateName(state)));
  }
  SEEP_RETURN_IF_ERROR(CheckFiniteMetrics(metrics, "store"));
  const StoreOperation operation("finish job");
  std::lock_guard lock(mutex_);
  SEEP_ASSIGN_OR_RETURN(WriteTx tx, WriteTx::Begin(*db_));
  SEEP_RETURN_IF_ERROR(
      FinishLocked(id, epoch, state, error_code, error_message, metrics, wall_time_s, now_ms));
  return tx.Commit();
}

Status JobStore::FinishLocked(const std::string& id, std::int64_t epoch, JobState state,
                              const std::string& error_code, const std::string& error_message,
                              const std::vector<std::pair<std::string, double>>& metrics,
                              double wall_time_s, std::int64_t now_ms) {
  SEEP_ASSIGN_OR_RETURN(
      Stmt s, db_->Prepare("UPDATE jobs SET state = ?, error_code = ?, error_message = ?, "
                           "wall_time_s = ?, finished_at_ms = ?, lease_expires_at_ms = NULL "
                           "WHERE id = ? AND lease_epoch = ? AND state = 'RUNNING'"));
  s.Bind(1, std::string_view(JobStateName(state)))
      .Bind(2, std::string_view(error_code))
      .Bind(3, std::string_view(error_message))
      .Bind(4, wall_time_s)
      .Bind(5, now_ms)
      .Bind(6, std::string_view(id))
      .Bind(7, epoch);
  SEEP_RETURN_IF_ERROR(s.Run());
  if (db_->Changes() != 1) return LeaseLost(id, epoch);
  if (state != JobState::kSucceeded) SEEP_RETURN_IF_ERROR(ClearResultsLocked(id));
  SEEP_ASSIGN_OR_RETURN(Stmt insert,
                        db_->Prepare("INSERT INTO results (job_id, name, value) VALUES (?, ?, ?)"));
  for (const auto& [name, value] : metrics) {
    insert.Reset();
    insert.Bind(1, std::string_view(id)).Bind(2, std::string_view(name)).Bind(3, value);
    SEEP_RETURN_IF_ERROR(insert.Run());
  }
  const std::string outcome =
      state == JobState::kSucceeded
          ? fmt::format("{} metric(s) after {:.3f} s", metrics.size(), wall_time_s)
          : fmt::format("{}: {}", error_code, error_message);
  return AddEventLocked(*db_, id, now_ms, JobStateName(state), outcome);
}

Result<JobRecord> JobStore::Cancel(const std::string& id, std::int64_t now_ms) {
  const StoreOperation operation("cancel job");
  std::lock_guard lock(mutex_);
  SEEP_ASSIGN_OR_RETURN(WriteTx tx, WriteTx::Begin(*db_));
  SEEP_ASSIGN_OR_RETURN(const JobRecord job, GetLocked(id, /*with_scene=*/false));
  if (IsTerminal(job.state)) {
    return core::FailedPrecondition(
        fmt::format("job {} is already {}; only QUEUED or RUNNING jobs can be cancelled", id,
                    JobStateName(job.state)));
  }
  if (job.state == JobState::kQueued) {
    SEEP_ASSIGN_OR_RETURN(
        Stmt s, db_->Prepare("UPDATE jobs SET state = 'CANCELLED', finished_at_ms = ?, "
                             "error_code = 'CANCELLED', error_message = 'cancelled before it "
                             "started' WHERE id = ? AND state = 'QUEUED'"));
    s.Bind(1, now_ms).Bind(2, std::string_view(id));
    SEEP_RETURN_IF_ERROR(s.Run());
    SEEP_RETURN_IF_ERROR(
        AddEventLocked(*db_, id, now_ms, "CANCELLED", "CANCELLED: cancelled before it started"));
  } else {
    SEEP_ASSIGN_OR_RETURN(Stmt s, db_->Prepare("UPDATE jobs SET cancel_requested = 1 WHERE id = ? "
                                               "AND state = 'RUNNING'"));
    s.Bind(1, std::string_view(id));
    SEEP_RETURN_IF_ERROR(s.Run());
    SEEP_RETURN_IF_ERROR(AddEventLocked(*db_, id, now_ms, "CANCEL_REQUESTED",
                                        fmt::format("at step {}", job.progress.step)));
  }
  SEEP_ASSIGN_OR_RETURN(JobRecord now, GetLocked(id, /*with_scene=*/true));
  SEEP_RETURN_IF_ERROR(tx.Commit());
  return now;
}

Result<JobRecord> JobStore::Resume(const std::string& id) {
  const StoreOperation operation("resume job");
  std::lock_guard lock(mutex_);
  SEEP_ASSIGN_OR_RETURN(WriteTx tx, WriteTx::Begin(*db_));
  SEEP_ASSIGN_OR_RETURN(const JobRecord job, GetLocked(id, /*with_scene=*/false));
  if (job.state != JobState::kFailed && job.state != JobState::kCancelled) {
    return core::FailedPrecondition(fmt::format(
        "job {} is {}; only FAILED or CANCELLED jobs can be resumed", id, JobStateName(job.state)));
  }
  SEEP_ASSIGN_OR_RETURN(
      Stmt s,
      db_->Prepare(
          "UPDATE jobs SET state = 'QUEUED', attempt = attempt + 1, "
          "cancel_requested = 0, started_at_ms = NULL, finished_at_ms = NULL, "
          "step = 0, time_s = 0, fraction_done = 0, stage_index = 0, stage_count = 0, "
          "stage_name = '', error_code = '', "
          "error_message = '', wall_time_s = 0, lease_owner = NULL, "
          "lease_expires_at_ms = NULL, interruptions = 0, interrupted_at_step = -1 WHERE id = ?"));
  s.Bind(1, std::string_view(id));
  SEEP_RETURN_IF_ERROR(s.Run());
  SEEP_RETURN_IF_ERROR(ClearResultsLocked(id));
  SEEP_RETURN_IF_ERROR(AddEventLocked(
      *db_, id, StoreNowMs(), "RESUME_REQUESTED",
      fmt::format("attempt {} queued (was {})", job.attempt + 1, JobStateName(job.state))));
  SEEP_ASSIGN_OR_RETURN(JobRecord now, GetLocked(id, /*with_scene=*/true));
  SEEP_RETURN_IF_ERROR(tx.Commit());
  return now;
}

Status JobStore::ClearResultsLocked(const std::string& id) {
  for (const char* table : kResultTables) {
    SEEP_ASSIGN_OR_RETURN(Stmt clear,
                          db_->Prepare(fmt::format("DELETE FROM {} WHERE job_id = ?", table)));
    clear.Bind(1, std::string_view(id));
    SEEP_RETURN_IF_ERROR(clear.Run());
  }
  return Status::Ok();
}

Result<std::vector<std::string>> JobStore::RequeueLocked(
    const char* where, const std::function<void(Stmt&, int)>& bind, std::string_view cancel_message,
    int max_interruptions, std::vector<CrashLoopFailure>* crash_loops) {
  SEEP_ASSIGN_OR_RETURN(
      Stmt cancel,
      db_->Prepare(fmt::format(
          "UPDATE jobs SET state = 'CANCELLED', error_code = 'CANCELLED', error_message = ?, "
          "finished_at_ms = strftime('%s', 'now') * 1000, lease_expires_at_ms = NULL WHERE "
          "state = 'RUNNING' AND cancel_requested = 1 AND {} RETURNING id",
          where)));
  cancel.Bind(1, cancel_message);
  bind(cancel, 2);
  std::vector<std::string> cancelled;
  for (;;) {
    SEEP_ASSIGN_OR_RETURN(const bool row, cancel.Step());
    if (!row) break;
    cancelled.push_back(cancel.ColumnText(0));
  }
  for (const std::string& c : cancelled) {
    SEEP_RETURN_IF_ERROR(AddEventLocked(*db_, c, StoreNowMs(), "CANCELLED",
                                        fmt::format("CANCELLED: {}", cancel_message)));
  }
  // An unreleased lease is an interruption; without a newer checkpoint, one without progress.
  SEEP_ASSIGN_OR_RETURN(
      Stmt count,
      db_->Prepare(fmt::format(
          "UPDATE jobs SET interruptions = CASE WHEN mark = interrupted_at_step THEN "
          "interruptions + 1 ELSE 1 END, interrupted_at_step = mark FROM (SELECT j.id AS mark_id, "
          "COALESCE((SELECT MAX(c.step) FROM checkpoints c WHERE c.job_id = j.id), 0) AS mark "
          "FROM jobs j) WHERE mark_id = jobs.id AND state = 'RUNNING' AND lease_expires_at_ms IS "
          "NOT NULL AND {}",
          where)));
  bind(count, 1);
  SEEP_RETURN_IF_ERROR(count.Run());
  SEEP_ASSIGN_OR_RETURN(
      Stmt fail,
      db_->Prepare(fmt::format(
          "UPDATE jobs SET state = 'FAILED', error_code = 'ABORTED', error_message = "
          "printf('interrupted %d times in a row without progress (a crash, a hung or dead "
          "worker; no checkpoint beyond step %d): it may be what brings seepd down, so it is not "
          "run again (see its events; `seep resume` tries once more)', interruptions, "
          "interrupted_at_step), finished_at_ms = strftime('%s', 'now') * 1000, "
          "lease_expires_at_ms = NULL WHERE state = 'RUNNING' AND interruptions >= ? AND {} "
          "RETURNING id, error_message",
          where)));
  fail.Bind(1, static_cast<std::int64_t>(std::max(1, max_interruptions)));
  bind(fail, 2);
  std::vector<CrashLoopFailure> failed;
  for (;;) {
    SEEP_ASSIGN_OR_RETURN(const bool row, fail.Step());
    if (!row) break;
    failed.push_back({fail.ColumnText(0), fail.ColumnText(1)});
  }
  for (const CrashLoopFailure& f : failed) {
    SEEP_RETURN_IF_ERROR(
        AddEventLocked(*db_, f.id, StoreNowMs(), "INTERRUPTED_TOO_OFTEN", f.message));
  }
  if (crash_loops != nullptr) crash_loops->insert(crash_loops->end(), failed.begin(), failed.end());
  SEEP_ASSIGN_OR_RETURN(
      Stmt s, db_->Prepare(fmt::format(
                  "UPDATE jobs SET state = 'QUEUED', step = 0, time_s = 0, fraction_done = 0, "
                  "stage_index = 0, stage_count = 0, stage_name = '', lease_owner = NULL, "
                  "lease_expires_at_ms = NULL WHERE state = 'RUNNING' AND {} "
                  "RETURNING id",
                  where)));
  bind(s, 1);
  std::vector<std::string> queued;
  for (;;) {
    SEEP_ASSIGN_OR_RETURN(const bool row, s.Step());
    if (!row) break;
    queued.push_back(s.ColumnText(0));
  }
  return queued;
}

Result<int> JobStore::RequeueRunning(const std::string& current_owner, int max_interruptions,
                                     std::vector<CrashLoopFailure>* crash_loops) {
  const StoreOperation operation("requeue interrupted jobs");
  std::lock_guard lock(mutex_);
  SEEP_ASSIGN_OR_RETURN(WriteTx tx, WriteTx::Begin(*db_));
  // A cancel that was pending when the previous process stopped is honoured now.
  SEEP_ASSIGN_OR_RETURN(
      const std::vector<std::string> queued,
      RequeueLocked(
          "lease_owner IS NOT ?",
          [&](Stmt& s, int index) { s.Bind(index, std::string_view(current_owner)); },
          "cancelled while seepd was stopped", max_interruptions, crash_loops));
  for (const std::string& id : queued) {
    SEEP_RETURN_IF_ERROR(AddEventLocked(*db_, id, StoreNowMs(), "RECOVERED",
                                        "queued again at seepd start (it was running when the "
                                        "previous seepd stopped)"));
  }
  SEEP_RETURN_IF_ERROR(tx.Commit());
  return static_cast<int>(queued.size());
}

Result<std::vector<JobRecord>> JobStore::RunningLeasedBy(const std::string& owner_prefix) {
  const StoreOperation operation("find the jobs a worker holds");
  std::lock_guard lock(mutex_);
  // substr, not LIKE: an owner's name may hold '%' or '_'.
  SEEP_ASSIGN_OR_RETURN(Stmt find,
                        db_->Prepare(fmt::format("SELECT {} FROM jobs WHERE state = 'RUNNING' AND "
                                                 "substr(lease_owner, 1, length(?1)) = ?1 "
                                                 "ORDER BY started_at_ms, rowid",
                                                 kJobColumns)));
  find.Bind(1, std::string_view(owner_prefix));
  std::vector<JobRecord> held;
  for (;;) {
    SEEP_ASSIGN_OR_RETURN(const bool row, find.Step());
    if (!row) break;
    held.push_back(ReadJobRow(find));
  }
  return held;
}

Result<std::vector<JobRecord>> JobStore::RequeueExpired(
    std::int64_t now_ms, int max_interruptions, std::vector<CrashLoopFailure>* crash_loops) {
  const StoreOperation operation("rescue expired leases");
  std::lock_guard lock(mutex_);
  SEEP_ASSIGN_OR_RETURN(WriteTx tx, WriteTx::Begin(*db_));
  constexpr const char* kExpired = "lease_expires_at_ms < ?";
  const auto bind_now = [now_ms](Stmt& s, int index) { s.Bind(index, now_ms); };
  SEEP_ASSIGN_OR_RETURN(
      Stmt find, db_->Prepare(fmt::format("SELECT {} FROM jobs WHERE state = 'RUNNING' AND {}",
                                          kJobColumns, kExpired)));
  bind_now(find, 1);
  std::vector<JobRecord> expired;
  for (;;) {
    SEEP_ASSIGN_OR_RETURN(const bool row, find.Step());
    if (!row) break;
    expired.push_back(ReadJobRow(find));
  }
  if (expired.empty()) return expired;
  SEEP_RETURN_IF_ERROR(RequeueLocked(kExpired, bind_now,
                                     "cancelled after its worker's lease expired",
                                     max_interruptions, crash_loops)
                           .status());
  SEEP_RETURN_IF_ERROR(tx.Commit());
  return expired;
}

}  // namespace seep::service
