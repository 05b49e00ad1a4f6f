// RAII around the SQLite C API: a connection (Db), a prepared statement (Stmt) and an immediate
// write transaction (WriteTx). Errors come back as Status; destructors never throw.
//
// SQLITE_FULL (the file system refused to grow the database or its WAL) is RESOURCE_EXHAUSTED
// with the free space measured; BUSY and LOCKED are UNAVAILABLE, a corrupt file DATA_LOSS.
//
// An error's Status never carries SQL text or SQLite's own message (which names tables and
// columns): those go to the log, and the Status says which store operation failed (the
// StoreOperation running on the thread) with SQLite's generic text for the code. Store errors
// reach clients (RPC errors, a job's error message), the schema is not theirs to see.
#pragma once

#include <sqlite3.h>

#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_map>

#include "seep/core/status.h"

namespace seep::service {

class FreeSpaceGuard;
using core::Result;
using core::Status;

// Names the store operation running on this thread ("insert job", "list jobs") for the errors
// raised while it lasts; nested ones restore the outer name.
class StoreOperation {
 public:
  explicit StoreOperation(const char* name);
  ~StoreOperation();
  StoreOperation(const StoreOperation&) = delete;
  StoreOperation& operator=(const StoreOperation&) = delete;
  static const char* Current();  // "database access" outside any

 private:
  const char* previous_;
};

class Stmt {
 public:
  // Binds are 1-based, as in SQLite.
  Stmt& Bind(int index, std::int64_t value);
  Stmt& Bind(int index, double value);
  Stmt& Bind(int index, std::string_view text);
  Stmt& BindBlob(int index, std::string_view bytes);
  Stmt& BindNull(int index);
  Stmt& Bind(int index, const std::optional<std::string>& text);
  Stmt& Bind(int index, const std::optional<std::int64_t>& value);  // NULL when absent

  // Makes the statement ready to run again with new bindings.
  void Reset();
  // Advances to the next row: true when a row is available, false when done.
  Result<bool> Step();
  // Runs a statement that returns no rows to completion.
  Status Run();

  std::int64_t ColumnInt(int col) const;
  double ColumnDouble(int col) const;
  std::string ColumnText(int col) const;
  std::string ColumnBlob(int col) const;
  bool ColumnIsNull(int col) const;

 private:
  friend class Db;
  // A statement of the Db's cache goes back to it (reset, its bindings cleared, free again);
  // any other is finalized.
  struct Release {
    std::atomic<bool>* in_use = nullptr;  // the cache entry's flag; null: not cached
    void operator()(sqlite3_stmt* s) const noexcept;
  };
  Stmt(sqlite3* db, sqlite3_stmt* stmt, const FreeSpaceGuard* free_space,
       std::atomic<bool>* in_use = nullptr)
      : db_(db), stmt_(stmt, Release{in_use}), free_space_(free_space) {}

  sqlite3* db_;
  std::unique_ptr<sqlite3_stmt, Release> stmt_;
  const FreeSpaceGuard* free_space_;  // the Db's, for the figures of SQLITE_FULL
  int bind_error_ = SQLITE_OK;
};

class Db {
 public:
  static Result<Db> Open(const std::string& path);

  // A statement for `sql`, from the connection's cache when it has one free: the service runs
  // the same few dozen statements again and again (a worker's heartbeat, progress, a claim), and
  // parsing one each time was a third of seepd's CPU under a hundred remote workers. A statement
  // in use (the same SQL asked for while its first is alive) or past the cache's size is
  // prepared anew and finalized after use.
  Result<Stmt> Prepare(std::string_view sql);
  // Runs one or more statements without parameters.
  Status Exec(const std::string& sql);
  // Runs one statement without parameters, through the cache (BEGIN, COMMIT, a pragma).
  Status Run(std::string_view sql);
  std::int64_t Changes() const { return sqlite3_changes64(db_.get()); }
  // The connection itself, for what this class does not wrap (a WAL hook).
  sqlite3* handle() const { return db_.get(); }
  // SQLITE_FULL errors (RESOURCE_EXHAUSTED) name the free space this guard measures; it must
  // outlive the connection.
  void set_free_space(const FreeSpaceGuard* guard) { free_space_ = guard; }

 private:
  struct Closer {
    void operator()(sqlite3* db) const noexcept { sqlite3_close_v2(db); }
  };
  explicit Db(sqlite3* db) : db_(db) {}

  struct Cached {
    sqlite3_stmt* stmt = nullptr;
    std::atomic<bool> in_use{false};
  };
  // Finalizes its statements before the connection closes (it is declared after db_).
  struct Cache {
    std::unordered_map<std::string, std::unique_ptr<Cached>> by_sql;
    Cache() = default;
    Cache(Cache&& other) noexcept : by_sql(std::move(other.by_sql)) { other.by_sql.clear(); }
    ~Cache();
  };
  static constexpr std::size_t kCachedStatements = 256;

  std::unique_ptr<sqlite3, Closer> db_;
  const FreeSpaceGuard* free_space_ = nullptr;
  Cache cache_;
};

// BEGIN IMMEDIATE … COMMIT; rolls back in the destructor unless Commit() succeeded.
class WriteTx {
 public:
  static Result<WriteTx> Begin(Db& db);
  WriteTx(WriteTx&& other) noexcept : db_(other.db_) { other.db_ = nullptr; }
  WriteTx& operator=(WriteTx&&) = delete;
  WriteTx(const WriteTx&) = delete;
  ~WriteTx();
  Status Commit();

 private:
  explicit WriteTx(Db* db) : db_(db) {}
  Db* db_;
};

// While it lives, commits on the connection skip their fsync (PRAGMA synchronous=NORMAL; FULL,
// the connection's setting, comes back in its destructor), for writes whose loss at a power
// failure is harmless: a lease renewal, live progress, a worker's history line, a result series
// that its job's outcome follows (seepd's next start queues every RUNNING job again and resumes it
// from its checkpoint either way). A crash of seepd alone loses nothing (the WAL is written before
// the commit returns), and order is kept: the WAL is appended in order, recovery stops at the
// first frame missing, and the next durable commit's fsync makes every frame before it durable,
// so such a write is lost only together with every later one that was not yet durable either.
// Not for outcomes, nor for claims a worker outside this process holds (a lease epoch that could
// be handed out twice) or periodic checkpoint records (a long run could lose every one of them);
// a final checkpoint's record, which its job's outcome follows, and a claim of seepd's own
// workers (they die with it, and the job is queued again) may (JobStore's CommitSync).
// `relaxed` false: changes nothing (for a write relaxed only in some of its uses).
class RelaxedCommit {
 public:
  explicit RelaxedCommit(Db& db, bool relaxed = true);
  ~RelaxedCommit();
  RelaxedCommit(const RelaxedCommit&) = delete;
  RelaxedCommit& operator=(const RelaxedCommit&) = delete;

 private:
  Db& db_;
  bool relaxed_;
};

}  // namespace seep::service
