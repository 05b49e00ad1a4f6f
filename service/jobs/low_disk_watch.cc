#include "jobs/low_disk_watch.h"

namespace seep::service {

LowDiskWatch::LowDiskWatch(JobStore& store, StartupRecovery& recovery,
                           std::function<void()> wake_workers,
                           std::shared_ptr<spdlog::logger> logger,
                           std::chrono::milliseconds interval)
    : store_(store),
      recovery_(recovery),
      wake_workers_(std::move(wake_workers)),
      logger_(std::move(logger)),
      interval_(interval) {}

LowDiskWatch::~LowDiskWatch() { Stop(); }

void LowDiskWatch::Start() {
  if (const auto& file = store_.free_space().policy().test_free_bytes_file; !file.empty()) {
    logger_->warn("test hook --test-free-disk-bytes-file {} is on: not for production",
                  file.string());
  }
  thread_ = std::jthread([this](const std::stop_token& stop) {
    while (!stop.stop_requested()) {
      LookOnce();
      std::unique_lock lock(mutex_);
      stopped_.wait_for(lock, stop, interval_, [] { return false; });
    }
  });
}

void LowDiskWatch::Stop() {
  if (!thread_.joinable()) return;
  thread_.request_stop();
  thread_.join();
}

void LowDiskWatch::LookOnce() {
  const FreeSpaceReading reading = store_.free_space().Measure();
  const bool low = reading.low();
  if (low && !low_) {
    logger_->warn(
        "disk full: {}: submits are refused (RESOURCE_EXHAUSTED), no job starts, a running job "
        "fails at its next checkpoint and the store's WAL gives its space back; reads go on",
        reading.Describe());
  } else if (!low && low_) {
    logger_->info("disk space is back ({} free on the data folder's file system): jobs start again",
                  HumanBytes(reading.free_bytes));
  }
  const bool was_low = low_;
  low_ = low;
  if (low || was_low) {
    // Failing leaves the WAL as it is until the next look.
    if (auto fitted = store_.FitWalToDisk(low); !fitted.ok()) {
      logger_->debug("WAL not fitted to the disk: {}", fitted.ToString());
    }
  }
  if (low) return;
  const bool recovering = recovery_.pending();
  if (recovering) {
    if (auto recovered = recovery_.Run(); !recovered.ok()) {
      logger_->error("recovery of interrupted jobs failed: {}", recovered.ToString());
    }
  }
  if ((was_low || recovering) && wake_workers_) wake_workers_();
}

}  // namespace seep::service
