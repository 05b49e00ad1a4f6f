// seepd watched from outside, as the fuzzer's invariants need it: whether the process is alive
// (the same pid), its resident memory (/proc/<pid>/status), and what its store holds, read from
// its database file with a read-only SQLite connection (what a refusal must not have added).
#pragma once

#include <sys/types.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <set>
#include <string>

struct sqlite3;

namespace seep::fuzz {

class SeepdObserver {
 public:
  SeepdObserver(pid_t pid, std::filesystem::path data_dir);
  ~SeepdObserver();
  SeepdObserver(const SeepdObserver&) = delete;
  SeepdObserver& operator=(const SeepdObserver&) = delete;

  pid_t pid() const { return pid_; }
  // The process exists and has not ended (a child not yet reaped shows as a zombie).
  bool Alive() const;
  // VmRSS in bytes; 0 when unreadable.
  std::size_t RssBytes() const;
  // Rows of a table of the store (jobs, sweeps); -1 when the database cannot be read.
  std::int64_t CountRows(const std::string& table);
  // Jobs QUEUED or RUNNING; -1 when the database cannot be read.
  std::int64_t CountUnfinished();
  // The ids of the store's jobs.
  std::set<std::string> JobIds();
  // Folders of <data>/checkpoints named after no job of the store.
  std::set<std::string> CheckpointFoldersWithoutAJob();

 private:
  bool Open();
  std::int64_t Count(const std::string& query);

  pid_t pid_;
  std::filesystem::path data_dir_;
  sqlite3* db_ = nullptr;
};

}  // namespace seep::fuzz
