// JobRunner: a fixed pool of worker threads that claim queued jobs from the store and run them.
//
// A job's failure is data (state FAILED with a code and message), never an exception leaving a
// thread. On shutdown, running jobs are stopped at a step boundary and left RUNNING in the
// store, so the next seepd start queues them again: nothing a user submitted is lost.
#pragma once

#include <spdlog/logger.h>

#include <condition_variable>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "jobs/job_hub.h"
#include "store/job_store.h"

namespace seep::service {

struct JobRunnerOptions {
  int workers = 1;
  std::string build_id;
  // Least wall time between two progress writes to the store for one job.
  std::chrono::milliseconds store_progress_interval{1000};
};

class JobRunner {
 public:
  JobRunner(JobStore& store, JobHub& hub, JobRunnerOptions options,
            std::shared_ptr<spdlog::logger> logger);
  ~JobRunner();
  JobRunner(const JobRunner&) = delete;
  JobRunner& operator=(const JobRunner&) = delete;

  void Start();
  // Stops claiming, interrupts running jobs at their next step and joins the workers.
  void Stop();
  // A job was queued: wake an idle worker.
  void Wake();

 private:
  void WorkerLoop(const std::stop_token& stop);
  void RunJob(const JobRecord& job, const std::stop_token& stop);

  JobStore& store_;
  JobHub& hub_;
  JobRunnerOptions options_;
  std::shared_ptr<spdlog::logger> logger_;
  std::mutex mutex_;
  std::condition_variable_any wake_;
  std::uint64_t wake_count_ = 0;
  std::vector<std::jthread> workers_;
};

}  // namespace seep::service
