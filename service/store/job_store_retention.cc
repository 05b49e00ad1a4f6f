// JobStore: deleting finished jobs, one at a time (DeleteJob) or by the retention policy.
#include <fmt/format.h>

#include <map>

#include "job_store.h"
#include "job_store_internal.h"
#include "sqlite_handle.h"

namespace seep::service {
namespace {

constexpr const char* kTerminalStates = "('SUCCEEDED', 'FAILED', 'CANCELLED')";

CheckpointRecord ReadRetentionRow(const Stmt& s) {
  CheckpointRecord c;
  c.job_id = s.ColumnText(0);
  c.step = static_cast<std::uint64_t>(s.ColumnInt(1));
  c.path = s.ColumnText(2);
  c.bytes = s.ColumnInt(3);
  c.created_at_ms = s.ColumnInt(4);
  return c;
}

}  // namespace

Result<std::vector<CheckpointRecord>> JobStore::Delete(const std::string& id) {
  const StoreOperation operation("delete job");
  std::lock_guard lock(mutex_);
  SEEP_ASSIGN_OR_RETURN(WriteTx tx, WriteTx::Begin(*db_));
  SEEP_ASSIGN_OR_RETURN(std::vector<CheckpointRecord> removed, DeleteLocked(id));
  SEEP_RETURN_IF_ERROR(tx.Commit());
  return removed;
}

Result<std::vector<CheckpointRecord>> JobStore::DeleteLocked(const std::string& id) {
  SEEP_ASSIGN_OR_RETURN(const JobRecord job, GetLocked(id, /*with_scene=*/false));
  if (!IsTerminal(job.state)) {
    return core::FailedPrecondition(fmt::format(
        "job {} is {}; only a finished job (SUCCEEDED, FAILED or CANCELLED) can be deleted: "
        "cancel it first",
        id, JobStateName(job.state)));
  }
  SEEP_ASSIGN_OR_RETURN(
      Stmt files, db_->Prepare("SELECT job_id, step, path, bytes, created_at_ms FROM checkpoints "
                               "WHERE job_id = ? ORDER BY step DESC"));
  files.Bind(1, std::string_view(id));
  std::vector<CheckpointRecord> removed;
  for (;;) {
    SEEP_ASSIGN_OR_RETURN(const bool row, files.Step());
    if (!row) break;
    removed.push_back(ReadRetentionRow(files));
    removed.back().path = ResolvedCheckpointPath(removed.back().path).string();
  }
  // Results, series, checkpoints, events, labels and calibration records go with it (ON DELETE
  // CASCADE).
  SEEP_ASSIGN_OR_RETURN(Stmt gone, db_->Prepare("DELETE FROM jobs WHERE id = ?"));
  gone.Bind(1, std::string_view(id));
  SEEP_RETURN_IF_ERROR(gone.Run());
  return removed;
}

Result<RetentionOutcome> JobStore::ApplyRetention(const RetentionPolicy& policy,
                                                  std::int64_t now_ms) {
  const StoreOperation operation("apply retention");
  std::lock_guard lock(mutex_);
  SEEP_ASSIGN_OR_RETURN(WriteTx tx, WriteTx::Begin(*db_));
  RetentionOutcome out;
  if (policy.max_age_ms > 0) {
    const std::int64_t cutoff = now_ms - policy.max_age_ms;
    SEEP_ASSIGN_OR_RETURN(
        Stmt files,
        db_->Prepare(fmt::format(
            "SELECT c.job_id, c.step, c.path, c.bytes, c.created_at_ms FROM checkpoints c JOIN "
            "jobs j ON j.id = c.job_id WHERE j.state IN {} AND j.finished_at_ms < ?",
            kTerminalStates)));
    files.Bind(1, cutoff);
    for (;;) {
      SEEP_ASSIGN_OR_RETURN(const bool row, files.Step());
      if (!row) break;
      out.removed_checkpoints.push_back(ReadRetentionRow(files));
    }
    SEEP_ASSIGN_OR_RETURN(
        Stmt old, db_->Prepare(fmt::format(
                      "DELETE FROM jobs WHERE state IN {} AND finished_at_ms < ? RETURNING id",
                      kTerminalStates)));
    old.Bind(1, cutoff);
    for (;;) {
      SEEP_ASSIGN_OR_RETURN(const bool row, old.Step());
      if (!row) break;
      out.deleted_jobs.push_back(old.ColumnText(0));
    }
  }
  SEEP_ASSIGN_OR_RETURN(Stmt total,
                        db_->Prepare("SELECT COALESCE(SUM(bytes), 0) FROM checkpoints"));
  SEEP_RETURN_IF_ERROR(total.Step().status());
  out.checkpoint_bytes_left = total.ColumnInt(0);
  if (policy.max_checkpoint_bytes > 0 && out.checkpoint_bytes_left > policy.max_checkpoint_bytes) {
    // Finished jobs' checkpoints: the ones a newer one of the same job supersedes first, then
    // the newest (final) ones; oldest first within each.
    SEEP_ASSIGN_OR_RETURN(
        Stmt candidates,
        db_->Prepare(fmt::format(
            "SELECT c.job_id, c.step, c.path, c.bytes, c.created_at_ms FROM checkpoints c JOIN "
            "jobs j ON j.id = c.job_id WHERE j.state IN {} ORDER BY c.step = (SELECT MAX(n.step) "
            "FROM checkpoints n WHERE n.job_id = c.job_id), c.created_at_ms, c.job_id, c.step",
            kTerminalStates)));
    std::vector<CheckpointRecord> over;
    std::int64_t left = out.checkpoint_bytes_left;
    while (left > policy.max_checkpoint_bytes) {
      SEEP_ASSIGN_OR_RETURN(const bool row, candidates.Step());
      if (!row) break;  // the rest belongs to queued and running jobs
      over.push_back(ReadRetentionRow(candidates));
      left -= over.back().bytes;
    }
    candidates.Reset();
    SEEP_ASSIGN_OR_RETURN(Stmt remove,
                          db_->Prepare("DELETE FROM checkpoints WHERE job_id = ? AND step = ?"));
    std::map<std::string, std::pair<int, std::int64_t>> per_job;
    for (const CheckpointRecord& c : over) {
      remove.Reset();
      remove.Bind(1, std::string_view(c.job_id)).Bind(2, static_cast<std::int64_t>(c.step));
      SEEP_RETURN_IF_ERROR(remove.Run());
      ++per_job[c.job_id].first;
      per_job[c.job_id].second += c.bytes;
    }
    for (const auto& [job_id, removed] : per_job) {
      SEEP_RETURN_IF_ERROR(AddEventLocked(
          *db_, job_id, now_ms, "CHECKPOINTS_RETAINED",
          fmt::format("{} checkpoint(s), {} bytes, removed: all checkpoints together exceeded the "
                      "budget of {} bytes (--retain-checkpoint-bytes)",
                      removed.first, removed.second, policy.max_checkpoint_bytes)));
    }
    out.checkpoints_over_budget = static_cast<int>(over.size());
    out.removed_checkpoints.insert(out.removed_checkpoints.end(), over.begin(), over.end());
    out.checkpoint_bytes_left = left;
  }
  SEEP_RETURN_IF_ERROR(tx.Commit());
  for (CheckpointRecord& c : out.removed_checkpoints) {
    c.path = ResolvedCheckpointPath(c.path).string();
  }
  return out;
}

}  // namespace seep::service
