// The retention policy of seepd (--retain-days, --retain-checkpoint-bytes): finished jobs older
// than the age limit are deleted with their files, and while all checkpoint files together are
// over the byte budget the oldest checkpoints of finished jobs are removed
// (JobStore::ApplyRetention says which, in what order). A queued or running job is never
// touched. It runs once at start, before the workers, and then every interval.
#pragma once

#include <spdlog/logger.h>

#include <chrono>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <thread>

#include "store/job_store.h"

namespace seep::service {

class Retention {
 public:
  Retention(JobStore& store, RetentionPolicy policy, std::chrono::milliseconds interval,
            std::shared_ptr<spdlog::logger> logger);
  ~Retention();
  Retention(const Retention&) = delete;
  Retention& operator=(const Retention&) = delete;

  bool enabled() const { return policy_.max_age_ms > 0 || policy_.max_checkpoint_bytes > 0; }
  // Applies the policy now: the store first, then the files of what it dropped. Logs one line
  // when anything was removed.
  void RunOnce();
  // RunOnce every interval on a thread of its own, until Stop (or destruction).
  void Start();
  void Stop();

 private:
  JobStore& store_;
  RetentionPolicy policy_;
  std::chrono::milliseconds interval_;
  std::shared_ptr<spdlog::logger> logger_;
  std::mutex mutex_;
  std::condition_variable_any wake_;
  std::jthread thread_;
};

}  // namespace seep::service
