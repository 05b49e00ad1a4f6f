// JobStore: the durable record of every job and its result, in SQLite.
//
// One connection guarded by a mutex (one writer); WAL, synchronous=FULL, busy_timeout, STRICT
// tables, migrations by PRAGMA user_version. SQL never leaves this directory.
#pragma once

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "durability_window.h"
#include "free_space.h"
#include "job_record.h"
#include "seep/core/status.h"
#include "stored_calibration.h"
#include "sweep_record.h"

namespace seep::service {

class Db;
class WalCheckpointer;
class Stmt;
using core::Result;
using core::Status;

struct InsertOutcome {
  JobRecord job;
  bool created = false;  // false: request_id matched an existing job, which is returned
};

// Which jobs List returns; empty members do not filter.
struct JobFilter {
  std::vector<JobState> states;
  std::string name_contains;
  std::vector<JobKind> kinds;
  std::vector<std::pair<std::string, std::string>> labels;  // the job carries every one
};

// What ApplyRetention removes; a zero member removes nothing.
struct RetentionPolicy {
  // Finished (terminal) jobs older than this, counted from when they finished, are deleted.
  std::int64_t max_age_ms = 0;
  // While the checkpoint files of all jobs together are larger, checkpoints of finished jobs are
  // removed: first every one that is not its job's newest, then the newest ones (a finished job's
  // final state), the oldest first in each group. A QUEUED or RUNNING job's checkpoints are never
  // removed, so the budget can be exceeded by them alone.
  std::int64_t max_checkpoint_bytes = 0;
};

struct RetentionOutcome {
  std::vector<std::string> deleted_jobs;
  // Every checkpoint record removed (of the deleted jobs, and those over the budget), with
  // job_id and its resolved path: the caller removes the files.
  std::vector<CheckpointRecord> removed_checkpoints;
  int checkpoints_over_budget = 0;  // how many of them went for the byte budget
  std::int64_t checkpoint_bytes_left = 0;
};

// OK when every metric is a finite number; else INVALID_ARGUMENT naming the first one that is not
// (SQLite would store a NaN as NULL). `what` starts the message ("store", "job result", ...).
Status CheckFiniteMetrics(const std::vector<std::pair<std::string, double>>& metrics,
                          std::string_view what);

struct JobPage {
  std::vector<JobRecord> jobs;  // newest first, scenes left empty
  std::optional<std::int64_t> next_cursor;
};

// A job that crash-looped: FAILED by a requeue, with the reason recorded on it.
struct CrashLoopFailure {
  std::string id;
  std::string message;
};

// How a commit reaches the disk. kDurable: synced (it survives a power loss). kRelaxed: written
// but not synced, so it survives a crash of the process, not a power loss, and the next durable
// commit makes it durable too (WAL frames are synced in order). kWindowed: kRelaxed, and the
// store's DurabilityWindow syncs it within JobStore::kDurabilityWindow (one fsync for every
// commit of the window), or the next durable commit does sooner.
enum class CommitSync { kDurable, kRelaxed, kWindowed };

class JobStore {
 public:
  static constexpr int kSchemaVersion = 14;
  // How many interruptions in a row without progress fail a job (see RequeueRunning).
  static constexpr int kDefaultMaxInterruptions = 3;
  // How long a CommitSync::kWindowed commit may wait for its fsync.
  static constexpr std::chrono::milliseconds kDurabilityWindow{100};
  ~JobStore();

  // The folder holding the database is the data folder: checkpoint paths inside it are stored
  // relative to it, so the folder can be moved (see RecordCheckpoint). `free_space`: how much of
  // its file system is kept free (store/free_space.h); below it Insert, InsertFork and
  // InsertSweep are RESOURCE_EXHAUSTED, and so is any write the file system refuses.
  static Result<std::unique_ptr<JobStore>> Open(const std::string& path,
                                                FreeSpacePolicy free_space = {});
  const std::filesystem::path& data_dir() const { return data_dir_; }
  const FreeSpaceGuard& free_space() const { return free_space_; }
  // While the disk is low (`low`), the WAL gives its space back: a checkpoint that resets it
  // also truncates the file, and one is run now that copies every frame back and truncates it
  // (UNAVAILABLE when a reader kept it from finishing: try again later). Not low: the WAL keeps
  // its size once more, its pages reused rather than allocated again at every reset.
  Status FitWalToDisk(bool low);

