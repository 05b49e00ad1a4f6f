// LowDiskWatch: looks at the data folder's free space (store/free_space.h) once an interval and
// acts on what changed. A low spell's start and end are logged once each, not at every refusal.
// While it lasts the store's WAL gives its space back (JobStore::FitWalToDisk): seepd's own files
// do not grow into the space kept free. When it ends, a start-up recovery put off for lack of
// space runs (StartupRecovery), and the workers are woken for the jobs that waited.
#pragma once

#include <spdlog/logger.h>

#include <chrono>
#include <condition_variable>
#include <functional>
#include <memory>
#include <mutex>
#include <thread>

#include "jobs/startup_recovery.h"
#include "store/job_store.h"

namespace seep::service {

class LowDiskWatch {
 public:
  LowDiskWatch(JobStore& store, StartupRecovery& recovery, std::function<void()> wake_workers,
               std::shared_ptr<spdlog::logger> logger,
               std::chrono::milliseconds interval = std::chrono::seconds(1));
  ~LowDiskWatch();
  LowDiskWatch(const LowDiskWatch&) = delete;
  LowDiskWatch& operator=(const LowDiskWatch&) = delete;

  void Start();
  void Stop();
  // One look: what the thread does at every interval.
  void LookOnce();

 private:
  JobStore& store_;
  StartupRecovery& recovery_;
  std::function<void()> wake_workers_;
  std::shared_ptr<spdlog::logger> logger_;
  std::chrono::milliseconds interval_;
  bool low_ = false;  // at the previous look; LookOnce's caller only
  std::mutex mutex_;
  std::condition_variable_any stopped_;
  std::jthread thread_;
};

}  // namespace seep::service
