// WalCheckpointer: copies the store's WAL back into the database on a thread and a connection of
// its own, so that no commit waits for it.
//
// SQLite's automatic checkpoint runs inside the commit that takes the WAL past 1,000 pages, on
// the committing connection: that commit copies the WAL's pages into the database and fsyncs it,
// milliseconds during which the store's mutex is held and every other store call waits. In a
// sweep of 12 ms jobs on two workers, a worker's claim waited 3.3 ms behind one about every
// twenty jobs: 1 % of the lanes' time, idle. Registering a WAL hook turns SQLite's automatic
// checkpoint off; this one's hook only wakes the thread, whose PASSIVE checkpoint (it waits for
// no reader or writer) copies the frames while commits go on. A writer that begins when every
// frame has been copied starts the WAL over from its beginning, as before.
//
// Should the thread fall behind (a flood of commits, a checkpoint that keeps failing), the
// committing connection checkpoints inline once the WAL reaches `inline_pages`, as SQLite itself
// does at 1,000: the WAL stays bounded whatever happens to the thread.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "seep/core/status.h"

struct sqlite3;

namespace seep::service {

class WalCheckpointer {
 public:
  // Four times SQLite's own threshold: a checkpoint copies each page once however often the WAL
  // holds it, and the pages every job rewrites (the jobs table's and its indexes' leaves, the
  // events' last page) are then copied a quarter as often. In a sweep of 12 ms jobs the thread's
  // checkpoints took 0.69-0.71 % of the physics' samples against 0.89-0.94 % at 1,000 pages (two
  // profiles each): about 0.025 ms a job. The WAL file grows to about 16 MiB (SQLite keeps its
  // size once reached; it is deleted at the last close).
  static constexpr int kPages = 4000;
  static constexpr int kInlinePages = 8000;  // a WAL of about 32 MiB

  // Hooks `store` (the store's connection to the database at `path`) and opens the thread's
  // connection. `store` must outlive this object.
  static core::Result<std::unique_ptr<WalCheckpointer>> Start(sqlite3* store,
                                                              const std::string& path,
                                                              int pages = kPages,
                                                              int inline_pages = kInlinePages);
  // Unhooks the store's connection (its last close checkpoints anyway), stops the thread and
  // closes the thread's connection.
  ~WalCheckpointer();
  WalCheckpointer(const WalCheckpointer&) = delete;
  WalCheckpointer& operator=(const WalCheckpointer&) = delete;

  // Checkpoints the thread has run, and those the committing connection ran inline.
  std::uint64_t checkpoints() const;
  std::uint64_t inline_checkpoints() const;
  // Returns once no checkpoint is asked for or running.
  void WaitIdle() const;

 private:
  WalCheckpointer(sqlite3* store, sqlite3* own, int pages, int inline_pages);
  static int Hook(void* self, sqlite3* db, const char* schema, int pages);
  void Loop(const std::stop_token& stop);

  sqlite3* const store_;
  sqlite3* const own_;  // the thread's connection
  const int pages_;
  const int inline_pages_;
  mutable std::mutex mutex_;
  mutable std::condition_variable_any changed_;
  // Guarded by mutex_.
  bool asked_ = false;
  bool running_ = false;
  std::uint64_t checkpoints_ = 0;
  std::uint64_t inline_checkpoints_ = 0;
  std::jthread thread_;  // last: it starts once the members above exist
};

}  // namespace seep::service
