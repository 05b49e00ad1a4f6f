// Recovery from checkpoint files (seepd --recover-from-checkpoints): after the database was lost,
// the jobs whose checkpoint files remain are rebuilt into an empty store. A checkpoint file
// (format 2 on) carries its job's id, its scene and its step and state, so each job folder of
// <data-dir>/checkpoints (and of <data-dir>/lost-checkpoints, where an accepted loss moved them)
// becomes a QUEUED job under its own id with its checkpoint records: it continues from its newest
// checkpoint that verifies, and a job that had finished, whose newest checkpoint is its final
// state, ends again at once with the same state hash. What a file cannot say is lost: labels,
// priority, request id, fork parentage, results of finished jobs (recomputed by the rerun) and
// calibration records. A folder nothing can be rebuilt from (no file that verifies, or only
// files of format 1, which carry the scene's hash alone) moves whole to lost-checkpoints, named
// in the log: nothing is deleted.
#pragma once

#include <spdlog/logger.h>

#include <filesystem>
#include <string>
#include <vector>

#include "seep/core/status.h"
#include "store/job_store.h"

namespace seep::service {

struct RecoveryReport {
  int jobs = 0;                            // rebuilt
  int checkpoint_files = 0;                // recorded for them
  std::vector<std::string> unrecoverable;  // job folders moved to lost-checkpoints, with why
};

// Must run at start, on a store with no job (FAILED_PRECONDITION otherwise: recovery never
// mixes with live records), before the checkpoint sweep.
core::Result<RecoveryReport> RecoverFromCheckpoints(JobStore& store,
                                                    const std::filesystem::path& checkpoints_dir,
                                                    spdlog::logger& log);

}  // namespace seep::service
