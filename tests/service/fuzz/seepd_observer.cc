#include "seepd_observer.h"

#include <sqlite3.h>

#include <fstream>
#include <sstream>

namespace seep::fuzz {

SeepdObserver::SeepdObserver(pid_t pid, std::filesystem::path data_dir)
    : pid_(pid), data_dir_(std::move(data_dir)) {}

SeepdObserver::~SeepdObserver() {
  if (db_ != nullptr) sqlite3_close(db_);
}

bool SeepdObserver::Alive() const {
  std::ifstream stat("/proc/" + std::to_string(pid_) + "/stat");
  std::string line;
  if (!std::getline(stat, line)) return false;
  // pid (comm) state ...: the state follows the last ')'.
  const auto close = line.rfind(')');
  if (close == std::string::npos || close + 2 >= line.size()) return false;
  const char state = line[close + 2];
  return state != 'Z' && state != 'X';
}

std::size_t SeepdObserver::RssBytes() const {
  std::ifstream in("/proc/" + std::to_string(pid_) + "/status");
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("VmRSS:", 0) != 0) continue;
    std::istringstream fields(line.substr(6));
    std::size_t kib = 0;
    fields >> kib;
    return kib * 1024;
  }
  return 0;
}

bool SeepdObserver::Open() {
  if (db_ != nullptr) return true;
  const std::string path = (data_dir_ / "seep.db").string();
  if (sqlite3_open_v2(path.c_str(), &db_, SQLITE_OPEN_READONLY, nullptr) != SQLITE_OK) {
    sqlite3_close(db_);
    db_ = nullptr;
    return false;
  }
  sqlite3_busy_timeout(db_, 5000);
  return true;
}

std::int64_t SeepdObserver::CountRows(const std::string& table) {
  return Count("SELECT COUNT(*) FROM " + table);
}

std::int64_t SeepdObserver::CountUnfinished() {
  return Count("SELECT COUNT(*) FROM jobs WHERE state IN ('QUEUED', 'RUNNING')");
}

std::int64_t SeepdObserver::Count(const std::string& query) {
  if (!Open()) return -1;
  sqlite3_stmt* stmt = nullptr;
  std::int64_t n = -1;
  if (sqlite3_prepare_v2(db_, query.c_str(), -1, &stmt, nullptr) == SQLITE_OK &&
      sqlite3_step(stmt) == SQLITE_ROW) {
    n = sqlite3_column_int64(stmt, 0);
  }
  sqlite3_finalize(stmt);
  return n;
}

std::set<std::string> SeepdObserver::JobIds() {
  std::set<std::string> ids;
  if (!Open()) return ids;
  sqlite3_stmt* stmt = nullptr;
  if (sqlite3_prepare_v2(db_, "SELECT id FROM jobs", -1, &stmt, nullptr) == SQLITE_OK) {
    while (sqlite3_step(stmt) == SQLITE_ROW) {
      ids.insert(reinterpret_cast<const char*>(sqlite3_column_text(stmt, 0)));
    }
  }
  sqlite3_finalize(stmt);
  return ids;
}

std::set<std::string> SeepdObserver::CheckpointFoldersWithoutAJob() {
  const std::set<std::string> jobs = JobIds();
  std::set<std::string> orphans;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(data_dir_ / "checkpoints", ec)) {
    const std::string name = entry.path().filename().string();
    if (jobs.count(name) == 0) orphans.insert(name);
  }
  return orphans;
}

}  // namespace seep::fuzz
