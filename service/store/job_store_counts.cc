// JobStore::CountByState: how many jobs are in each state (the metrics endpoint's gauges).
#include "job_store.h"
#include "sqlite_handle.h"

namespace seep::service {

Result<std::vector<std::pair<JobState, std::int64_t>>> JobStore::CountByState() {
  std::lock_guard lock(mutex_);
  std::vector<std::pair<JobState, std::int64_t>> counts;
  for (const JobState state : {JobState::kQueued, JobState::kRunning, JobState::kSucceeded,
                               JobState::kFailed, JobState::kCancelled}) {
    counts.emplace_back(state, 0);
  }
  SEEP_ASSIGN_OR_RETURN(Stmt s, db_->Prepare("SELECT state, COUNT(*) FROM jobs GROUP BY state"));
  for (;;) {
    SEEP_ASSIGN_OR_RETURN(const bool row, s.Step());
    if (!row) break;
    const auto state = ParseJobState(s.ColumnText(0));
    if (!state) continue;
    for (auto& [known, count] : counts) {
      if (known == *state) count = s.ColumnInt(1);
    }
  }
  return counts;
}

}  // namespace seep::service
