// JobStore: batch jobs (schema v12). seepd's batch executor (service/executor/) records each
// batch job it submits to start seep-worker, follows its state as the batch system reports it,
// and decides how many more to submit from what the live ones' workers hold; a remote worker
// names its batch job in its claim, which the claim stores with the job (jobs.batch_job_id).
#include <fmt/format.h>

#include "job_store.h"
#include "job_store_internal.h"
#include "sqlite_handle.h"

namespace seep::service {
namespace {

constexpr const char* kBatchColumns =
    "id, workers, max_jobs, state, node, submitted_at_ms, ended_at_ms";

BatchJobRecord ReadBatchRow(const Stmt& s) {
  BatchJobRecord batch;
  batch.id = s.ColumnText(0);
  batch.workers = static_cast<int>(s.ColumnInt(1));
  batch.max_jobs = static_cast<int>(s.ColumnInt(2));
  batch.state = s.ColumnText(3);
  batch.node = s.ColumnText(4);
  batch.submitted_at_ms = s.ColumnInt(5);
  if (!s.ColumnIsNull(6)) batch.ended_at_ms = s.ColumnInt(6);
  return batch;
}

}  // namespace

Status JobStore::InsertBatchJob(const BatchJobRecord& batch) {
  const StoreOperation operation("record a batch job");
  std::lock_guard lock(mutex_);
  SEEP_ASSIGN_OR_RETURN(
      Stmt s, db_->Prepare(fmt::format("INSERT OR REPLACE INTO batch_jobs ({}) VALUES (?, ?, ?, ?, "
                                       "?, ?, ?)",
                                       kBatchColumns)));
  s.Bind(1, std::string_view(batch.id))
      .Bind(2, static_cast<std::int64_t>(batch.workers))
      .Bind(3, static_cast<std::int64_t>(batch.max_jobs))
      .Bind(4, std::string_view(batch.state))
      .Bind(5, std::string_view(batch.node))
      .Bind(6, batch.submitted_at_ms)
      .Bind(7, batch.ended_at_ms);
  return s.Run();
}

Result<BatchJobRecord> JobStore::GetBatchJob(const std::string& id) {
  const StoreOperation operation("read a batch job");
  std::lock_guard lock(mutex_);
  SEEP_ASSIGN_OR_RETURN(
      Stmt s, db_->Prepare(fmt::format("SELECT {} FROM batch_jobs WHERE id = ?", kBatchColumns)));
  s.Bind(1, std::string_view(id));
  SEEP_ASSIGN_OR_RETURN(const bool row, s.Step());
  if (!row) return core::NotFound(fmt::format("store: no batch job {}", id));
  return ReadBatchRow(s);
}

Result<std::vector<BatchJobRecord>> JobStore::LiveBatchJobs() {
  const StoreOperation operation("list the live batch jobs");
  std::lock_guard lock(mutex_);
  SEEP_ASSIGN_OR_RETURN(
      Stmt s, db_->Prepare(fmt::format("SELECT {} FROM batch_jobs WHERE ended_at_ms IS NULL ORDER "
                                       "BY submitted_at_ms, id",
                                       kBatchColumns)));
  std::vector<BatchJobRecord> live;
  for (;;) {
    SEEP_ASSIGN_OR_RETURN(const bool row, s.Step());
    if (!row) break;
    live.push_back(ReadBatchRow(s));
  }
  return live;
}

Status JobStore::UpdateBatchJob(const std::string& id, const std::string& state,
                                const std::string& node, std::optional<std::int64_t> ended_at_ms) {
  const StoreOperation operation("update a batch job");
  std::lock_guard lock(mutex_);
  SEEP_ASSIGN_OR_RETURN(
      Stmt s,
      db_->Prepare("UPDATE batch_jobs SET state = ?, node = CASE WHEN ? = '' THEN node ELSE "
                   "? END, ended_at_ms = ? WHERE id = ?"));
  s.Bind(1, std::string_view(state))
      .Bind(2, std::string_view(node))
      .Bind(3, std::string_view(node))
      .Bind(4, ended_at_ms)
      .Bind(5, std::string_view(id));
  return s.Run();
}

Result<BatchDemand> JobStore::BatchDemandNow() {
  const StoreOperation operation("count what the batch jobs hold");
  std::lock_guard lock(mutex_);
  BatchDemand demand;
  SEEP_ASSIGN_OR_RETURN(Stmt queued,
                        db_->Prepare("SELECT COUNT(*) FROM jobs WHERE state = 'QUEUED' AND kind = "
                                     "'SIMULATION'"));
  SEEP_ASSIGN_OR_RETURN(const bool counted, queued.Step());
  if (counted) demand.queued_simulations = queued.ColumnInt(0);
  SEEP_ASSIGN_OR_RETURN(
      Stmt use, db_->Prepare("SELECT batch_job_id, SUM(state = 'RUNNING'), COUNT(*), SUM(state = "
                             "'RUNNING' AND cancel_requested != 0) FROM jobs WHERE batch_job_id IN "
                             "(SELECT id FROM batch_jobs WHERE ended_at_ms IS NULL) GROUP BY "
                             "batch_job_id"));
  for (;;) {
    SEEP_ASSIGN_OR_RETURN(const bool row, use.Step());
    if (!row) break;
    BatchDemand::Use& u = demand.by_batch_job[use.ColumnText(0)];
    u.running = static_cast<int>(use.ColumnInt(1));
    u.claimed = static_cast<int>(use.ColumnInt(2));
    u.cancel_requested = static_cast<int>(use.ColumnInt(3));
  }
  return demand;
}

}  // namespace seep::service
