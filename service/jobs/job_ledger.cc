#include "jobs/job_ledger.h"

#include <fmt/format.h>

namespace seep::service {

core::Result<FinalStateKept> JobLedger::RecordSuccess(const JobRecord& job, std::int64_t epoch,
                                                      const std::optional<FinalState>& final_state,
                                                      const RunSuccess& run) {
  FinalStateKept kept;
  if (final_state) {
    auto saved = SaveCheckpoint(job, final_state->meta, final_state->state, final_state->keep,
                                CheckpointRole::kFinalState);
    if (saved.ok()) {
      kept.bytes = *saved;
    } else if (saved.status().code() == core::StatusCode::kAborted) {
      return saved.status();  // the lease is lost: nothing more may be written
    } else {
      kept.failure = saved.status();
      // Best effort: the history line is worth less than the outcome that follows.
      (void)AddFinalStateFailedEvent(job, epoch, final_state->meta.step, kept.failure);
    }
  }
  SEEP_RETURN_IF_ERROR(StoreResultSeries(job.id, epoch, run.series_columns, run.series_values,
                                         run.state_sha256, run.final_progress));
  SEEP_RETURN_IF_ERROR(
      Finish(job.id, epoch, JobState::kSucceeded, "", "", run.metrics, run.wall_time_s));
  return kept;
}

core::Status JobLedger::AddFinalStateFailedEvent(const JobRecord& job, std::int64_t epoch,
                                                 std::uint64_t step, const core::Status& why) {
  return AddEvent(job.id, epoch, "CHECKPOINT_FAILED",
                  fmt::format("step {}: {}", step, why.ToString()));
}

}  // namespace seep::service
