// JobStore: the durable record of every job and its result, in SQLite.
//
// One connection guarded by a mutex (one writer); WAL, synchronous=FULL, busy_timeout, STRICT
// tables, migrations by PRAGMA user_version. SQL never leaves this directory.
#pragma once

#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "job_record.h"
#include "seep/core/status.h"

namespace seep::service {

class Db;
using core::Result;
using core::Status;

struct InsertOutcome {
  JobRecord job;
  bool created = false;  // false: request_id matched an existing job, which is returned
};

struct JobPage {
  std::vector<JobRecord> jobs;  // newest first, scenes left empty
  std::optional<std::int64_t> next_cursor;
};

class JobStore {
 public:
  static constexpr int kSchemaVersion = 1;
  ~JobStore();

  static Result<std::unique_ptr<JobStore>> Open(const std::string& path);

  // Stores a new QUEUED job; with a request_id already present, returns that job instead.
  Result<InsertOutcome> Insert(const JobRecord& job);
  Result<JobRecord> Get(const std::string& id);
  // Newest first; cursor is the next_cursor of the previous page.
  Result<JobPage> List(std::uint32_t limit, std::optional<std::int64_t> cursor);
  // Moves the oldest QUEUED job to RUNNING and returns it.
  Result<std::optional<JobRecord>> ClaimNextQueued(std::int64_t now_ms);
  Status UpdateProgress(const std::string& id, const JobProgress& progress);
  // Moves a RUNNING job to a terminal state with its metrics, in one transaction.
  Status Finish(const std::string& id, JobState state, const std::string& error_code,
                const std::string& error_message,
                const std::vector<std::pair<std::string, double>>& metrics, double wall_time_s,
                std::int64_t now_ms);
  // At start-up: jobs left RUNNING by a previous process go back to QUEUED. Returns how many.
  Result<int> RequeueRunning();

 private:
  explicit JobStore(std::unique_ptr<Db> db);
  Status Migrate();
  Result<JobRecord> GetLocked(const std::string& id, bool with_scene);
  Result<std::optional<std::string>> FindByRequestIdLocked(const std::string& request_id);

  std::mutex mutex_;
  std::unique_ptr<Db> db_;
};

}  // namespace seep::service
