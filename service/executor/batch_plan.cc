#include "executor/batch_plan.h"

#include <algorithm>
#include <array>
#include <string_view>

namespace seep::service {
namespace {

BatchDemand::Use UseOf(const BatchDemand& demand, const std::string& id) {
  const auto it = demand.by_batch_job.find(id);
  return it == demand.by_batch_job.end() ? BatchDemand::Use{} : it->second;
}

int Capacity(const BatchDemand::Use& use, const BatchPlanOptions& options) {
  if (options.max_jobs_per_worker > 0) {
    return std::max(0, options.max_jobs_per_worker - use.claimed) > 0 ? 1 : 0;
  }
  return std::max(0, options.workers_per_job - use.running);
}

}  // namespace

bool IsEndedBatchState(const std::string& state) {
  // PREEMPTED is not among them: a job submitted with --requeue goes back to PENDING.
  constexpr std::array<std::string_view, 10> kEnded = {
      "COMPLETED", "CANCELLED", "FAILED",        "TIMEOUT", "NODE_FAIL",
      "BOOT_FAIL", "DEADLINE",  "OUT_OF_MEMORY", "REVOKED", "ENDED"};
  // squeue may print "CANCELLED by 0".
  const std::string_view word = std::string_view(state).substr(0, state.find(' '));
  return std::find(kEnded.begin(), kEnded.end(), word) != kEnded.end();
}

BatchPlan PlanBatchJobs(const BatchDemand& demand, const std::vector<BatchJobRecord>& live,
                        const BatchPlanOptions& options) {
  BatchPlan plan;
  std::int64_t free_slots = 0;
  int alive = 0;
  std::vector<const BatchJobRecord*> idle_pending;  // cancellable when not needed
  for (const BatchJobRecord& batch : live) {
    if (batch.ended_at_ms || IsEndedBatchState(batch.state)) continue;
    ++alive;
    const BatchDemand::Use use = UseOf(demand, batch.id);
    if (options.max_jobs_per_worker == 1 && use.cancel_requested > 0) {
      plan.cancel.push_back(batch.id);
      continue;
    }
    free_slots += Capacity(use, options);
    if (batch.state == "PENDING" && use.claimed == 0) idle_pending.push_back(&batch);
  }
  const std::int64_t deficit = demand.queued_simulations - free_slots;
  if (deficit > 0) {
    const std::int64_t per_job = std::max(1, options.workers_per_job);
    const std::int64_t wanted = (deficit + per_job - 1) / per_job;
    plan.submit = static_cast<int>(
        std::clamp<std::int64_t>(wanted, 0, std::max(0, options.max_live - alive)));
    return plan;
  }
  // The newest pending ones first: the oldest are the likeliest to start soon.
  for (auto it = idle_pending.rbegin(); it != idle_pending.rend(); ++it) {
    const int capacity = Capacity(BatchDemand::Use{}, options);
    if (free_slots - capacity < demand.queued_simulations) break;
    free_slots -= capacity;
    plan.cancel.push_back((*it)->id);
  }
  return plan;
}

}  // namespace seep::service