  // Stores a new QUEUED job; with a request_id already present, returns that job instead.
  Result<InsertOutcome> Insert(const JobRecord& job);
  // Insert for a fork (job.parent_job_id set; job_store_forks.cc): the job and the record of its
  // first checkpoint `start` (the copy of its parent's checkpoint, already written) in one
  // transaction, so that its first claim continues from it. With a request_id already present it
  // returns that job and records nothing (the caller removes its copy).
  Result<InsertOutcome> InsertFork(const JobRecord& job, const CheckpointRecord& start);
  Result<JobRecord> Get(const std::string& id);
  // Get without the scene bytes (left empty): for readers that never show it, such as watchers.
  Result<JobRecord> GetWithoutScene(const std::string& id);
  // Every state with its number of jobs (0 included), in the order of JobState.
  Result<std::vector<std::pair<JobState, std::int64_t>>> CountByState();
  // Newest first; cursor is the next_cursor of the previous page (with the same filter).
  Result<JobPage> List(std::uint32_t limit, std::optional<std::int64_t> cursor,
                       const JobFilter& filter = {});

  // Moves the QUEUED job of highest priority (the oldest of those) to RUNNING under a new lease
  // held by owner until now_ms + lease_ms (lease_epoch + 1), records its CLAIMED event in the
  // same transaction, and returns it; with `kind` set, only a job of that kind (a remote worker
  // runs simulations only). `placement`: where the
  // claiming remote worker runs (its batch job and node), recorded with the job (none: cleared).
  // Nothing is claimed while the disk is low (free_space()).
  // `sync`: kRelaxed only for a claim whose holder dies with this process (seepd's own
  // workers): lost to a power loss, the job is simply queued again, and no live worker can hold
  // an epoch the store forgot.
  Result<std::optional<JobRecord>> ClaimNextQueued(
      const std::string& owner, std::int64_t now_ms, std::int64_t lease_ms,
      std::optional<JobKind> kind = std::nullopt,
      const std::optional<WorkerPlacement>& placement = std::nullopt,
      CommitSync sync = CommitSync::kDurable);
  // Worker writes, each fenced by the lease epoch of the claim: a worker whose lease was taken
  // over (or whose job is no longer RUNNING) gets ABORTED and must stop the job.
  // Heartbeat extends the lease to expires_at_ms and returns whether a cancel was requested.
  // With keep_beyond_ms, a stored expiry at or beyond it is kept and nothing is written (the
  // lease is still checked): renewals every second of a lease of minutes then cost a read, not
  // a write, a second.
  Result<bool> Heartbeat(const std::string& id, std::int64_t epoch, std::int64_t expires_at_ms,
                         std::optional<std::int64_t> keep_beyond_ms = std::nullopt);
  Status UpdateProgress(const std::string& id, std::int64_t epoch, const JobProgress& progress);
  // Moves the RUNNING job to a terminal state with its metrics, in one transaction; a metric
  // that is not finite is INVALID_ARGUMENT (nothing written). A job that ends other than
  // SUCCEEDED keeps no result: a series or calibration records stored before are removed.
  Status Finish(const std::string& id, std::int64_t epoch, JobState state,
                const std::string& error_code, const std::string& error_message,
                const std::vector<std::pair<std::string, double>>& metrics, double wall_time_s,
                std::int64_t now_ms);

