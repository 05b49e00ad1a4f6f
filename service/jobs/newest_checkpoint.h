// LoadNewestCheckpoint: the one "newest checkpoint that verifies" routine, for the resume of a
// claimed job (CheckpointKeeper::RestoreNewest) and for GetJobFields.
//
// A candidate is taken when its file reads and verifies (store/checkpoint_io), belongs to the
// job and its scene (job id and scene SHA-256 in its header), its state parses and
// core::Simulation::Restore accepts it. Every candidate passed over is reported, with the reason,
// before the next one is tried.
#pragma once

#include <functional>
#include <optional>
#include <span>

#include "seep/core/run/simulation.h"
#include "seep/core/status.h"
#include "store/checkpoint_io.h"
#include "store/job_record.h"

namespace seep::service {

struct SkippedCheckpoint {
  const CheckpointRecord& record;
  core::Status why;      // from the file read, the state parse or Simulation::Restore
  bool foreign = false;  // it verifies but belongs to another job or scene (why: DATA_LOSS)
};

struct RestoredCheckpoint {
  const CheckpointRecord& record;
  CheckpointMeta meta;  // its header: the build that wrote it, its step and time
};

struct VerifiedCheckpoint {
  const CheckpointRecord& record;
  CheckpointFile file;
};

// The file-level half: the first of `newest_first` with a step below `below_step` (none: any)
// whose file reads, verifies and belongs to the job and its scene; nullopt when none does. What
// a remote worker downloads (it parses and restores the state itself).
std::optional<VerifiedCheckpoint> NextVerifiedCheckpoint(
    const JobRecord& job, std::span<const CheckpointRecord> newest_first,
    std::optional<std::uint64_t> below_step,
    const std::function<void(const SkippedCheckpoint&)>& on_skip);

// Restores `sim` from the first of `newest_first` that is usable; nullopt when none is.
std::optional<RestoredCheckpoint> LoadNewestCheckpoint(
    const JobRecord& job, std::span<const CheckpointRecord> newest_first, core::Simulation& sim,
    const std::function<void(const SkippedCheckpoint&)>& on_skip);

}  // namespace seep::service
