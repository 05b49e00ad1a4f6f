// StoreLedger: the JobLedger of seepd itself, over its JobStore and the checkpoint files of its
// data folder. seepd's own workers use it, and so does the WorkerService on behalf of remote
// workers (whose uploaded checkpoints thus land where a local worker's would).
#pragma once

#include <spdlog/logger.h>

#include <filesystem>
#include <memory>
#include <optional>

#include "jobs/job_ledger.h"
#include "jobs/test_crash_points.h"
#include "store/job_store.h"

namespace seep::service {

class StoreLedger final : public JobLedger {
 public:
  // Checkpoint files go to <checkpoint_dir>/<job id>/ckpt-<step>.bin. `crash_points` (test only,
  // may be null) is passed between a checkpoint file and its record, and between a finished
  // run's final state made ready (its file written, if it has one) and its success recorded.
  // `claims`: the only kind of job Claim hands out (none: any); seepd's own threads run only
  // calibrations when its simulations run in worker processes.
  StoreLedger(JobStore& store, std::filesystem::path checkpoint_dir,
              std::shared_ptr<spdlog::logger> logger, const TestCrashPoints* crash_points = nullptr,
              std::optional<JobKind> claims = std::nullopt);

  core::Result<std::optional<JobRecord>> Claim(const std::string& owner,
                                               std::chrono::milliseconds lease) override;
  core::Result<bool> Heartbeat(const std::string& id, std::int64_t epoch,
                               std::chrono::milliseconds lease) override;
  core::Status UpdateProgress(const std::string& id, std::int64_t epoch,
                              const JobProgress& progress) override;
  core::Status AddEvent(const std::string& id, std::int64_t epoch, const std::string& kind,
                        const std::string& message) override;
  core::Result<std::int64_t> SaveCheckpoint(const JobRecord& job, const CheckpointMeta& meta,
                                            std::string_view state, std::uint32_t keep,
                                            CheckpointRole role) override;
  core::Result<std::optional<FetchedCheckpoint>> NewestCheckpoint(
      const JobRecord& job, std::optional<std::uint64_t> below_step) override;
  core::Status StoreResultSeries(const std::string& id, std::int64_t epoch,
                                 const std::vector<std::string>& columns,
                                 const std::vector<double>& values, const std::string& state_sha256,
                                 const JobProgress& final_progress) override;
  // One commit for the whole success, made durable within the store's durability window
  // (CommitSync::kWindowed: these runs are seepd's own, and one lost to a power loss runs again
  // to the same bytes). A final state whose checkpoint is at most kStoredCheckpointMaxBytes goes
  // into that commit too (its record holds the bytes); a larger one is written to its file first
  // (durably: the commit's record points to it).
  core::Result<FinalStateKept> RecordSuccess(const JobRecord& job, std::int64_t epoch,
                                             const std::optional<FinalState>& final_state,
                                             const RunSuccess& run) override;
  core::Status Finish(const std::string& id, std::int64_t epoch, JobState state,
                      const std::string& error_code, const std::string& error_message,
                      const std::vector<std::pair<std::string, double>>& metrics,
                      double wall_time_s) override;
  core::Status ReleaseLease(const std::string& id, std::int64_t epoch) override;

 private:
  // Where the job's checkpoint of `step` is written, when it is a file.
  std::filesystem::path CheckpointPath(const JobRecord& job, std::uint64_t step) const;
  // Removes the files of records the store dropped, but not the one of step `kept_step`.
  void RemoveDropped(const std::vector<CheckpointRecord>& dropped, std::uint64_t kept_step) const;

  JobStore& store_;
  std::filesystem::path checkpoint_dir_;
  std::shared_ptr<spdlog::logger> logger_;
  const TestCrashPoints* crash_points_;
  std::optional<JobKind> claims_;
};

}  // namespace seep::service