  // QUEUED -> CANCELLED at once; RUNNING -> cancel_requested (the worker finishes it); a terminal
  // job -> FAILED_PRECONDITION; unknown -> NOT_FOUND. Returns the job as it is now.
  Result<JobRecord> Cancel(const std::string& id, std::int64_t now_ms);
  // FAILED or CANCELLED -> QUEUED as the next attempt, its outcome cleared; other states ->
  // FAILED_PRECONDITION; unknown -> NOT_FOUND. Returns the job as it is now.
  Result<JobRecord> Resume(const std::string& id);
  // Removes a finished job and everything kept of it (job_store_retention.cc), in one
  // transaction; a QUEUED or RUNNING job is FAILED_PRECONDITION naming its state, an unknown one
  // NOT_FOUND. Returns its checkpoint records (resolved paths): the caller removes the files.
  Result<std::vector<CheckpointRecord>> Delete(const std::string& id);
  // Sweeps (job_store_sweeps.cc). InsertSweep stores the sweep and its jobs (new QUEUED jobs,
  // in position order) in one transaction; with a request_id already present it returns that
  // sweep instead (ALREADY_EXISTS when its definition differs), storing nothing.
  Result<SweepInsertOutcome> InsertSweep(const SweepRecord& sweep,
                                         const std::vector<JobRecord>& jobs);
  // The sweep with its job ids by position (jobs deleted on their own are missing); NOT_FOUND
  // for an unknown sweep.
  Result<SweepRecord> GetSweep(const std::string& id);
  // Removes the sweep and every job of it (as Delete) in one transaction: FAILED_PRECONDITION
  // naming the first QUEUED or RUNNING job, when it has one, and nothing is removed. Returns the
  // checkpoint records of all its jobs: the caller removes the files.
  Result<SweepDeletion> DeleteSweep(const std::string& id);
  // Batch jobs (job_store_batch.cc): the jobs a batch executor (seepd --executor slurm)
  // submitted to start remote workers, and what it needs to decide how many more to submit.
  Status InsertBatchJob(const BatchJobRecord& batch_job);
  // NOT_FOUND for an id never recorded.
  Result<BatchJobRecord> GetBatchJob(const std::string& id);
  // Those not ended, oldest first.
  Result<std::vector<BatchJobRecord>> LiveBatchJobs();
  // The state and node the batch system reports now; ended_at_ms set: it ended (is no longer
  // live). Unknown ids are ignored.
  Status UpdateBatchJob(const std::string& id, const std::string& state, const std::string& node,
                        std::optional<std::int64_t> ended_at_ms);
  // What the live batch jobs' workers hold, and the simulation jobs that wait for a worker.
  Result<BatchDemand> BatchDemandNow();

  // Applies the policy as of now_ms, in one transaction (job_store_retention.cc); each job that
  // keeps its record but loses checkpoints gets a CHECKPOINTS_RETAINED event.
  Result<RetentionOutcome> ApplyRetention(const RetentionPolicy& policy, std::int64_t now_ms);

  // Checkpoint files of a job (job_store_checkpoints.cc). Record is fenced by the lease epoch;
  // it replaces a record of the same step and returns the records beyond the newest `keep`,
  // already removed from the store, whose files the caller deletes. A path inside the data
  // folder is stored relative to it (elsewhere: absolute); every record the store returns has
  // its path resolved against the data folder as it is now, absolute and normalized.
  // `sync`: kRelaxed for a run's final state only, whose outcome (a durable Finish) follows.
  Result<std::vector<CheckpointRecord>> RecordCheckpoint(const std::string& id, std::int64_t epoch,
                                                         const CheckpointRecord& checkpoint,
                                                         std::uint32_t keep,
                                                         CommitSync sync = CommitSync::kDurable);
  // Newest (highest step) first.
  Result<std::vector<CheckpointRecord>> ListCheckpoints(const std::string& id);
  // The resolved path of every recorded checkpoint file of every job (for the start-up sweep).
  Result<std::vector<std::filesystem::path>> AllCheckpointPaths();
  // The time series and final-state hash of a run that succeeded, fenced by the lease epoch;
  // stored before Finish so that a job is never SUCCEEDED without them. With final_progress,
  // where the run ended is stored in the same transaction (else the progress stays).
  Status StoreResultSeries(const std::string& id, std::int64_t epoch,
                           const std::vector<std::string>& columns,
                           const std::vector<double>& values, const std::string& state_sha256,
                           const JobProgress* final_progress = nullptr);
  // A run's success in one transaction, fenced by the lease epoch: its final state's checkpoint
  // (when given; the records beyond the newest `keep` are dropped and returned, as
  // RecordCheckpoint does), its series, hash and final progress, its metrics and SUCCEEDED. One
  // commit, so a job is never SUCCEEDED without all of it. `sync`: kDurable (one fsync for the
  // lot) or kWindowed, for a run of seepd's own workers: lost to a power loss within the window,
  // the job is RUNNING (or QUEUED) again at the next start and runs again to the same bytes.
  Result<std::vector<CheckpointRecord>> RecordSuccess(const std::string& id, std::int64_t epoch,
                                                      const RunSuccess& run,
                                                      const CheckpointRecord* final_checkpoint,
                                                      std::uint32_t keep, std::int64_t now_ms,
                                                      CommitSync sync = CommitSync::kDurable);
  // The durability window's syncs so far (each covers every windowed commit before it), and
  // whether a windowed commit waits for one.
  std::uint64_t WindowedSyncs() const;
  bool WindowedCommitPending() const;
  // The job's event log, oldest first (the store adds SUBMITTED, CHECKPOINT, the outcome and
  // the other state changes it makes itself). Adding to a job that does not exist is NOT_FOUND.
  Status AddEvent(const std::string& id, std::int64_t at_ms, const std::string& kind,
                  const std::string& message);
  // AddEvent by the worker holding the job's lease: fenced by the lease epoch (ABORTED when the
  // job is no longer RUNNING under it), so a worker that lost its job leaves no trace in it.
  Status AddLeasedEvent(const std::string& id, std::int64_t epoch, std::int64_t at_ms,
                        const std::string& kind, const std::string& message);
  // The job's events after the event `after_id` (0: from the first), at most `limit`; an unknown
  // job is NOT_FOUND.
  Result<std::vector<JobEventRecord>> ListEvents(const std::string& id, std::int64_t after_id = 0,
                                                 std::uint32_t limit = UINT32_MAX);

