// The start-up sweep of the checkpoint folder: what a crash can leave behind is removed before
// any worker writes. A crash between a checkpoint file and its record leaves a file no record
// points to (an orphan: no restart ever reads it); a crash inside a write leaves a temporary file
// (store/durable_files.h); a deleted job may leave its folder. What stays is made private (files
// 0600, folders 0700). Only <data-dir>/checkpoints is swept, never the database or the log
// beside it.
//
// The store is the only account of which file is whose. A store with no job at all beside
// checkpoint files has lost its database (deleted, emptied, or another one put in its place):
// every file would look like an orphan, a running job's included, and they are the jobs' only
// state. The sweep then removes nothing and refuses (FAILED_PRECONDITION naming the files), unless
// the operator accepts the loss (--accept-lost-database), which moves them to
// <data-dir>/lost-checkpoints, each job's folder whole. Each orphan removed is logged by name.
#pragma once

#include <spdlog/logger.h>

#include <cstdint>
#include <filesystem>

#include "seep/core/status.h"
#include "store/job_store.h"

namespace seep::service {

struct SweepCounts {
  int orphan_files = 0;   // no checkpoint record points to them
  int lost_files = 0;     // moved to lost-checkpoints (a lost database, accepted)
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
                                                spdlog::logger& log,
                                                bool accept_lost_database = false);

// Where an accepted lost database's checkpoint files go: beside the checkpoint folder.
inline std::filesystem::path LostCheckpointsDir(const std::filesystem::path& checkpoints_dir) {
  return checkpoints_dir.parent_path() / "lost-checkpoints";
}

}  // namespace seep::service
