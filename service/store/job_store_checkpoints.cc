// JobStore: checkpoint records, result series and the per-job event log (schema v3).
#include <fmt/format.h>

#include <algorithm>
#include <climits>
#include <cstring>

#include "job_store.h"
#include "job_store_internal.h"
#include "sqlite_handle.h"

namespace seep::service {
namespace {

// The columns of a time series travel as one text, separated by commas (names never hold one).
std::string JoinColumns(const std::vector<std::string>& columns) {
  std::string out;
  for (std::size_t i = 0; i < columns.size(); ++i) {
    if (i > 0) out += ',';
    out += columns[i];
  }
  return out;
}

std::vector<std::string> SplitColumns(const std::string& text) {
  std::vector<std::string> out;
  if (text.empty()) return out;
  std::size_t start = 0;
  for (;;) {
    const std::size_t comma = text.find(',', start);
    out.push_back(text.substr(start, comma - start));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return out;
}

// Doubles as their native bytes: the store is read back on the machine that wrote it.
std::string DoublesToBlob(const std::vector<double>& values) {
  std::string blob(values.size() * sizeof(double), '\0');
  if (!values.empty()) std::memcpy(blob.data(), values.data(), blob.size());
  return blob;
}

std::vector<double> BlobToDoubles(const std::string& blob) {
  std::vector<double> values(blob.size() / sizeof(double));
  if (!values.empty()) std::memcpy(values.data(), blob.data(), values.size() * sizeof(double));
  return values;
}

// Fails with ABORTED unless the job is RUNNING under `epoch`.
Status CheckLease(Db& db, const std::string& id, std::int64_t epoch) {
  SEEP_ASSIGN_OR_RETURN(
      Stmt s, db.Prepare("SELECT 1 FROM jobs WHERE id = ? AND lease_epoch = ? AND state = "
                         "'RUNNING'"));
  s.Bind(1, std::string_view(id)).Bind(2, epoch);
  SEEP_ASSIGN_OR_RETURN(const bool row, s.Step());
  if (!row) return LeaseLost(id, epoch);
  return Status::Ok();
}

}  // namespace

std::string JobStore::StoredCheckpointPath(const std::string& path) const {
  if (path.empty()) return path;  // the store holds its bytes
  std::error_code ec;
  const std::filesystem::path absolute = std::filesystem::absolute(path, ec).lexically_normal();
  const std::filesystem::path relative = absolute.lexically_relative(data_dir_);
  if (relative.empty() || *relative.begin() == "..") return absolute.string();
  return relative.string();
}

std::filesystem::path JobStore::ResolvedCheckpointPath(const std::string& stored) const {
  if (stored.empty()) return {};                   // the store holds its bytes
  return (data_dir_ / stored).lexically_normal();  // an absolute `stored` stays itself
}

namespace {

CheckpointRecord ReadCheckpointRow(const Stmt& s) {
  CheckpointRecord c;
  c.step = static_cast<std::uint64_t>(s.ColumnInt(0));
  c.time_s = s.ColumnDouble(1);
  c.path = s.ColumnText(2);  // as stored: the caller resolves it
  c.bytes = s.ColumnInt(3);
  c.attempt = static_cast<std::uint32_t>(s.ColumnInt(4));
  c.created_at_ms = s.ColumnInt(5);
  if (!s.ColumnIsNull(6)) c.content = s.ColumnBlob(6);
  return c;
}

constexpr const char* kCheckpointColumns =
    "step, time_s, path, bytes, attempt, created_at_ms, content";

}  // namespace

Status JobStore::InsertCheckpointLocked(const std::string& id, const CheckpointRecord& checkpoint) {
  SEEP_ASSIGN_OR_RETURN(
      Stmt insert,
      db_->Prepare(fmt::format("INSERT OR REPLACE INTO checkpoints (job_id, {}) VALUES (?, ?, ?, "
                               "?, ?, ?, ?, ?)",
                               kCheckpointColumns)));
  insert.Bind(1, std::string_view(id))
      .Bind(2, static_cast<std::int64_t>(checkpoint.step))
      .Bind(3, checkpoint.time_s)
      .Bind(4, std::string_view(StoredCheckpointPath(checkpoint.path)))
      .Bind(5, checkpoint.bytes)
      .Bind(6, static_cast<std::int64_t>(checkpoint.attempt))
      .Bind(7, checkpoint.created_at_ms);
  if (checkpoint.path.empty()) {
    insert.BindBlob(8, checkpoint.content);
  } else {
    insert.BindNull(8);
  }
  return insert.Run();
}

Result<std::vector<CheckpointRecord>> JobStore::RecordCheckpoint(const std::string& id,
                                                                 std::int64_t epoch,
                                                                 const CheckpointRecord& checkpoint,
                                                                 std::uint32_t keep,
                                                                 CommitSync sync) {
  const StoreOperation operation("record checkpoint");
  std::lock_guard lock(mutex_);
  const RelaxedCommit relaxed(*db_, sync == CommitSync::kRelaxed);
  SEEP_ASSIGN_OR_RETURN(WriteTx tx, WriteTx::Begin(*db_));
  SEEP_RETURN_IF_ERROR(CheckLease(*db_, id, epoch));
  SEEP_ASSIGN_OR_RETURN(std::vector<CheckpointRecord> dropped,
                        RecordCheckpointLocked(id, checkpoint, keep));
  SEEP_RETURN_IF_ERROR(tx.Commit());
  return dropped;
}

Result<std::vector<CheckpointRecord>> JobStore::RecordCheckpointLocked(
    const std::string& id, const CheckpointRecord& checkpoint, std::uint32_t keep) {
  SEEP_RETURN_IF_ERROR(InsertCheckpointLocked(id, checkpoint));
  // The records beyond the newest `keep` (keep >= 1: the one just written always stays).
  SEEP_ASSIGN_OR_RETURN(
      Stmt old, db_->Prepare(fmt::format("DELETE FROM checkpoints WHERE job_id = ? AND step NOT IN "
                                         "(SELECT step FROM checkpoints WHERE job_id = ? ORDER BY "
                                         "step DESC LIMIT ?) RETURNING {}",
                                         kCheckpointColumns)));
  old.Bind(1, std::string_view(id))
      .Bind(2, std::string_view(id))
      .Bind(3, static_cast<std::int64_t>(std::max<std::uint32_t>(keep, 1)));
  std::vector<CheckpointRecord> dropped;
  for (;;) {
    SEEP_ASSIGN_OR_RETURN(const bool row, old.Step());
    if (!row) break;
    dropped.push_back(ReadCheckpointRow(old));
    dropped.back().path = ResolvedCheckpointPath(dropped.back().path).string();
  }
  SEEP_RETURN_IF_ERROR(
      AddEventLocked(*db_, id, checkpoint.created_at_ms, "CHECKPOINT",
                     fmt::format("step {} (t = {} s), {} bytes, attempt {}", checkpoint.step,
                                 checkpoint.time_s, checkpoint.bytes, checkpoint.attempt)));
  return dropped;
}

Result<std::vector<CheckpointRecord>> JobStore::ListCheckpoints(const std::string& id) {
  const StoreOperation operation("list checkpoints");
  std::lock_guard lock(mutex_);
  SEEP_ASSIGN_OR_RETURN(
      Stmt s,
      db_->Prepare(fmt::format("SELECT {} FROM checkpoints WHERE job_id = ? ORDER BY step DESC",
                               kCheckpointColumns)));
  s.Bind(1, std::string_view(id));
  std::vector<CheckpointRecord> out;
  for (;;) {
    SEEP_ASSIGN_OR_RETURN(const bool row, s.Step());
    if (!row) break;
    out.push_back(ReadCheckpointRow(s));
    out.back().path = ResolvedCheckpointPath(out.back().path).string();
  }
  return out;
}

Result<std::vector<std::filesystem::path>> JobStore::AllCheckpointPaths() {
  const StoreOperation operation("list checkpoint files");
  std::lock_guard lock(mutex_);
  SEEP_ASSIGN_OR_RETURN(Stmt s, db_->Prepare("SELECT path FROM checkpoints WHERE path != ''"));
  std::vector<std::filesystem::path> out;
  for (;;) {
    SEEP_ASSIGN_OR_RETURN(const bool row, s.Step());
    if (!row) break;
    out.push_back(ResolvedCheckpointPath(s.ColumnText(0)));
  }
  return out;
}

namespace {

Status CheckSeriesColumns(const std::vector<std::string>& columns) {
  for (const auto& c : columns) {
    if (c.empty() || c.find(',') != std::string::npos) {
      return core::InvalidArgument(
          fmt::format("store: series column '{}' must be non-empty and hold no comma", c));
    }
  }
  return Status::Ok();
}

}  // namespace

Status JobStore::StoreResultSeries(const std::string& id, std::int64_t epoch,
                                   const std::vector<std::string>& columns,
                                   const std::vector<double>& values,
                                   const std::string& state_sha256,
                                   const JobProgress* final_progress) {
  SEEP_RETURN_IF_ERROR(CheckSeriesColumns(columns));
  const StoreOperation operation("store result series");
  std::lock_guard lock(mutex_);
  const RelaxedCommit relaxed(*db_);  // made durable by the outcome (Finish) that follows
  SEEP_ASSIGN_OR_RETURN(WriteTx tx, WriteTx::Begin(*db_));
  SEEP_RETURN_IF_ERROR(CheckLease(*db_, id, epoch));
  SEEP_RETURN_IF_ERROR(
      StoreResultSeriesLocked(id, epoch, columns, values, state_sha256, final_progress));
  return tx.Commit();
}

Status JobStore::StoreResultSeriesLocked(const std::string& id, std::int64_t epoch,
                                         const std::vector<std::string>& columns,
                                         const std::vector<double>& values,
                                         const std::string& state_sha256,
                                         const JobProgress* final_progress) {
  SEEP_ASSIGN_OR_RETURN(Stmt s,
                        db_->Prepare("INSERT OR REPLACE INTO result_series (job_id, columns, vals, "
                                     "state_sha256) VALUES (?, ?, ?, ?)"));
  const std::string joined = JoinColumns(columns);
  s.Bind(1, std::string_view(id))
      .Bind(2, std::string_view(joined))
      .BindBlob(3, DoublesToBlob(values))
      .Bind(4, std::string_view(state_sha256));
  SEEP_RETURN_IF_ERROR(s.Run());
  if (final_progress != nullptr) {
    SEEP_RETURN_IF_ERROR(UpdateProgressLocked(id, epoch, *final_progress));
  }
  return Status::Ok();
}

Result<std::vector<CheckpointRecord>> JobStore::RecordSuccess(
    const std::string& id, std::int64_t epoch, const RunSuccess& run,
    const CheckpointRecord* final_checkpoint, std::uint32_t keep, std::int64_t now_ms,
    CommitSync sync) {
  SEEP_RETURN_IF_ERROR(CheckSeriesColumns(run.series_columns));
  SEEP_RETURN_IF_ERROR(CheckFiniteMetrics(run.metrics, "store"));
  const StoreOperation operation("record a run's success");
  std::lock_guard lock(mutex_);
  const RelaxedCommit relaxed(*db_, sync != CommitSync::kDurable);
  SEEP_ASSIGN_OR_RETURN(WriteTx tx, WriteTx::Begin(*db_));
  SEEP_RETURN_IF_ERROR(CheckLease(*db_, id, epoch));
  std::vector<CheckpointRecord> dropped;
  if (final_checkpoint != nullptr) {
    SEEP_ASSIGN_OR_RETURN(dropped, RecordCheckpointLocked(id, *final_checkpoint, keep));
  }
  SEEP_RETURN_IF_ERROR(StoreResultSeriesLocked(id, epoch, run.series_columns, run.series_values,
                                               run.state_sha256, &run.final_progress));
  SEEP_RETURN_IF_ERROR(
      FinishLocked(id, epoch, JobState::kSucceeded, "", "", run.metrics, run.wall_time_s, now_ms));
  SEEP_RETURN_IF_ERROR(tx.Commit());
  if (sync == CommitSync::kWindowed) durability_window_->Committed();
  return dropped;
}

Status JobStore::ReadResultSeriesLocked(JobRecord& job) {
  SEEP_ASSIGN_OR_RETURN(
      Stmt s,
      db_->Prepare("SELECT columns, vals, state_sha256 FROM result_series WHERE job_id = ?"));
  s.Bind(1, std::string_view(job.id));
  SEEP_ASSIGN_OR_RETURN(const bool row, s.Step());
  if (!row) return Status::Ok();
  job.series_columns = SplitColumns(s.ColumnText(0));
  job.series_values = BlobToDoubles(s.ColumnBlob(1));
  job.state_sha256 = s.ColumnText(2);
  return Status::Ok();
}

Status JobStore::AddEvent(const std::string& id, std::int64_t at_ms, const std::string& kind,
                          const std::string& message) {
  const StoreOperation operation("add event");
  std::lock_guard lock(mutex_);
  return AddEventLocked(*db_, id, at_ms, kind, message);
}

Status JobStore::AddLeasedEvent(const std::string& id, std::int64_t epoch, std::int64_t at_ms,
                                const std::string& kind, const std::string& message) {
  const StoreOperation operation("add event");
  std::lock_guard lock(mutex_);
  const RelaxedCommit relaxed(*db_);  // a worker's history line: durable with the next commit
  SEEP_ASSIGN_OR_RETURN(WriteTx tx, WriteTx::Begin(*db_));
  SEEP_RETURN_IF_ERROR(CheckLease(*db_, id, epoch));
  SEEP_RETURN_IF_ERROR(AddEventLocked(*db_, id, at_ms, kind, message));
  return tx.Commit();
}

Result<std::vector<JobEventRecord>> JobStore::ListEvents(const std::string& id,
                                                         std::int64_t after_id,
                                                         std::uint32_t limit) {
  const StoreOperation operation("list events");
  std::lock_guard lock(mutex_);
  SEEP_ASSIGN_OR_RETURN(Stmt known, db_->Prepare("SELECT 1 FROM jobs WHERE id = ?"));
  known.Bind(1, std::string_view(id));
  SEEP_ASSIGN_OR_RETURN(const bool exists, known.Step());
  if (!exists) return core::NotFound(fmt::format("job {} not found", id));
  SEEP_ASSIGN_OR_RETURN(Stmt s, db_->Prepare("SELECT id, at_ms, kind, message FROM events WHERE "
                                             "job_id = ? AND id > ? ORDER BY id LIMIT ?"));
  s.Bind(1, std::string_view(id))
      .Bind(2, after_id)
      .Bind(3, static_cast<std::int64_t>(std::min<std::uint32_t>(limit, INT32_MAX)));
  std::vector<JobEventRecord> out;
  for (;;) {
    SEEP_ASSIGN_OR_RETURN(const bool row, s.Step());
    if (!row) break;
    out.push_back({s.ColumnInt(0), s.ColumnInt(1), s.ColumnText(2), s.ColumnText(3)});
  }
  return out;
}

}  // namespace seep::service
