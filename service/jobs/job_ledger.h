// JobLedger: everything a worker asks of the ledger of jobs while it runs one, in one interface,
// so that the one runner (JobRunner) runs jobs inside seepd (StoreLedger: the JobStore and the
// data folder's checkpoint files) and in seep-worker on another host (RemoteLedger: the same
// calls over gRPC to seepd's seep.v1.WorkerService). Results are bit-identical by construction:
// the same code takes the same steps on the same state either way.
//
// Every write names the lease epoch of the claim (a fencing token): a worker whose lease was
// taken over, or whose job is no longer RUNNING, gets ABORTED and must stop without writing.
#pragma once

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "seep/core/status.h"
#include "store/checkpoint_io.h"
#include "store/job_record.h"

namespace seep::service {

// A checkpoint as a worker receives it to resume from: its header and the state bytes, which
// verified (every chunk's and the whole file's SHA-256) and belong to the job and its scene.
struct FetchedCheckpoint {
  std::uint64_t step = 0;  // of its record (a resume that cannot use it asks for one below)
  CheckpointMeta meta;
  std::string state;
  std::string name;  // the file's name in the ledger's folder, for logs and events
};

// What a checkpoint is kept for. kResumePoint: a run continues from it after an interruption,
// so its record is durable at once. kFinalState: the state a run ended in (for exports and
// forks), which its outcome (a durable Finish) follows: its record may wait for that commit, since
// a power loss before it loses both and the job runs again.
enum class CheckpointRole { kResumePoint, kFinalState };

// A finished run's state as its end keeps it: the checkpoint's header and the state's bytes,
// and how many of the job's checkpoints to keep (the newest; older ones are removed).
struct FinalState {
  CheckpointMeta meta;
  std::string_view state;
  std::uint32_t keep = 1;
};

// What RecordSuccess kept of the final state: its checkpoint's bytes, or why it was not kept.
struct FinalStateKept {
  std::optional<std::int64_t> bytes;  // nullopt: none was given, or it could not be kept
  core::Status failure;               // why it could not be kept (the success stands)
};

class JobLedger {
 public:
  virtual ~JobLedger() = default;

  // The queued job of highest priority, moved to RUNNING under a new lease of `owner` that
  // lasts `lease` (the ledger's clock), or nullopt when none is queued.
  // The ledger records the CLAIMED event with the claim.
  virtual core::Result<std::optional<JobRecord>> Claim(const std::string& owner,
                                                       std::chrono::milliseconds lease) = 0;
  // Renews the lease: afterwards it has at least half of `lease` to run (a ledger may keep an
  // expiry that far ahead instead of writing now + lease at every renewal, so renew at least
  // every half lease; the runner does every quarter). True when a cancel was requested.
  virtual core::Result<bool> Heartbeat(const std::string& id, std::int64_t epoch,
                                       std::chrono::milliseconds lease) = 0;
  virtual core::Status UpdateProgress(const std::string& id, std::int64_t epoch,
                                      const JobProgress& progress) = 0;
  // One line of the job's history (CLAIMED, RESUMED, CHECKPOINT_SKIPPED, ...).
  virtual core::Status AddEvent(const std::string& id, std::int64_t epoch, const std::string& kind,
                                const std::string& message) = 0;

  // Keeps `state` as the job's checkpoint at meta.step (its file written atomically and
  // verified, then recorded, and the job's checkpoints beyond the newest `keep` removed).
  // Returns the file's size in bytes; RESOURCE_EXHAUSTED, nothing written, when the disk is too
  // full for it (below seepd's --min-free-disk-mb once written, or the file system refused it).
  virtual core::Result<std::int64_t> SaveCheckpoint(const JobRecord& job,
                                                    const CheckpointMeta& meta,
                                                    std::string_view state, std::uint32_t keep,
                                                    CheckpointRole role) = 0;
  // The newest recorded checkpoint of the job below `below_step` (none: any) that verifies and
  // belongs to the job and its scene; those passed over are recorded as CHECKPOINT_SKIPPED
  // events. nullopt when there is none.
  virtual core::Result<std::optional<FetchedCheckpoint>> NewestCheckpoint(
      const JobRecord& job, std::optional<std::uint64_t> below_step) = 0;

  // A run that succeeded: its time series, final-state hash and where it ended (the progress at
  // its last step), stored before Finish.
  virtual core::Status StoreResultSeries(const std::string& id, std::int64_t epoch,
                                         const std::vector<std::string>& columns,
                                         const std::vector<double>& values,
                                         const std::string& state_sha256,
                                         const JobProgress& final_progress) = 0;
  // A run that succeeded: its final state kept (when given) as a checkpoint of role
  // kFinalState, then its series, hash and final progress, then SUCCEEDED with its metrics. A
  // final state that cannot be kept is a CHECKPOINT_FAILED event and `failure`, not an error:
  // the run's outcome stands without it. This default makes the three calls above; a ledger
  // that can do it in one commit does (StoreLedger).
  virtual core::Result<FinalStateKept> RecordSuccess(const JobRecord& job, std::int64_t epoch,
                                                     const std::optional<FinalState>& final_state,
                                                     const RunSuccess& run);
  // The terminal state with its metrics (SUCCEEDED) or its error (FAILED, CANCELLED).
  virtual core::Status Finish(const std::string& id, std::int64_t epoch, JobState state,
                              const std::string& error_code, const std::string& error_message,
                              const std::vector<std::pair<std::string, double>>& metrics,
                              double wall_time_s) = 0;
  // A worker stopped by its own shutdown, its job checkpointed, gives the job back. Inside seepd
  // the job stays RUNNING with its lease released (no expiry), and seepd's next start queues it
  // again without counting an interruption; from a remote worker the lease ends at once and the
  // coordinator's rescuer queues the job again on its next round (the new checkpoint is the
  // progress that keeps it from counting as an interruption without progress).
  virtual core::Status ReleaseLease(const std::string& id, std::int64_t epoch) = 0;

 protected:
  // The CHECKPOINT_FAILED event of a final state that could not be kept (RecordSuccess).
  core::Status AddFinalStateFailedEvent(const JobRecord& job, std::int64_t epoch,
                                        std::uint64_t step, const core::Status& why);
};

}  // namespace seep::service
