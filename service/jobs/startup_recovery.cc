#include "jobs/startup_recovery.h"

#include <vector>

namespace seep::service {

StartupRecovery::StartupRecovery(JobStore& store, std::string lease_owner, int max_interruptions,
                                 std::shared_ptr<spdlog::logger> logger)
    : store_(store),
      lease_owner_(std::move(lease_owner)),
      max_interruptions_(max_interruptions),
      logger_(std::move(logger)) {}

bool StartupRecovery::pending() const {
  std::lock_guard lock(mutex_);
  return !done_;
}

core::Status StartupRecovery::Run() {
  std::lock_guard lock(mutex_);
  if (done_) return core::Status::Ok();
  // Checked first: requeued on a low disk, the jobs could start nowhere, and a store write that
  // the file system refuses half-way helps nobody.
  core::Status refused =
      store_.free_space().CheckRoom("the recovery of interrupted jobs waits for space");
  std::vector<CrashLoopFailure> crash_loops;
  if (refused.ok()) {
    auto requeued = store_.RequeueRunning(lease_owner_, max_interruptions_, &crash_loops);
    if (requeued.ok()) {
      done_ = true;
      if (*requeued > 0) {
        logger_->info("recovered {} interrupted job(s); queued to run again", *requeued);
      }
      for (const auto& failure : crash_loops) {
        logger_->warn("job {} failed: {}", failure.id, failure.message);
      }
      return core::Status::Ok();
    }
    if (requeued.status().code() != core::StatusCode::kResourceExhausted) {
      return requeued.status();
    }
    refused = requeued.status();
  }
  if (!put_off_) {
    put_off_ = true;
    logger_->warn(
        "{}; seepd serves read-only: reads are answered, submits are refused "
        "(RESOURCE_EXHAUSTED) and no job starts until space is freed",
        refused.message());
  }
  return core::Status::Ok();
}

}  // namespace seep::service
