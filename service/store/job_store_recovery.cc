// JobStore::InsertRecovered: a job rebuilt from its checkpoint files (seepd
// --recover-from-checkpoints) goes into the store whole, in one transaction.
#include <fmt/format.h>

#include "job_store.h"
#include "job_store_internal.h"

namespace seep::service {

Status JobStore::InsertRecovered(const JobRecord& job,
                                 const std::vector<CheckpointRecord>& checkpoints,
                                 const std::string& note) {
  const StoreOperation operation("insert a recovered job");
  std::lock_guard lock(mutex_);
  SEEP_ASSIGN_OR_RETURN(WriteTx tx, WriteTx::Begin(*db_));
  JobRecord queued = job;
  queued.request_id.reset();
  SEEP_ASSIGN_OR_RETURN(const InsertOutcome inserted, InsertLocked(queued));
  if (!inserted.created) {
    return core::AlreadyExists(fmt::format("job {} is in the store already", job.id));
  }
  // As if claimed once: its next claim (epoch 2) continues from its newest checkpoint, as any
  // job does after its first claim.
  SEEP_ASSIGN_OR_RETURN(Stmt epoch, db_->Prepare("UPDATE jobs SET lease_epoch = 1 WHERE id = ?"));
  epoch.Bind(1, std::string_view(job.id));
  SEEP_RETURN_IF_ERROR(epoch.Run());
  for (const CheckpointRecord& checkpoint : checkpoints) {
    SEEP_RETURN_IF_ERROR(InsertCheckpointLocked(job.id, checkpoint));
  }
  SEEP_RETURN_IF_ERROR(AddEventLocked(*db_, job.id, job.created_at_ms, "REBUILT", note));
  return tx.Commit();
}

}  // namespace seep::service
