// Removing the checkpoint files of records the store has already dropped (DeleteJob, the
// retention policy): each file durably, then each job folder left empty. A file that cannot be
// removed is logged and left to the next start-up sweep (jobs/checkpoint_sweep.h), which removes
// every file no record points to.
#pragma once

#include <spdlog/logger.h>

#include <cstdint>
#include <span>

#include "store/job_record.h"

namespace seep::service {

struct RemovedFiles {
  int files = 0;
  std::uint64_t bytes = 0;  // as recorded
};

RemovedFiles RemoveCheckpointFiles(std::span<const CheckpointRecord> records, spdlog::logger& log);

}  // namespace seep::service
