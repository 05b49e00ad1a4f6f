// JobRunner: a fixed pool of worker threads that claim queued jobs from the store and run them.
//
// A job's failure is data (state FAILED with a code and message), never an exception leaving a
// thread. Each claim is a lease (owner, epoch, expiry) that a heartbeat thread renews, but only
// when the job made progress (a step, a progress report, a calibration solve) since the last
// renewal: a hung worker's lease runs out. A rescuer thread requeues the jobs whose lease
// expired while the server serves, and tells a hung worker of this process that it lost them;
// every write a worker makes is fenced by its epoch, so a worker whose lease was taken over gets
// ABORTED and stops its job without writing. A job that runs longer than job_time_limit in one
// claim is stopped at a step boundary, checkpointed and FAILED with DEADLINE_EXCEEDED. Each running
// job has its own stop source: a user's cancel stops that job only (recorded CANCELLED), shutdown
// stops all of them at a step boundary and leaves them RUNNING in the store, so the next seepd
// start queues them again. Running jobs write periodic checkpoints (CheckpointKeeper), one more
// when they are stopped, and a claimed job continues from its newest usable checkpoint: after a
// crash, a shutdown, a cancel or a failure followed by ResumeJob. Calibration jobs
// (job_runner_calibration.cc) are short and write no checkpoints: after a restart or a resume they
// run again from the start, and their records replace the earlier ones. A simulation's end (its
// last checkpoint, result and terminal state, mostly waits on fsync) is recorded by its worker's
// EndingSlot while the worker claims and runs its next job; the job keeps its lease until then.
//
// Every write a worker makes goes through a JobLedger (jobs/job_ledger.h): seepd's StoreLedger,
// or in seep-worker the RemoteLedger that makes the same calls over gRPC. The runner of a remote
// worker has no store: it neither rescues leases (the coordinator does) nor runs calibrations
// (the coordinator hands it simulations only).
#pragma once

#include <spdlog/logger.h>

#include <atomic>
#include <condition_variable>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "jobs/checkpoint_keeper.h"
#include "jobs/ending_slot.h"
#include "jobs/job_hub.h"
#include "jobs/job_ledger.h"
#include "jobs/test_crash_points.h"
#include "metrics/service_metrics.h"
#include "store/job_store.h"

namespace seep::service {

struct JobRunnerOptions {
  int workers = 1;
  // Threads of the core's parallel loops per running job (>= 1); 0 = the cores shared out among
  // the workers (core::CoreThreadsPerJob). Results do not depend on it.
  int threads_per_job = 0;
  std::string build_id;
  // Least wall time between two progress writes to the store for one job.
  std::chrono::milliseconds store_progress_interval{1000};
  // Who holds the leases this runner takes (unique per seepd process).
  std::string lease_owner = "seepd";
  // How long a lease lasts without a renewal; it must exceed the longest stretch of work without
  // progress (one step, a scene's set-up).
  std::chrono::milliseconds lease_duration{30000};
  // How often an idle worker looks for a job without being woken (in case a wake-up was missed).
  std::chrono::milliseconds idle_poll{1000};
  // How often the heartbeat renews leases and the rescuer looks for expired ones.
  std::chrono::milliseconds heartbeat_interval{2000};
  // Wall time one claim of a job may run before it is FAILED with DEADLINE_EXCEEDED; 0 = none.
  std::chrono::milliseconds job_time_limit{0};
  // A final write (result and terminal state) that fails is tried this many times in all, the
  // waits between tries doubling from final_write_backoff; then the job is FAILED with the reason.
  int final_write_attempts = 5;
  std::chrono::milliseconds final_write_backoff{100};
  // Interruptions in a row without progress after which a job is FAILED (JobStore::
  // RequeueRunning); the rescuer applies it, seepd passes it to the start-up requeue too.
  int max_interruptions = 3;
  // Test only: a worker running a job of this name ends the process (_Exit(86), as a crash
  // would) 1500 steps into its run.
  std::string test_crash_job;
  // Test only: a worker running a job of this name dies of SIGSEGV 1500 steps into its run.
  std::string test_segfault_job;
  // Test only: a worker running a job of this name allocates (and touches) memory 1500 steps
  // into its run until an allocation fails (a worker process with a memory limit only).
  std::string test_hog_memory_job;
  // A worker process that seepd supervises (seep-worker --supervised): a job's lease is renewed
  // during its set-up too (the scene's decoding, packing and first solve make no step, and a
  // large one outlasts a lease), because seepd itself ends a set-up that outlasts the time limit
  // or a cancel by ending the process. Elsewhere a set-up renews nothing, so that a hung one
  // loses its lease.
  bool renew_during_setup = false;
  // Said in the outcome of a run that ran out of memory (std::bad_alloc): the limit it ran into,
  // e.g. "the worker process's address space is limited to 2048 MiB (seepd
  // --job-memory-limit-mb)"; empty: none is known.
  std::string memory_limit_note;
  // Test only: the first this many tries of final result writes fail as a store error would.
  int test_fail_final_writes = 0;
  // Test only: a worker running a job of this name in its first claim stops making progress
  // 1500 steps into its run (as a hung worker would) until it is told it lost the lease.
  std::string test_stall_job;
  // Periodic checkpoints of running jobs, and resume from them (enabled = false: off).
  CheckpointPolicy checkpoints;
  // Test only: where seepd may kill itself (TestCrashPoints; null = nowhere).
  const TestCrashPoints* crash_points = nullptr;
  // Counts the steps the jobs take (optional, owned by the caller).
  ServiceMetrics* metrics = nullptr;
  // A worker process that ends by itself (seep-worker started by a batch system): once it has
  // claimed max_jobs jobs in all (0: no limit) and they ended, or once it found nothing to claim
  // for exit_when_idle with no job running (0: never), on_work_done is called, once, from a
  // worker thread; the caller then stops the runner.
  int max_jobs = 0;
  std::chrono::milliseconds exit_when_idle{0};
  std::function<void()> on_work_done;
};

class JobRunner {
 public:
  // `store` is seepd's (for the rescuer and the calibration records), or null in a remote
  // worker; both outlive the runner.
  JobRunner(JobLedger& ledger, JobStore* store, JobHub& hub, JobRunnerOptions options,
            std::shared_ptr<spdlog::logger> logger);
  ~JobRunner();
  JobRunner(const JobRunner&) = delete;
  JobRunner& operator=(const JobRunner&) = delete;

