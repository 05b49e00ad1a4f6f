// CheckpointKeeper: the periodic checkpoints of one running job, and the resume from them.
//
// The ledger (jobs/job_ledger.h) keeps them: seepd's StoreLedger as files in
// <data-dir>/checkpoints/<job id>/ckpt-<step>.bin (checkpoint_io: atomic, verified; the folders
// made durably, 0700; a small final state in its record in the store), a remote worker's
// RemoteLedger by uploading them to seepd, which does the same. A checkpoint is due every
// `every_steps` steps or `interval` of wall time, whichever comes first (either may be off); only
// the newest `keep` are kept, and each one is recorded (fenced by the job's lease epoch) before
// older ones are deleted. Resume asks the ledger for the newest one that verifies and belongs to
// this scene, and takes it if it restores, else the next older one; every checkpoint skipped is
// logged and recorded as a job event with the reason.
#pragma once

#include <spdlog/logger.h>

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "jobs/job_ledger.h"
#include "seep/core/run/simulation.h"
#include "seep/core/status.h"

namespace seep::service {

struct CheckpointPolicy {
  bool enabled = false;                       // false = checkpoints off
  std::uint64_t every_steps = 0;              // 0 = no step trigger
  std::chrono::milliseconds interval{30000};  // 0 = no wall-time trigger
  std::uint32_t keep = 3;
  // Told of every checkpoint written and recorded: its bytes and wall seconds (for metrics).
  std::function<void(std::int64_t bytes, double seconds)> on_written;
};

class CheckpointKeeper {
 public:
  CheckpointKeeper(JobLedger& ledger, const CheckpointPolicy& policy, const JobRecord& job,
                   std::string build_id, std::shared_ptr<spdlog::logger> log);

  bool enabled() const { return policy_.enabled; }

  // Restores `sim` from the newest usable checkpoint of the job. Returns the step it continues
  // from, or nullopt when there is none (the run starts from the beginning).
  std::optional<std::uint64_t> RestoreNewest(core::Simulation& sim);

  // The run starts (after a restore, if any): the wall-time trigger counts from here.
  void StartClock() { last_time_ = std::chrono::steady_clock::now(); }

  // Called at every step end: writes a checkpoint when one is due (see Write for the status).
  core::Status MaybeWrite(const core::Simulation& sim);
  // Writes one now (at shutdown, cancel and the end of a run). A failure is logged and recorded
  // as an event; the run goes on (its result is still correct, only less protected). A lost
  // lease is returned as ABORTED so the caller stops, and a full disk (the ledger's
  // RESOURCE_EXHAUSTED) too, so that the caller fails the job with the reason.
  core::Status Write(const core::Simulation& sim);
  // The run's final state, already serialized (SerializeSimulationState of its snapshot), as the
  // ledger keeps it with the run's success (JobLedger::RecordSuccess); nullopt when checkpoints
  // are off. `state` must outlive the result.
  std::optional<FinalState> FinalStateOf(const core::Simulation& sim, std::string_view state) const;
  // What RecordSuccess kept of it, `seconds` after the success began to be recorded: counted
  // as a checkpoint written, or logged as not kept.
  void CountFinalState(const FinalState& final_state, const FinalStateKept& kept, double seconds);

  std::uint64_t written() const { return written_; }
  double seconds_writing() const { return seconds_writing_; }

 private:
  CheckpointMeta MetaOf(const core::Simulation& sim) const;
  // One checkpoint written and recorded, `bytes` long, in `seconds`.
  void CountWritten(std::int64_t bytes, double seconds);
  void Event(const std::string& kind, const std::string& message);

  JobLedger& ledger_;
  CheckpointPolicy policy_;
  const JobRecord& job_;
  std::string build_id_;
  std::string scene_sha256_;
  std::shared_ptr<spdlog::logger> log_;
  std::uint64_t last_step_ = 0;
  std::chrono::steady_clock::time_point last_time_;
  std::uint64_t written_ = 0;
  double seconds_writing_ = 0.0;
};

}  // namespace seep::service
