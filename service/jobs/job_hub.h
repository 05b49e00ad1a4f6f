// JobHub: the in-memory side of job progress. Workers publish live progress here many times a
// second; the store only gets a throttled copy. Watchers wait on the hub's version counter, so
// a WatchJob stream wakes on every change without polling the database.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <map>
#include <mutex>
#include <optional>
#include <string>

#include "store/job_record.h"

namespace seep::service {

class JobHub {
 public:
  // Live progress of a running job; also counts as a change.
  void Publish(const std::string& id, const JobProgress& progress);
  // The job left RUNNING (or changed state): drop its live progress and wake watchers.
  void Finished(const std::string& id);
  // Any other change that watchers should see (e.g. a new job).
  void NotifyChanged();
  // Ends every wait: the server is shutting down.
  void Close();

  std::optional<JobProgress> Live(const std::string& id) const;
  std::uint64_t version() const;
  bool closed() const;
  // Waits until the version differs from seen, the hub closes or the timeout passes.
  void WaitForChange(std::uint64_t seen, std::chrono::milliseconds timeout) const;

 private:
  mutable std::mutex mutex_;
  mutable std::condition_variable changed_;
  std::uint64_t version_ = 0;
  bool closed_ = false;
  std::map<std::string, JobProgress> live_;
};

}  // namespace seep::service
