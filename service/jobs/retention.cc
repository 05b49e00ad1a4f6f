#include "jobs/retention.h"

#include "jobs/checkpoint_removal.h"
#include "jobs/wall_clock.h"

namespace seep::service {

Retention::Retention(JobStore& store, RetentionPolicy policy, std::chrono::milliseconds interval,
                     std::shared_ptr<spdlog::logger> logger)
    : store_(store), policy_(policy), interval_(interval), logger_(std::move(logger)) {}

Retention::~Retention() { Stop(); }

void Retention::RunOnce() {
  if (!enabled()) return;
  auto outcome = store_.ApplyRetention(policy_, NowMs());
  if (!outcome.ok()) {
    logger_->error("retention not applied: {}", outcome.status().message());
    return;
  }
  // The records are gone: the files follow (a crash in between leaves them to the next sweep).
  const RemovedFiles removed = RemoveCheckpointFiles(outcome->removed_checkpoints, *logger_);
  if (outcome->deleted_jobs.empty() && outcome->checkpoints_over_budget == 0) return;
  logger_->info(
      "retention: deleted {} finished job(s) older than {:.6g} day(s) and {} checkpoint(s) of "
      "finished jobs over the budget of {} bytes; {} file(s), {} bytes removed; checkpoints now "
      "hold {} bytes",
      outcome->deleted_jobs.size(), static_cast<double>(policy_.max_age_ms) / 86'400'000.0,
      outcome->checkpoints_over_budget, policy_.max_checkpoint_bytes, removed.files, removed.bytes,
      outcome->checkpoint_bytes_left);
  for (const std::string& id : outcome->deleted_jobs) {
    logger_->info("retention: job {} deleted (finished more than {:.6g} day(s) ago)", id,
                  static_cast<double>(policy_.max_age_ms) / 86'400'000.0);
  }
}

void Retention::Start() {
  if (!enabled() || interval_.count() <= 0) return;
  thread_ = std::jthread([this](const std::stop_token& stop) {
    while (!stop.stop_requested()) {
      {
        std::unique_lock lock(mutex_);
        wake_.wait_for(lock, stop, interval_, [] { return false; });
      }
      if (!stop.stop_requested()) RunOnce();
    }
  });
}

void Retention::Stop() {
  if (!thread_.joinable()) return;
  thread_.request_stop();
  wake_.notify_all();
  thread_.join();
}

}  // namespace seep::service
