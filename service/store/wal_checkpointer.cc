#include "wal_checkpointer.h"

#include <fmt/format.h>
#include <sqlite3.h>

#include "seep/core/log.h"

namespace seep::service {

core::Result<std::unique_ptr<WalCheckpointer>> WalCheckpointer::Start(sqlite3* store,
                                                                      const std::string& path,
                                                                      int pages, int inline_pages) {
  sqlite3* own = nullptr;
  // NOMUTEX: only the thread uses this connection.
  const int rc =
      sqlite3_open_v2(path.c_str(), &own, SQLITE_OPEN_READWRITE | SQLITE_OPEN_NOMUTEX, nullptr);
  if (rc != SQLITE_OK) {
    const std::string why = own != nullptr ? sqlite3_errmsg(own) : sqlite3_errstr(rc);
    sqlite3_close_v2(own);
    return core::Unavailable(
        fmt::format("store: cannot open a second connection to {} for checkpoints: {}", path, why));
  }
  std::unique_ptr<WalCheckpointer> checkpointer(
      new WalCheckpointer(store, own, pages, inline_pages));
  sqlite3_wal_hook(store, &WalCheckpointer::Hook, checkpointer.get());
  return checkpointer;
}

WalCheckpointer::WalCheckpointer(sqlite3* store, sqlite3* own, int pages, int inline_pages)
    : store_(store),
      own_(own),
      pages_(pages),
      inline_pages_(inline_pages),
      thread_([this](const std::stop_token& stop) { Loop(stop); }) {}

WalCheckpointer::~WalCheckpointer() {
  sqlite3_wal_hook(store_, nullptr, nullptr);
  thread_.request_stop();
  thread_.join();
  sqlite3_close_v2(own_);
  core::Logger()->debug("store: {} WAL checkpoint(s) on the checkpointer's thread, {} inline",
                        checkpoints_, inline_checkpoints_);
}

std::uint64_t WalCheckpointer::checkpoints() const {
  std::lock_guard lock(mutex_);
  return checkpoints_;
}

std::uint64_t WalCheckpointer::inline_checkpoints() const {
  std::lock_guard lock(mutex_);
  return inline_checkpoints_;
}

void WalCheckpointer::WaitIdle() const {
  std::unique_lock lock(mutex_);
  changed_.wait(lock, [&] { return !asked_ && !running_; });
}

// Called by SQLite on the committing thread, after each commit, with the WAL's frame count.
int WalCheckpointer::Hook(void* self, sqlite3* db, const char* schema, int pages) {
  auto* checkpointer = static_cast<WalCheckpointer*>(self);
  if (pages >= checkpointer->inline_pages_) {
    // The same call SQLite's automatic checkpoint makes; on this connection, inside the commit.
    // Counted, as the thread's, only when it ran (a failure is left for the next commit).
    if (sqlite3_wal_checkpoint_v2(db, schema, SQLITE_CHECKPOINT_PASSIVE, nullptr, nullptr) ==
        SQLITE_OK) {
      std::lock_guard lock(checkpointer->mutex_);
      ++checkpointer->inline_checkpoints_;
    }
    return SQLITE_OK;
  }
  if (pages >= checkpointer->pages_) {
    std::lock_guard lock(checkpointer->mutex_);
    if (!checkpointer->asked_) {
      checkpointer->asked_ = true;
      checkpointer->changed_.notify_all();
    }
  }
  return SQLITE_OK;  // the commit's outcome: a checkpoint's never changes it
}

void WalCheckpointer::Loop(const std::stop_token& stop) {
  std::unique_lock lock(mutex_);
  while (changed_.wait(lock, stop, [&] { return asked_; })) {
    asked_ = false;
    running_ = true;
    lock.unlock();
    int wal_frames = 0;
    int copied = 0;
    // A connection opens the WAL on a read that finds the database in WAL mode. Opened on a new
    // store (its pages still all in the WAL, the database file empty) this one had not, and a
    // checkpoint through it then did nothing and said SQLITE_OK with -1 frames (SQLite 3.40).
    // The pragma opens it, and costs next to nothing once it is open.
    (void)sqlite3_exec(own_, "PRAGMA journal_mode", nullptr, nullptr, nullptr);
    const int rc =
        sqlite3_wal_checkpoint_v2(own_, nullptr, SQLITE_CHECKPOINT_PASSIVE, &wal_frames, &copied);
    const bool done = rc == SQLITE_OK && wal_frames >= 0;
    if (!done && rc != SQLITE_BUSY) {
      // Left for the next commit to ask again (or, past inline_pages, to do inline).
      core::Logger()->warn("store: WAL checkpoint failed: {} (sqlite code {}, WAL frames {})",
                           sqlite3_errmsg(own_), rc, wal_frames);
    }
    lock.lock();
    running_ = false;
    if (done) ++checkpoints_;
    changed_.notify_all();
  }
}

}  // namespace seep::service