  void Start();
  // Stops claiming, interrupts running jobs at their next step and joins the workers.
  void Stop();
  // Jobs were queued: wake the idle workers.
  void Wake();
  // Asks the worker running this job (if it runs here) to stop it and record CANCELLED.
  void CancelRunning(const std::string& id);

 private:
  // What the runner knows of one job that a worker of this process is running.
  struct Running {
    std::int64_t epoch = 0;
    std::stop_source stop;  // this job only: cancel, lease loss or shutdown
    std::atomic<bool> cancel{false};
    std::atomic<bool> lease_lost{false};
    std::atomic<bool> time_limit_hit{false};
    std::atomic<bool> setting_up{true};  // until the simulation is built (renew_during_setup)
    // Bumped by the worker at every sign of progress; the heartbeat renews the lease only when it
    // moved since the last renewal (renewed_ticks: heartbeat thread only).
    std::atomic<std::uint64_t> ticks{0};
    std::uint64_t renewed_ticks = 0;
    std::shared_ptr<spdlog::logger> log;  // the job's own ("job-<id>")
    std::chrono::steady_clock::time_point wall_start;
    // Progress writes to the store, at most one per store_progress_interval: the time of the
    // last, and the newest progress held back since (the heartbeat writes it once the interval
    // has passed, so a run whose progress comes rarely is not left showing an older one).
    std::mutex progress_mutex;
    std::chrono::steady_clock::time_point last_store_write;  // progress_mutex
    std::optional<JobProgress> unstored_progress;            // progress_mutex

    // Why a checkpoint could not be written for lack of disk space (its RESOURCE_EXHAUSTED);
    // set by the worker before it stops the run, read by Conclude after the run ended.
    core::Status disk_full;

    // The one handling of a lost lease: when a fenced write `s` is ABORTED, another claim owns
    // the job now, so this worker stops it and records nothing more. True if so.
    bool StopIfLeaseLost(const core::Status& s);
    // A checkpoint the disk had no room for (`s` RESOURCE_EXHAUSTED) stops the run, to be FAILED
    // with the reason: its newest checkpoint stays its resume point. True if so.
    bool StopIfDiskFull(const core::Status& s);
  };
  // What differs between the end of a simulation and that of a calibration (see Conclude).
  struct Ending {
    const char* kind;  // "" or "calibration ", in log lines
    // First, for every outcome: false when the lease turned out lost (nothing is recorded).
    std::function<bool(bool stopped)> keep_state;
    std::function<void(double wall_s)> interrupted;  // shutdown: its log line and event
    // Records the result and SUCCEEDED (through RetryFinalWrite); an error other than ABORTED
    // makes the job FAILED with it (a non-finite metric, a store that keeps failing).
    std::function<Status(double wall_s)> succeed;
  };

