// DurabilityWindow: makes commits that skipped their own fsync durable within a bounded time.
//
// A run of seepd's own workers that succeeds commits its final state, series and outcome without
// an fsync (JobStore's CommitSync::kWindowed). Its thread then fdatasyncs the WAL file once the
// oldest of those commits has waited `window`, so one fsync covers every success of that window:
// a sweep of short jobs ends two hundred a second on two cores; an fsync each cost about 0.1 ms of
// CPU a job (of a 10 ms job) in I/O submissions and interrupts on a virtual disk, and on a disk
// whose flush takes milliseconds it would hold each ending that long. A durable commit in
// between makes them durable sooner (the WAL is synced in order, SQLite's own syncs included).
//
// Syncing the WAL through a descriptor of our own is sound on Linux: fdatasync writes every dirty
// page of the file (its inode), whoever wrote it. SQLite never truncates or deletes the WAL while
// the store's connection is open (no journal_size_limit, no TRUNCATE checkpoint, the
// WalCheckpointer's included; it deletes the file only when its last connection closes, after
// that connection's final checkpoint, and the checkpointer's connection closes first).
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>

#include "seep/core/status.h"

namespace seep::service {

class DurabilityWindow {
 public:
  // `wal`: the database's WAL file, which must exist (SQLite creates it when a connection in WAL
  // mode first reads the database).
  static core::Result<std::unique_ptr<DurabilityWindow>> Open(const std::filesystem::path& wal,
                                                              std::chrono::milliseconds window);
  // Syncs what is pending, then stops the thread.
  ~DurabilityWindow();
  DurabilityWindow(const DurabilityWindow&) = delete;
  DurabilityWindow& operator=(const DurabilityWindow&) = delete;

  // A windowed commit has returned: it is made durable within the window.
  void Committed();
  // Syncs now what has been committed so far (no-op when nothing is pending).
  core::Status Flush();

  // fdatasyncs done so far, and whether a windowed commit waits for one.
  std::uint64_t syncs() const;
  bool pending() const;

 private:
  DurabilityWindow(int fd, std::filesystem::path wal, std::chrono::milliseconds window);
  void Loop(const std::stop_token& stop);
  // Syncs the commits counted up to now; `lock` is held on entry and on return (released while
  // the fsync runs, so that commits go on meanwhile).
  core::Status SyncLocked(std::unique_lock<std::mutex>& lock);

  const int fd_;
  const std::filesystem::path wal_;
  const std::chrono::milliseconds window_;
  mutable std::mutex mutex_;
  std::condition_variable_any changed_;
  // Guarded by mutex_: windowed commits counted, the count the last sync covered, when the
  // oldest commit not yet covered returned, and whether a sync is running.
  std::uint64_t committed_ = 0;
  std::uint64_t synced_ = 0;
  std::optional<std::chrono::steady_clock::time_point> oldest_pending_;
  bool syncing_ = false;
  std::uint64_t syncs_ = 0;
  std::jthread thread_;  // last: it starts once the members above exist
};

}  // namespace seep::service
