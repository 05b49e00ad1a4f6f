#include "durability_window.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <fmt/std.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "seep/core/log.h"

namespace seep::service {

core::Result<std::unique_ptr<DurabilityWindow>> DurabilityWindow::Open(
    const std::filesystem::path& wal, std::chrono::milliseconds window) {
  // Read-only is enough: on Linux fdatasync needs no write access, and this descriptor never
  // writes (nor locks: SQLite's locks are on the database and -shm files, which it keeps).
  const int fd = ::open(wal.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) {
    return core::FailedPrecondition(fmt::format("store: cannot open the WAL file {} to sync it: {}",
                                                wal, std::strerror(errno)));
  }
  return std::unique_ptr<DurabilityWindow>(new DurabilityWindow(fd, wal, window));
}

DurabilityWindow::DurabilityWindow(int fd, std::filesystem::path wal,
                                   std::chrono::milliseconds window)
    : fd_(fd),
      wal_(std::move(wal)),
      window_(window),
      thread_([this](const std::stop_token& stop) { Loop(stop); }) {}

DurabilityWindow::~DurabilityWindow() {
  thread_.request_stop();
  thread_.join();
  (void)Flush();
  ::close(fd_);
}

void DurabilityWindow::Committed() {
  std::lock_guard lock(mutex_);
  ++committed_;
  if (!oldest_pending_) {
    oldest_pending_ = std::chrono::steady_clock::now();
    changed_.notify_all();
  }
}

core::Status DurabilityWindow::Flush() {
  std::unique_lock lock(mutex_);
  return SyncLocked(lock);
}

std::uint64_t DurabilityWindow::syncs() const {
  std::lock_guard lock(mutex_);
  return syncs_;
}

bool DurabilityWindow::pending() const {
  std::lock_guard lock(mutex_);
  return committed_ != synced_;
}

void DurabilityWindow::Loop(const std::stop_token& stop) {
  std::unique_lock lock(mutex_);
  while (changed_.wait(lock, stop, [&] { return oldest_pending_.has_value(); })) {
    // Sleeps out the window of the oldest commit (a Flush meanwhile may cover it first).
    const auto due = *oldest_pending_ + window_;
    changed_.wait_until(lock, stop, due, [] { return false; });
    if (stop.stop_requested()) return;  // the destructor flushes
    if (auto s = SyncLocked(lock); !s.ok()) core::Logger()->error("{}", s.ToString());
  }
}

core::Status DurabilityWindow::SyncLocked(std::unique_lock<std::mutex>& lock) {
  changed_.wait(lock, [&] { return !syncing_; });  // one sync at a time
  if (committed_ == synced_) {
    oldest_pending_.reset();
    return core::Status::Ok();
  }
  const std::uint64_t before = synced_;
  const std::uint64_t covered = committed_;
  oldest_pending_.reset();  // commits from here on wait for the next sync
  syncing_ = true;
  lock.unlock();
  const int rc = ::fdatasync(fd_);
  const int error = errno;
  lock.lock();
  syncing_ = false;
  changed_.notify_all();
  synced_ = covered;
  if (rc != 0) {
    // Not retried: after a failed fsync the kernel may have dropped the pages it could not write,
    // and a second fsync would then report success. SQLite's next sync reports it too.
    return core::DataLoss(fmt::format(
        "store: fdatasync of the WAL file {} failed ({}): the last {} windowed commits (runs' "
        "successes) may not survive a power loss",
        wal_, std::strerror(error), covered - before));
  }
  ++syncs_;
  return core::Status::Ok();
}

}  // namespace seep::service
