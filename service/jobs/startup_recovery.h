// StartupRecovery: what seepd does, before its workers run, to the jobs a previous run left
// RUNNING (JobStore::RequeueRunning): queued again, or FAILED after too many interruptions
// without progress. On a disk below --min-free-disk-mb, or one whose file system refuses the
// writes, it is put off rather than fatal: seepd then starts read-only (it serves every read,
// refuses submits with RESOURCE_EXHAUSTED and starts no job), and LowDiskWatch runs it once space
// is back. A job it waits for stays RUNNING in the meantime, its held_reason saying why.
#pragma once

#include <spdlog/logger.h>

#include <memory>
#include <mutex>
#include <string>

#include "seep/core/status.h"
#include "store/job_store.h"

namespace seep::service {

class StartupRecovery {
 public:
  // `lease_owner`: this seepd's (any other lease belongs to a previous run).
  StartupRecovery(JobStore& store, std::string lease_owner, int max_interruptions,
                  std::shared_ptr<spdlog::logger> logger);

  // Recovers now, or puts it off for lack of space (OK, pending() true, logged once); any other
  // store error is returned. Once recovered, it does nothing more.
  core::Status Run();
  bool pending() const;

 private:
  JobStore& store_;
  const std::string lease_owner_;
  const int max_interruptions_;
  std::shared_ptr<spdlog::logger> logger_;
  mutable std::mutex mutex_;
  bool done_ = false;     // guarded by mutex_
  bool put_off_ = false;  // guarded by mutex_: said in the log once
};

}  // namespace seep::service