  // Calibration records (job_store_calibrations.cc). Record replaces every record and tag of
  // the job (a re-run after a restart writes the same rows again), fenced by the lease epoch;
  // every record must carry job_id == id.
  Status RecordCalibrations(const std::string& id, std::int64_t epoch,
                            const std::vector<StoredCalibration>& records,
                            const std::vector<std::string>& tags);
  // Newest first; cursor is the next_cursor of the previous page (with the same filter).
  Result<CalibrationPage> ListCalibrations(std::uint32_t limit, std::optional<std::int64_t> cursor,
                                           const CalibrationFilter& filter = {});
  // The `limit` converged records closest to the probe by CalibrationDistance
  // (calibration_lookup.h), closest first; ties go to the newer record. A scan of every
  // converged record: fine for the thousands a calibration database holds.
  Result<std::vector<CalibrationNeighbour>> NearestCalibrations(const CalibrationProbe& probe,
                                                                std::uint32_t limit);
  // Every converged record of one setup (scene_sha256), by target permeability.
  Result<std::vector<StoredCalibration>> CalibrationsOfSetup(const std::string& scene_sha256);

  // At start-up: jobs left RUNNING under a lease not held by current_owner go back to QUEUED
  // (or to CANCELLED when a cancel was pending). Returns how many were re-queued.
  //
  // Both requeues count interruptions: a job whose lease was not released (a crash, a hung or
  // dead worker; not a shutdown, see ReleaseLease) and whose newest checkpoint is at the same step
  // as at its previous interruption was interrupted once more without progress; at
  // max_interruptions in a row it is FAILED (ABORTED, the count and step in its message, an
  // INTERRUPTED_TOO_OFTEN event) instead of queued, so that a job that crashes seepd does not run
  // first on every restart. Those are appended to *crash_loops when given.
  Result<int> RequeueRunning(const std::string& current_owner,
                             int max_interruptions = kDefaultMaxInterruptions,
                             std::vector<CrashLoopFailure>* crash_loops = nullptr);
  // While serving: jobs RUNNING under a lease that expired before now_ms (their worker died or
  // stopped making progress) go back to QUEUED, or to CANCELLED when a cancel was pending; the
  // old lease's writes are ABORTED from then on. Returns the rescued jobs as they were before
  // (a crash-looping one is FAILED instead, as in RequeueRunning).
  Result<std::vector<JobRecord>> RequeueExpired(
      std::int64_t now_ms, int max_interruptions = kDefaultMaxInterruptions,
      std::vector<CrashLoopFailure>* crash_loops = nullptr);
  // The RUNNING jobs whose lease owner begins with owner_prefix (one worker process's), oldest
  // claim first: what seepd's supervisor of its worker processes looks at.
  Result<std::vector<JobRecord>> RunningLeasedBy(const std::string& owner_prefix);
  // A job rebuilt from its checkpoint files after the database was lost
  // (jobs/checkpoint_recovery.h): inserted QUEUED under its own id, as if claimed once (so that
  // its next claim continues from its newest checkpoint), with its checkpoint records and a
  // REBUILT event saying `note`, in one transaction; ALREADY_EXISTS if the id is taken.
  Status InsertRecovered(const JobRecord& job, const std::vector<CheckpointRecord>& checkpoints,
                         const std::string& note);
  // A worker stopped by shutdown leaves its job RUNNING for the next start but releases the
  // lease (no expiry), so that the interruption does not count as one without progress.
  // Fenced by the lease epoch.
  Status ReleaseLease(const std::string& id, std::int64_t epoch);

