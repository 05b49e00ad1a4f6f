// A low or full disk in the store: below --min-free-disk-mb no job is accepted or claimed while
// reads and a running job's outcome still go through; a write the file system refuses
// (SQLITE_FULL) is RESOURCE_EXHAUSTED naming the free space, not INTERNAL; and the WAL gives its
// space back on a low disk.
#include "store/free_space.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <string>

#include "job_store_fixture.h"
#include "store/job_store.h"
#include "store/sqlite_handle.h"

namespace seep::service {
namespace {

constexpr std::uint64_t kThreshold = 256u << 20;  // --min-free-disk-mb 256

class LowDisk : public JobStoreTest {
 protected:
  void SetUp() override {
    JobStoreTest::SetUp();
    store_.reset();
    free_file_ = dir_ / "free-bytes";
    SetFree(10u << 30);
    auto store = JobStore::Open(path_, {kThreshold, free_file_});
    ASSERT_TRUE(store.ok()) << store.status().ToString();
    store_ = std::move(*store);
  }
  void SetFree(std::uint64_t bytes) const { std::ofstream(free_file_) << bytes; }

  std::filesystem::path free_file_;
};

void ExpectDiskFull(const core::Status& status, const std::string& free) {
  EXPECT_EQ(status.code(), core::StatusCode::kResourceExhausted) << status.ToString();
  for (const std::string& part :
       {std::string("disk full"), free + " free", std::string("--min-free-disk-mb 256")}) {
    EXPECT_NE(status.message().find(part), std::string::npos)
        << part << " not in " << status.message();
  }
}

// A scratch folder holding `free`, the free space a guard's test file reports; removed at the end.
struct ScratchFolder {
  ScratchFolder(const std::string& name, std::uint64_t free_bytes)
      : dir(std::filesystem::temp_directory_path() /
            ("seep-" + name + "-" + std::to_string(::getpid()))) {
    std::filesystem::create_directories(dir);
    SetFree(free_bytes);
  }
  ~ScratchFolder() { std::filesystem::remove_all(dir); }
  void SetFree(std::uint64_t bytes) const { std::ofstream(dir / "free") << bytes; }
  std::filesystem::path dir;
};

TEST(FreeSpaceGuard, RefusesWhatWouldLeaveLessThanTheThresholdNamingTheFiguresAndTheFlag) {
  const ScratchFolder scratch("free-space", 300u << 20);
  const std::filesystem::path& dir = scratch.dir;
  const FreeSpaceGuard guard(dir, {kThreshold, dir / "free"});
  EXPECT_TRUE(guard.CheckRoom("nothing").ok());
  const core::Status big = guard.CheckRoom("the checkpoint is not written", 60u << 20);
  EXPECT_EQ(big.code(), core::StatusCode::kResourceExhausted);
  EXPECT_NE(big.message().find("300.0 MiB free"), std::string::npos) << big.message();
  EXPECT_NE(big.message().find("60.0 MiB more"), std::string::npos) << big.message();
  EXPECT_NE(big.message().find("--min-free-disk-mb 256"), std::string::npos) << big.message();
  scratch.SetFree(1u << 20);
  ExpectDiskFull(guard.CheckRoom("nothing"), "1.0 MiB");
  // No threshold: nothing is refused, however little is free.
  EXPECT_TRUE(FreeSpaceGuard(dir, {0, dir / "free"}).CheckRoom("nothing").ok());
  // The real file system answers too.
  EXPECT_TRUE(FreeSpaceGuard(dir, {1, {}}).Measure().measured);
}

TEST_F(LowDisk, RefusesNewJobsAndClaimsButKeepsReadsAndARunningJobsOutcome) {
  ASSERT_TRUE(store_->Insert(NewJob("running")).ok());
  ASSERT_TRUE(store_->Insert(NewJob("waiting")).ok());
  auto claimed = store_->ClaimNextQueued("w", 2000, 30000);
  ASSERT_TRUE(claimed.ok() && *claimed) << claimed.status().ToString();

  SetFree(1u << 20);
  ExpectDiskFull(store_->Insert(NewJob("refused")).status(), "1.0 MiB");
  EXPECT_EQ(store_->Get("refused").status().code(), core::StatusCode::kNotFound);
  auto none = store_->ClaimNextQueued("w", 3000, 30000);
  ASSERT_TRUE(none.ok()) << none.status().ToString();
  EXPECT_FALSE(*none) << "a job was started on a low disk";
  // The reserve is for these: the running job's outcome and its events, and every read.
  ASSERT_TRUE(store_->AddEvent((*claimed)->id, 3000, "NOTE", "still written").ok());
  ASSERT_TRUE(store_
                  ->Finish((*claimed)->id, (*claimed)->lease_epoch, JobState::kFailed,
                           "RESOURCE_EXHAUSTED", "disk full", {}, 1.0, 4000)
                  .ok());
  auto page = store_->List(10, std::nullopt);
  ASSERT_TRUE(page.ok());
  EXPECT_EQ(page->jobs.size(), 2u);
  EXPECT_EQ(store_->Get("waiting")->state, JobState::kQueued);
  EXPECT_EQ(store_->Get((*claimed)->id)->state, JobState::kFailed);
  EXPECT_FALSE(store_->ListEvents((*claimed)->id)->empty());

  SetFree(10u << 30);  // space freed: the waiting job starts, submits are taken again
  auto next = store_->ClaimNextQueued("w", 5000, 30000);
  ASSERT_TRUE(next.ok() && *next);
  EXPECT_EQ((*next)->id, "waiting");
  EXPECT_TRUE(store_->Insert(NewJob("after")).ok());
}

TEST_F(LowDisk, TheWalGivesItsSpaceBack) {
  for (int i = 0; i < 50; ++i) ASSERT_TRUE(store_->Insert(NewJob("j" + std::to_string(i))).ok());
  const std::string wal = path_ + "-wal";
  ASSERT_GT(std::filesystem::file_size(wal), 0u);
  ASSERT_TRUE(store_->FitWalToDisk(true).ok());
  EXPECT_EQ(std::filesystem::file_size(wal), 0u);
  // Nothing was lost with it.
  EXPECT_EQ(store_->List(100, std::nullopt)->jobs.size(), 50u);
  ASSERT_TRUE(store_->FitWalToDisk(false).ok());
  EXPECT_TRUE(store_->Insert(NewJob("after")).ok());
}

// SQLite's own SQLITE_FULL, met here at the page limit of the connection (max_page_count) as it
// is at a full file system.
TEST(SqliteFull, IsResourceExhaustedNamingTheFreeSpaceNotInternal) {
  const ScratchFolder scratch("sqlite-full", 3u << 20);
  const FreeSpaceGuard guard(scratch.dir, {kThreshold, scratch.dir / "free"});
  {
    auto db = Db::Open((scratch.dir / "full.db").string());
    ASSERT_TRUE(db.ok());
    db->set_free_space(&guard);
    ASSERT_TRUE(
        db->Exec("CREATE TABLE rows (bytes BLOB NOT NULL); PRAGMA max_page_count=20;").ok());
    core::Status full;
    for (int i = 0; i < 100 && full.ok(); ++i) {
      auto insert = db->Prepare("INSERT INTO rows (bytes) VALUES (?)");
      ASSERT_TRUE(insert.ok());
      full = insert->BindBlob(1, std::string(4000, 'x')).Run();
    }
    ExpectDiskFull(full, "3.0 MiB");
  }
}

}  // namespace
}  // namespace seep::service
