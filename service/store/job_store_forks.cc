// JobStore: forks (schema v11). A fork is stored together with the record of its first
// checkpoint, so that no claim ever sees the one without the other; its parent is named by id
// only (no foreign key), so that deleting the parent leaves the fork as it is.
#include <fmt/format.h>

#include "job_store.h"
#include "job_store_internal.h"
#include "sqlite_handle.h"

namespace seep::service {

Result<InsertOutcome> JobStore::InsertFork(const JobRecord& job, const CheckpointRecord& start) {
  if (!job.parent_job_id) return core::Internal("store: InsertFork needs the fork's parent");
  SEEP_RETURN_IF_ERROR(free_space_.CheckRoom(kNoNewJobs));
  const StoreOperation operation("insert a fork");
  std::lock_guard lock(mutex_);
  SEEP_ASSIGN_OR_RETURN(WriteTx tx, WriteTx::Begin(*db_));
  SEEP_ASSIGN_OR_RETURN(InsertOutcome outcome, InsertLocked(job));
  if (!outcome.created) return outcome;  // its checkpoint was recorded with it the first time
  SEEP_RETURN_IF_ERROR(InsertCheckpointLocked(job.id, start));
  SEEP_RETURN_IF_ERROR(AddEventLocked(
      *db_, job.id, start.created_at_ms, "CHECKPOINT",
      fmt::format("step {} (t = {} s), {} bytes: job {}'s checkpoint, copied as this fork's start",
                  start.step, start.time_s, start.bytes, *job.parent_job_id)));
  SEEP_RETURN_IF_ERROR(tx.Commit());
  return outcome;
}

Result<std::vector<std::string>> JobStore::ChildJobIdsLocked(const std::string& id) {
  SEEP_ASSIGN_OR_RETURN(Stmt s,
                        db_->Prepare("SELECT id FROM jobs WHERE parent_job_id = ? ORDER BY rowid"));
  s.Bind(1, std::string_view(id));
  std::vector<std::string> children;
  for (;;) {
    SEEP_ASSIGN_OR_RETURN(const bool row, s.Step());
    if (!row) break;
    children.push_back(s.ColumnText(0));
  }
  return children;
}

}  // namespace seep::service