 private:
  JobStore(std::unique_ptr<Db> db, std::filesystem::path data_dir, FreeSpacePolicy free_space);
  // A checkpoint path as stored (relative inside the data folder) and as returned (resolved).
  std::string StoredCheckpointPath(const std::string& path) const;
  std::filesystem::path ResolvedCheckpointPath(const std::string& stored) const;
  Status Migrate();
  Result<JobRecord> GetLocked(const std::string& id, bool with_scene);
  // Insert and Delete inside the caller's transaction (InsertSweep and DeleteSweep use them).
  Result<InsertOutcome> InsertLocked(const JobRecord& job);
  Result<std::vector<CheckpointRecord>> DeleteLocked(const std::string& id);
  Result<SweepRecord> GetSweepLocked(const std::string& id);
  Status ReadLabelsLocked(std::vector<JobRecord>& jobs);
  Status ReadResultSeriesLocked(JobRecord& job);
  // UpdateProgress's statement, mutex_ held (ABORTED unless RUNNING under `epoch`).
  Status UpdateProgressLocked(const std::string& id, std::int64_t epoch,
                              const JobProgress& progress);
  // Records (or replaces) one checkpoint row of job `id`, inside the caller's transaction.
  Status InsertCheckpointLocked(const std::string& id, const CheckpointRecord& checkpoint);
  // RecordCheckpoint's and RecordSuccess's part, inside the caller's transaction (lease checked).
  Result<std::vector<CheckpointRecord>> RecordCheckpointLocked(const std::string& id,
                                                               const CheckpointRecord& checkpoint,
                                                               std::uint32_t keep);
  // StoreResultSeries's and Finish's parts, inside the caller's transaction.
  Status StoreResultSeriesLocked(const std::string& id, std::int64_t epoch,
                                 const std::vector<std::string>& columns,
                                 const std::vector<double>& values, const std::string& state_sha256,
                                 const JobProgress* final_progress);
  Status FinishLocked(const std::string& id, std::int64_t epoch, JobState state,
                      const std::string& error_code, const std::string& error_message,
                      const std::vector<std::pair<std::string, double>>& metrics,
                      double wall_time_s, std::int64_t now_ms);
  // The ids of the jobs forked from `id`, oldest first.
  Result<std::vector<std::string>> ChildJobIdsLocked(const std::string& id);
  Result<std::optional<std::string>> FindByRequestIdLocked(const std::string& request_id);
  Status ReadCalibrationTagsLocked(std::vector<StoredCalibration>& records);
  // Removes what a run of the job produced (metrics, series, calibration records and tags).
  Status ClearResultsLocked(const std::string& id);
  // RUNNING jobs matching `where` (its one parameter bound by `bind(statement, index)`) go back
  // to QUEUED, or to CANCELLED with `cancel_message` (and a CANCELLED event) when a cancel was
  // pending; returns the ids of those queued.
  Result<std::vector<std::string>> RequeueLocked(const char* where,
                                                 const std::function<void(Stmt&, int)>& bind,
                                                 std::string_view cancel_message,
                                                 int max_interruptions,
                                                 std::vector<CrashLoopFailure>* crash_loops);

  std::filesystem::path data_dir_;  // absolute, normalized
  FreeSpaceGuard free_space_;       // before db_, whose errors name what it measures
  std::mutex mutex_;
  std::unique_ptr<Db> db_;
  // After db_: destroyed first, so that it syncs what is pending while the connection (which
  // keeps the WAL file) is still open.
  std::unique_ptr<DurabilityWindow> durability_window_;
  // After durability_window_: unhooked and stopped first, while db_ is open.
  std::unique_ptr<WalCheckpointer> wal_checkpointer_;
};

}  // namespace seep::service
