// PlanBatchJobs: how many batch jobs (each starting one seep-worker) the executor submits now,
// and which it cancels, from the queue and what the live batch jobs' workers hold. Pure, so that
// the rule is tested without a batch system.
//
// A live batch job can still take `capacity` jobs: one per job mode (max_jobs_per_worker 1),
// one if its worker has claimed nothing yet; packed (max_jobs_per_worker 0, the worker runs
// until the queue is empty), its worker slots less the jobs it runs. Submitted: enough to give
// every queued simulation a slot, up to max_live batch jobs. Cancelled: a one-per-job batch job
// whose job a user cancelled (its worker is stopped by scancel, not left to notice), and pending
// batch jobs not needed any more (the queue shrank: cancels, other workers), newest first.
#pragma once

#include <string>
#include <vector>

#include "store/job_record.h"

namespace seep::service {

struct BatchPlanOptions {
  int workers_per_job = 1;      // seep jobs one batch job's worker runs at a time
  int max_jobs_per_worker = 1;  // 1: a batch job per seep job; 0: until the queue is empty
  int max_live = 100;           // batch jobs alive at once, at most
};

struct BatchPlan {
  int submit = 0;
  std::vector<std::string> cancel;  // batch job ids
};

// True for a state in which a batch job will not run again (Slurm's terminal states).
bool IsEndedBatchState(const std::string& state);

BatchPlan PlanBatchJobs(const BatchDemand& demand, const std::vector<BatchJobRecord>& live,
                        const BatchPlanOptions& options);

}  // namespace seep::service
