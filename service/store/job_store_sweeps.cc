// JobStore: sweeps, stored with their jobs in one transaction and deleted with them in one.
#include <fmt/format.h>

#include "job_store.h"
#include "job_store_internal.h"
#include "sqlite_handle.h"

namespace seep::service {

Result<SweepInsertOutcome> JobStore::InsertSweep(const SweepRecord& sweep,
                                                 const std::vector<JobRecord>& jobs) {
  SEEP_RETURN_IF_ERROR(free_space_.CheckRoom(kNoNewJobs));
  const StoreOperation operation("insert sweep");
  std::lock_guard lock(mutex_);
  SEEP_ASSIGN_OR_RETURN(WriteTx tx, WriteTx::Begin(*db_));
  if (sweep.request_id) {
    SEEP_ASSIGN_OR_RETURN(Stmt find, db_->Prepare("SELECT id FROM sweeps WHERE request_id = ?"));
    find.Bind(1, std::string_view(*sweep.request_id));
    SEEP_ASSIGN_OR_RETURN(const bool found, find.Step());
    if (found) {
      SEEP_ASSIGN_OR_RETURN(SweepRecord existing, GetSweepLocked(find.ColumnText(0)));
      if (existing.definition != sweep.definition) {
        return core::AlreadyExists(
            fmt::format("request_id: '{}' was already used for sweep {} with a different sweep",
                        *sweep.request_id, existing.id));
      }
      return SweepInsertOutcome{std::move(existing), false};
    }
  }
  SEEP_ASSIGN_OR_RETURN(Stmt s, db_->Prepare("INSERT INTO sweeps (id, request_id, name, "
                                             "definition, created_at_ms) VALUES (?, ?, ?, ?, ?)"));
  s.Bind(1, std::string_view(sweep.id))
      .Bind(2, sweep.request_id)
      .Bind(3, std::string_view(sweep.name))
      .BindBlob(4, sweep.definition)
      .Bind(5, sweep.created_at_ms);
  SEEP_RETURN_IF_ERROR(s.Run());
  SEEP_ASSIGN_OR_RETURN(
      Stmt member,
      db_->Prepare("INSERT INTO sweep_jobs (sweep_id, position, job_id) VALUES (?, ?, ?)"));
  SweepRecord stored = sweep;
  stored.jobs.clear();
  for (std::size_t position = 0; position < jobs.size(); ++position) {
    SEEP_ASSIGN_OR_RETURN(const InsertOutcome job, InsertLocked(jobs[position]));
    if (!job.created) {  // a sweep's jobs carry no request_id, so each one is new
      return core::Internal(
          fmt::format("store: sweep job {} matched an existing job's request_id", job.job.id));
    }
    member.Reset();
    member.Bind(1, std::string_view(sweep.id))
        .Bind(2, static_cast<std::int64_t>(position))
        .Bind(3, std::string_view(jobs[position].id));
    SEEP_RETURN_IF_ERROR(member.Run());
    stored.jobs.emplace_back(static_cast<std::uint32_t>(position), jobs[position].id);
  }
  SEEP_RETURN_IF_ERROR(tx.Commit());
  return SweepInsertOutcome{std::move(stored), true};
}

Result<SweepRecord> JobStore::GetSweepLocked(const std::string& id) {
  SEEP_ASSIGN_OR_RETURN(
      Stmt s,
      db_->Prepare(
          "SELECT id, request_id, name, definition, created_at_ms FROM sweeps WHERE id = ?"));
  s.Bind(1, std::string_view(id));
  SEEP_ASSIGN_OR_RETURN(const bool row, s.Step());
  if (!row) return core::NotFound(fmt::format("sweep {} not found", id));
  SweepRecord sweep;
  sweep.id = s.ColumnText(0);
  if (!s.ColumnIsNull(1)) sweep.request_id = s.ColumnText(1);
  sweep.name = s.ColumnText(2);
  sweep.definition = s.ColumnBlob(3);
  sweep.created_at_ms = s.ColumnInt(4);
  SEEP_ASSIGN_OR_RETURN(
      Stmt members,
      db_->Prepare("SELECT position, job_id FROM sweep_jobs WHERE sweep_id = ? ORDER BY position"));
  members.Bind(1, std::string_view(id));
  for (;;) {
    SEEP_ASSIGN_OR_RETURN(const bool more, members.Step());
    if (!more) break;
    sweep.jobs.emplace_back(static_cast<std::uint32_t>(members.ColumnInt(0)),
                            members.ColumnText(1));
  }
  return sweep;
}

Result<SweepRecord> JobStore::GetSweep(const std::string& id) {
  const StoreOperation operation("get sweep");
  std::lock_guard lock(mutex_);
  return GetSweepLocked(id);
}

Result<SweepDeletion> JobStore::DeleteSweep(const std::string& id) {
  const StoreOperation operation("delete sweep");
  std::lock_guard lock(mutex_);
  SEEP_ASSIGN_OR_RETURN(WriteTx tx, WriteTx::Begin(*db_));
  SEEP_ASSIGN_OR_RETURN(const SweepRecord sweep, GetSweepLocked(id));
  SweepDeletion deletion;
  for (const auto& [position, job_id] : sweep.jobs) {
    // DeleteLocked refuses a QUEUED or RUNNING job, naming it; the transaction then removes
    // nothing.
    SEEP_ASSIGN_OR_RETURN(std::vector<CheckpointRecord> files, DeleteLocked(job_id));
    deletion.checkpoints.insert(deletion.checkpoints.end(), files.begin(), files.end());
    deletion.job_ids.push_back(job_id);
  }
  SEEP_ASSIGN_OR_RETURN(Stmt gone, db_->Prepare("DELETE FROM sweeps WHERE id = ?"));
  gone.Bind(1, std::string_view(id));
  SEEP_RETURN_IF_ERROR(gone.Run());
  SEEP_RETURN_IF_ERROR(tx.Commit());
  return deletion;
}

}  // namespace seep::service
