// What the store keeps of a job. Plain data: the scene travels as the serialized seep.v1.Scene
// bytes (seep.v1.Calibration for a calibration job), so the store needs neither protobuf nor the
// physics.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace seep::service {

enum class JobState { kQueued, kRunning, kSucceeded, kFailed, kCancelled };

const char* JobStateName(JobState state);  // "QUEUED", …; the spelling stored in SQLite
std::optional<JobState> ParseJobState(std::string_view name);
inline bool IsTerminal(JobState s) {
  return s == JobState::kSucceeded || s == JobState::kFailed || s == JobState::kCancelled;
}

// What a job runs: a scene (simulation) or a residual-aperture calibration.
enum class JobKind { kSimulation, kCalibration };

const char* JobKindName(JobKind kind);  // "SIMULATION", "CALIBRATION"; the spelling stored
std::optional<JobKind> ParseJobKind(std::string_view name);

struct JobProgress {
  std::uint64_t step = 0;
  double time_s = 0.0;
  double fraction_done = 0.0;
  double eta_s = 0.0;
  // A scene with stages: the current stage, from 1 (0: the scene has none), of stage_count.
  std::uint32_t stage_index = 0;
  std::uint32_t stage_count = 0;
  std::string stage_name;
  // The newest sample of the run's time series by column name (boundary rates, pressure range,
  // mass-balance error): live progress only, never stored.
  std::vector<std::pair<std::string, double>> latest;

  static JobProgress At(std::uint64_t step, double time_s, double fraction_done, double eta_s) {
    JobProgress p;
    p.step = step;
    p.time_s = time_s;
    p.fraction_done = fraction_done;
    p.eta_s = eta_s;
    return p;
  }
};

// Where the remote worker that claimed a job last runs, as it said in its claim: the batch
// system's job that started it (a Slurm job id) and the node. None for seepd's own workers.
struct WorkerPlacement {
  std::string batch_job_id;
  std::string node;
};

struct JobRecord {
  std::string id;
  std::string name;
  std::optional<std::string> request_id;
  JobState state = JobState::kQueued;
  JobKind kind = JobKind::kSimulation;
  // Queued jobs are claimed highest priority first, oldest first within one priority.
  std::int32_t priority = 0;
  std::string scene;  // serialized seep.v1.Scene, or seep.v1.Calibration for a calibration job
  std::string build_id;
  std::int64_t created_at_ms = 0;
  std::optional<std::int64_t> started_at_ms;
  std::optional<std::int64_t> finished_at_ms;
  JobProgress progress;
  std::string error_code;
  std::string error_message;
  // Sorted by name; filled for finished jobs.
  std::vector<std::pair<std::string, double>> metrics;
  double wall_time_s = 0.0;
  // A SUCCEEDED run's samples over time (row-major, series_columns[0] = "time_s") and the
  // SHA-256 (hex) of its final state: equal hashes mean bit-identical final states.
  std::vector<std::string> series_columns;
  std::vector<double> series_values;
  std::string state_sha256;
  // 1 for the first run; Resume adds one.
  std::uint32_t attempt = 1;
  // Set by Cancel on a RUNNING job; the worker that holds the lease stops and records CANCELLED.
  bool cancel_requested = false;
  // The lease of the worker running the job. lease_epoch grows on every claim, so a write
  // conditioned on it fails for any worker that is not the latest claimant (a fencing token).
  std::optional<std::string> lease_owner;
  std::int64_t lease_epoch = 0;
  std::optional<std::int64_t> lease_expires_at_ms;
  // key=value pairs given at submit, sorted by key (keys unique); validated by the service.
  std::vector<std::pair<std::string, std::string>> labels;
  // A fork: the job it continues and the step of that job's checkpoint it started from. Kept
  // when the parent is deleted (the fork has its own copy of the checkpoint).
  std::optional<std::string> parent_job_id;
  std::uint64_t parent_step = 0;
  // The jobs forked from this one, oldest first (filled by Get and GetWithoutScene).
  std::vector<std::string> child_job_ids;
  // Set when the latest claim was a remote worker's started by a batch system.
  std::optional<WorkerPlacement> placement;
};

// A job of a batch system (a Slurm job) that seepd's executor submitted to start seep-worker.
struct BatchJobRecord {
  std::string id;     // the batch system's job id
  int workers = 1;    // seep jobs its worker runs at a time
  int max_jobs = 0;   // seep jobs its worker claims in all before it ends (0: until idle)
  std::string state;  // as the batch system last reported it (PENDING, RUNNING, ...)
  std::string node;   // where it runs ("" until known)
  std::int64_t submitted_at_ms = 0;
  std::optional<std::int64_t> ended_at_ms;  // set once it is gone from the batch system
};

// What the executor decides on (JobStore::BatchDemandNow).
struct BatchDemand {
  std::int64_t queued_simulations = 0;  // QUEUED simulation jobs: they wait for a worker
  struct Use {
    int running = 0;           // seep jobs RUNNING under a claim of its worker
    int claimed = 0;           // seep jobs whose latest claim was its worker's, in any state
    int cancel_requested = 0;  // of the running ones, those a user cancelled
  };
  std::map<std::string, Use> by_batch_job;  // live batch jobs only; absent: nothing claimed
};

// What a run that succeeded leaves besides its final state (JobStore::RecordSuccess): its time
// series, the final state's hash, where it ended (the progress at its last step), its metrics.
struct RunSuccess {
  std::vector<std::string> series_columns;
  std::vector<double> series_values;
  std::string state_sha256;
  JobProgress final_progress;
  std::vector<std::pair<std::string, double>> metrics;
  double wall_time_s = 0.0;
};

// One checkpoint of a job, as the store records it.
struct CheckpointRecord {
  std::string job_id;  // filled where records of several jobs travel together (retention)
  std::uint64_t step = 0;
  double time_s = 0.0;
  std::string path;     // its file; empty when the store holds its bytes (content)
  std::string content;  // the checkpoint's bytes, when the store holds them
  std::int64_t bytes = 0;
  std::uint32_t attempt = 1;
  std::int64_t created_at_ms = 0;
};

// One line of a job's history: kind is a short word (CLAIMED, RESUMED, CHECKPOINT_SKIPPED, ...).
struct JobEventRecord {
  std::int64_t id = 0;  // grows with every event of any job: a cursor for paging
  std::int64_t at_ms = 0;
  std::string kind;
  std::string message;
};

}  // namespace seep::service
