// SlurmExecutor (seepd --executor slurm): seepd as the ledger and coordinator of runs that
// seep-worker processes execute inside Slurm jobs. A thread reconciles, every poll interval and
// whenever a job is submitted or cancelled:
//   1. the batch jobs it submitted, against squeue (state and node; those gone or terminal end);
//   2. PlanBatchJobs (batch_plan.h) on the queue and what the live ones' workers hold;
//   3. sbatch for the batch jobs wanted, scancel for those not wanted (a cancelled job's worker,
//      pending ones the queue no longer needs).
// Each batch job runs one seep-worker (the script it writes into <data-dir>/slurm/): one seep
// job and exit (--max-jobs 1), or, packed, N at a time until the queue is empty. Submitted with
// --requeue and --signal=B:TERM@grace, a preempted or timed-out worker checkpoints its job and
// gives it back before Slurm kills it; a worker that vanishes (scancel --signal=KILL, a node
// lost) loses its lease, which the coordinator's rescuer requeues, and the next round submits a
// batch job for it. Nothing is assumed of the cluster beyond sbatch, squeue and scancel on PATH
// and the SLURM_* variables of a job; no shared filesystem (workers speak gRPC only).
#pragma once

#include <spdlog/logger.h>

#include <chrono>
#include <condition_variable>
#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "executor/batch_plan.h"
#include "jobs/runner_flags.h"
#include "store/job_store.h"

namespace seep::service {

struct SlurmExecutorOptions {
  std::string partition;                 // --partition (empty: the cluster's default)
  std::string time_limit;                // --time (empty: the partition's default)
  std::vector<std::string> extra;        // more sbatch arguments, as they are
  int pack = 0;                          // 0: a batch job per seep job; N: N workers per batch job
  int max_batch_jobs = 100;              // alive at once
  std::string worker_path;               // seep-worker on the nodes
  std::string server;                    // the address workers dial
  std::vector<std::string> worker_args;  // more seep-worker arguments (e.g. --tls-ca PATH)
  std::string output;                    // sbatch --output (may hold %j)
  int signal_grace_s = 120;              // SIGTERM this long before the time limit
  double exit_when_idle_s = 30.0;        // a packed worker ends after this long without work
  std::chrono::milliseconds poll_interval{5000};
  std::chrono::milliseconds command_timeout{30000};
  std::string token;   // given to the workers in their environment (SEEP_TOKEN)
  RunnerFlags runner;  // threads, lease and checkpoint cadence, forwarded
};

class SlurmExecutor {
 public:
  SlurmExecutor(JobStore& store, std::filesystem::path data_dir, SlurmExecutorOptions options,
                std::shared_ptr<spdlog::logger> logger);
  ~SlurmExecutor();
  SlurmExecutor(const SlurmExecutor&) = delete;
  SlurmExecutor& operator=(const SlurmExecutor&) = delete;

  // Writes the worker script and checks that sbatch and squeue answer; an error names what is
  // missing. Then starts the reconciling thread.
  core::Status Start();
  void Stop();
  // Something changed in the queue (a submit, a cancel): reconcile now.
  void Wake();
  // The address the workers dial, when it is known only once the server is bound (before Start).
  void SetServer(std::string server) { options_.server = std::move(server); }

 private:
  void Loop(const std::stop_token& stop);
  void ReconcileOnce();
  // Step 1: the live batch jobs' states from squeue, stored; returns them as they are now (those
  // that ended flagged so), or nullopt when the store or squeue did not answer.
  std::optional<std::vector<BatchJobRecord>> RefreshStates();
  // sbatch's arguments for one worker's batch job (with --test-only: checked, not submitted).
  std::vector<std::string> SbatchArgv(bool test_only) const;
  core::Result<std::string> Submit();
  void Cancel(const std::string& batch_job_id, const char* why);
  std::string ScriptText() const;

  JobStore& store_;
  std::filesystem::path slurm_dir_;  // <data-dir>/slurm
  std::filesystem::path script_path_;
  SlurmExecutorOptions options_;
  BatchPlanOptions plan_options_;
  std::shared_ptr<spdlog::logger> logger_;
  std::mutex mutex_;
  std::condition_variable_any wake_;
  bool woken_ = false;  // guarded by mutex_
  std::jthread thread_;
};

}  // namespace seep::service
