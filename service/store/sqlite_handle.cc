#include "sqlite_handle.h"

#include <fmt/format.h>

#include <mutex>

#include "free_space.h"
#include "seep/core/log.h"

namespace seep::service {
namespace {

thread_local const char* t_operation = nullptr;

// The full story (SQLite's message, the statement) goes to the log; the Status names the
// operation and the kind of failure only.
Status SqliteError(sqlite3* db, int rc, std::string_view what, std::string_view sql = {},
                   const FreeSpaceGuard* free_space = nullptr) {
  const char* detail = db != nullptr ? sqlite3_errmsg(db) : sqlite3_errstr(rc);
  const char* operation = StoreOperation::Current();
  core::Logger()->error("store: {} failed in {}: {} (sqlite code {}){}{}", operation, what, detail,
                        rc, sql.empty() ? "" : "; statement: ", sql);
  const int primary = rc & 0xff;
  if (primary == SQLITE_FULL) {
    return core::ResourceExhausted(fmt::format(
        "store: {} failed: disk full: {} (sqlite code {}; {}; details in seepd's log)", operation,
        sqlite3_errstr(rc), rc,
        free_space != nullptr ? free_space->Measure().Figures() : "free space not measured"));
  }
  const auto code = (rc == SQLITE_BUSY || rc == SQLITE_LOCKED)      ? core::StatusCode::kUnavailable
                    : (rc == SQLITE_CORRUPT || rc == SQLITE_NOTADB) ? core::StatusCode::kDataLoss
                                                                    : core::StatusCode::kInternal;
  return {code, fmt::format("store: {} failed: {} (sqlite code {}; details in seepd's log)",
                            operation, sqlite3_errstr(rc), rc)};
}

}  // namespace

StoreOperation::StoreOperation(const char* name) : previous_(t_operation) { t_operation = name; }
StoreOperation::~StoreOperation() { t_operation = previous_; }
const char* StoreOperation::Current() {
  return t_operation != nullptr ? t_operation : "database access";
}

Stmt& Stmt::Bind(int index, std::int64_t value) {
  if (bind_error_ == SQLITE_OK) bind_error_ = sqlite3_bind_int64(stmt_.get(), index, value);
  return *this;
}
Stmt& Stmt::Bind(int index, double value) {
  if (bind_error_ == SQLITE_OK) bind_error_ = sqlite3_bind_double(stmt_.get(), index, value);
  return *this;
}
Stmt& Stmt::Bind(int index, std::string_view text) {
  if (bind_error_ == SQLITE_OK) {
    bind_error_ = sqlite3_bind_text64(stmt_.get(), index, text.data(), text.size(),
                                      SQLITE_TRANSIENT, SQLITE_UTF8);
  }
  return *this;
}
Stmt& Stmt::BindBlob(int index, std::string_view bytes) {
  if (bind_error_ == SQLITE_OK) {
    bind_error_ =
        sqlite3_bind_blob64(stmt_.get(), index, bytes.data(), bytes.size(), SQLITE_TRANSIENT);
  }
  return *this;
}
Stmt& Stmt::BindNull(int index) {
  if (bind_error_ == SQLITE_OK) bind_error_ = sqlite3_bind_null(stmt_.get(), index);
  return *this;
}
Stmt& Stmt::Bind(int index, const std::optional<std::string>& text) {
  return text ? Bind(index, std::string_view(*text)) : BindNull(index);
}

Stmt& Stmt::Bind(int index, const std::optional<std::int64_t>& value) {
  return value ? Bind(index, *value) : BindNull(index);
}

void Stmt::Reset() {
  sqlite3_reset(stmt_.get());
  sqlite3_clear_bindings(stmt_.get());
  bind_error_ = SQLITE_OK;
}

Result<bool> Stmt::Step() {
  if (bind_error_ != SQLITE_OK) {
    return SqliteError(db_, bind_error_, "bind", sqlite3_sql(stmt_.get()), free_space_);
  }
  const int rc = sqlite3_step(stmt_.get());
  if (rc == SQLITE_ROW) return true;
  if (rc == SQLITE_DONE) return false;
  return SqliteError(db_, rc, "step", sqlite3_sql(stmt_.get()), free_space_);
}

Status Stmt::Run() {
  for (;;) {
    SEEP_ASSIGN_OR_RETURN(const bool row, Step());
    if (!row) return Status::Ok();
  }
}

std::int64_t Stmt::ColumnInt(int col) const { return sqlite3_column_int64(stmt_.get(), col); }
double Stmt::ColumnDouble(int col) const { return sqlite3_column_double(stmt_.get(), col); }
std::string Stmt::ColumnText(int col) const {
  const auto* text = sqlite3_column_text(stmt_.get(), col);
  if (text == nullptr) return {};
  return {reinterpret_cast<const char*>(text),
          static_cast<std::size_t>(sqlite3_column_bytes(stmt_.get(), col))};
}
std::string Stmt::ColumnBlob(int col) const {
  const void* blob = sqlite3_column_blob(stmt_.get(), col);
  if (blob == nullptr) return {};
  return {static_cast<const char*>(blob),
          static_cast<std::size_t>(sqlite3_column_bytes(stmt_.get(), col))};
}
bool Stmt::ColumnIsNull(int col) const {
  return sqlite3_column_type(stmt_.get(), col) == SQLITE_NULL;
}

Result<Db> Db::Open(const std::string& path) {
  // Before SQLite initializes (its first open): no memory statistics. Kept, they take a global
  // mutex at every allocation SQLite makes, for figures nothing here reads.
  static std::once_flag configured;
  std::call_once(configured, [] { (void)sqlite3_config(SQLITE_CONFIG_MEMSTATUS, 0); });
  sqlite3* raw = nullptr;
  const int rc =
      sqlite3_open_v2(path.c_str(), &raw,
                      SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE | SQLITE_OPEN_FULLMUTEX, nullptr);
  Db db(raw);  // owns the handle even when opening failed
  if (rc != SQLITE_OK) return SqliteError(raw, rc, "open " + path);
  sqlite3_extended_result_codes(raw, 1);
  return db;
}

void Stmt::Release::operator()(sqlite3_stmt* s) const noexcept {
  if (in_use == nullptr) {
    sqlite3_finalize(s);
    return;
  }
  // Reset also ends the read the statement may hold open (a WAL checkpoint would wait for it).
  sqlite3_reset(s);
  sqlite3_clear_bindings(s);
  in_use->store(false);
}

Db::Cache::~Cache() {
  for (auto& [sql, cached] : by_sql) sqlite3_finalize(cached->stmt);
}

Result<Stmt> Db::Prepare(std::string_view sql) {
  const auto found = cache_.by_sql.find(std::string(sql));
  if (found != cache_.by_sql.end() && !found->second->in_use.exchange(true)) {
    return Stmt(db_.get(), found->second->stmt, free_space_, &found->second->in_use);
  }
  const bool cache = found == cache_.by_sql.end() && cache_.by_sql.size() < kCachedStatements;
  sqlite3_stmt* raw = nullptr;
  const int rc = sqlite3_prepare_v3(db_.get(), sql.data(), static_cast<int>(sql.size()),
                                    cache ? SQLITE_PREPARE_PERSISTENT : 0, &raw, nullptr);
  if (rc != SQLITE_OK) {
    sqlite3_finalize(raw);
    return SqliteError(db_.get(), rc, "prepare", sql, free_space_);
  }
  if (!cache || raw == nullptr) return Stmt(db_.get(), raw, free_space_);  // null: a comment
  auto cached = std::make_unique<Cached>();
  cached->stmt = raw;
  cached->in_use = true;
  std::atomic<bool>* in_use = &cached->in_use;
  cache_.by_sql.emplace(std::string(sql), std::move(cached));
  return Stmt(db_.get(), raw, free_space_, in_use);
}

Status Db::Exec(const std::string& sql) {
  const int rc = sqlite3_exec(db_.get(), sql.c_str(), nullptr, nullptr, nullptr);
  if (rc != SQLITE_OK) return SqliteError(db_.get(), rc, "exec", sql, free_space_);
  return Status::Ok();
}

Status Db::Run(std::string_view sql) {
  SEEP_ASSIGN_OR_RETURN(Stmt stmt, Prepare(sql));
  return stmt.Run();
}

Result<WriteTx> WriteTx::Begin(Db& db) {
  SEEP_RETURN_IF_ERROR(db.Run("BEGIN IMMEDIATE"));
  return WriteTx(&db);
}

WriteTx::~WriteTx() {
  if (db_ != nullptr) (void)db_->Run("ROLLBACK");
}

Status WriteTx::Commit() {
  if (db_ == nullptr) return core::Internal("store: transaction already finished");
  Status s = db_->Run("COMMIT");
  if (s.ok()) db_ = nullptr;
  return s;
}

RelaxedCommit::RelaxedCommit(Db& db, bool relaxed) : db_(db), relaxed_(relaxed) {
  // A failure leaves FULL in place: the safe direction.
  if (relaxed_) (void)db_.Run("PRAGMA synchronous=NORMAL");
}

RelaxedCommit::~RelaxedCommit() {
  if (relaxed_) (void)db_.Run("PRAGMA synchronous=FULL");
}

}  // namespace seep::service