  void WorkerLoop(const std::stop_token& stop);
  // Whether this runner's work is done (max_jobs claimed and ended, or idle for exit_when_idle);
  // mutex_ held.
  bool WorkDoneLocked(std::chrono::steady_clock::time_point now) const;
  void HeartbeatLoop(const std::stop_token& stop);
  // Renews one lease; on a pending cancel or a lost lease, stops the job.
  void Renew(const std::string& id, Running& running);
  // Requeues the jobs whose lease expired; a worker of this process still holding one of them
  // (hung) is told it lost the lease and forgotten, so a new claim can register.
  void RescueLoop(const std::stop_token& stop);
  void RescueExpired();
  // Test only (test_stall_job): blocks, making no progress and deaf to shutdown (as a worker
  // stuck in a step), until it is told it lost the lease.
  void StallForTest(Running& running);
  // Test only (test_hog_memory_job): allocates until an allocation throws std::bad_alloc.
  [[noreturn]] static void HogMemoryForTest(spdlog::logger& log);
  // Runs a claimed job; a simulation's end is handed to `endings` (recorded on its thread).
  void RunJob(JobRecord job, const std::stop_token& shutdown, EndingSlot& endings);
  // After a job's end is recorded: forgotten, its followers told, an idle worker woken.
  void Ended(const std::string& id, const Running& running);
  // Forgets `running` if it is still the job's registered run (a rescued job may be claimed
  // again, by another worker, before its hung worker ends).
  void Unregister(const std::string& id, const Running& running);
  // A simulation job: its scene decoded, resumed from its newest usable checkpoint and run with
  // periodic checkpoints. Returns the recording of its end (ConcludeSimulation), to run later.
  struct SimulationRun;
  std::function<void()> RunSimulation(JobRecord job, const std::shared_ptr<Running>& running);
  // A simulation's end: its last checkpoint, result series and terminal state (Conclude).
  void ConcludeSimulation(SimulationRun& run);
  // A calibration job (job_runner_calibration.cc): calibrates every target with the job's stop
  // token, then records the records and the terminal state, each fenced by the lease epoch.
  void RunCalibration(const JobRecord& job, Running& running);
  // Live progress to the hub, and to the store at most every store_progress_interval.
  void PublishProgress(const std::string& id, Running& running, const JobProgress& progress);
  // The progress PublishProgress held back, written once the interval has passed (heartbeat).
  void StoreHeldBackProgress(const std::string& id, Running& running);
  // Writes progress to the store through the ledger.
  void StoreProgress(const std::string& id, Running& running, const JobProgress& progress);
  // Records how a run ended: nothing after a lost lease; CANCELLED for a user's cancel; FAILED
  // (DEADLINE_EXCEEDED) over the time limit; FAILED (RESOURCE_EXHAUSTED) when a checkpoint found
  // the disk full; for a shutdown an INTERRUPTED event only (the job
  // stays RUNNING, so the next start queues it again); ending.succeed for a success, and FAILED
  // with its reason when that cannot be recorded; FAILED with the outcome otherwise.
  void Conclude(const JobRecord& job, Running& running, const core::Status& outcome,
                const Ending& ending);
  // An event of a job this worker runs (fenced by its lease epoch).
  void AddEvent(const std::string& id, const Running& running, const std::string& kind,
                const std::string& message);
  // Runs a final write until it succeeds, the lease is lost (ABORTED) or the store refuses the
  // data (INVALID_ARGUMENT), at most final_write_attempts times with a doubling wait; the last
  // failure says how many tries were made. `injectable`: test_fail_final_writes applies.
  core::Status RetryFinalWrite(Running& running, const char* what, bool injectable,
                               const std::function<core::Status()>& write);
  // A run's body, an exception turned into an INTERNAL outcome (nothing leaves a worker); running
  // out of memory is RESOURCE_EXHAUSTED, naming the limit when one is known.
  core::Status CatchAll(const std::function<core::Status()>& body) const;

  JobLedger& ledger_;
  JobStore* store_;  // null in a remote worker
  JobHub& hub_;
  JobRunnerOptions options_;
  std::shared_ptr<spdlog::logger> logger_;
  std::mutex mutex_;
  std::condition_variable_any wake_;
  std::condition_variable_any heartbeat_wake_;  // only to end the heartbeat's wait early
  std::uint64_t wake_count_ = 0;
  std::atomic<int> injected_final_write_failures_{0};        // from test_fail_final_writes
  std::map<std::string, std::shared_ptr<Running>> running_;  // guarded by mutex_
  int claims_ = 0;  // claimed, or being claimed, in all (for max_jobs); guarded by mutex_
  std::chrono::steady_clock::time_point idle_since_;  // the last job's end; guarded by mutex_
  std::atomic<bool> work_done_{false};                // on_work_done was called
  std::vector<std::jthread> workers_;
  std::jthread heartbeat_;
  std::jthread rescuer_;
};

}  // namespace seep::service
