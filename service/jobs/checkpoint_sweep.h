// The start-up sweep of the checkpoint folder: what a crash can leave behind is removed before
// any worker writes. A crash between a checkpoint file and its record leaves a file no record
// points to (an orphan: no restart ever reads it); a crash inside a write leaves a temporary file
// (store/durable_files.h); a deleted job may leave its folder. What stays is made private (files
// 0600, folders 0700). Only <data-dir>/checkpoints is swept, never the database or the log
// beside it.
#pragma once

#include <spdlog/logger.h>

#include <cstdint>
#include <filesystem>

#include "seep/core/status.h"
#include "store/job_store.h"

namespace seep::service {

struct SweepCounts {
  int orphan_files = 0;   // no checkpoint record points to them
  int temp_files = 0;     // leftovers of interrupted writes
  int empty_folders = 0;  // job folders left with no file
  int tightened = 0;      // kept files and folders made 0600 / 0700 (older seepd wrote 0644/0755)
  std::uint64_t bytes = 0;
  int failures = 0;  // could not be removed (logged each)
};

// Must run while nothing writes checkpoints (at start, before the workers). A missing folder is
// an empty one. Logs one line with the counts when anything was removed.
core::Result<SweepCounts> SweepCheckpointFolder(JobStore& store,
                                                const std::filesystem::path& checkpoints_dir,
                                                spdlog::logger& log);

}  // namespace seep::service
