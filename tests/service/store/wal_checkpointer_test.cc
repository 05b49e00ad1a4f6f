// WalCheckpointer: the WAL is copied back into the database by the checkpointer's thread, not by
// the commit that took it past the threshold, and it restarts from its beginning afterwards; if
// the thread never gets to it, the committing connection checkpoints inline at the hard limit.
// Either way the WAL file stays a few commits long instead of holding every commit made.
#include "store/wal_checkpointer.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <climits>
#include <filesystem>
#include <string>

#include "store/sqlite_handle.h"

namespace seep::service {
namespace {

constexpr std::uintmax_t kFrameBytes = 24 + 4096;  // a WAL frame: its header and one page
constexpr std::uintmax_t kWalHeaderBytes = 32;

class WalCheckpointerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("seep-checkpointer-test-" + std::to_string(::getpid()) + "-" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
    path_ = (dir_ / "test.db").string();
    auto db = Db::Open(path_);
    ASSERT_TRUE(db.ok()) << db.status().ToString();
    db_.emplace(std::move(*db));
    // NORMAL: the WAL's own behaviour without an fsync a commit (the store's relaxed commits).
    ASSERT_TRUE(db_->Exec("PRAGMA journal_mode=WAL; PRAGMA synchronous=NORMAL; "
                          "CREATE TABLE rows (id INTEGER PRIMARY KEY, bytes BLOB NOT NULL);")
                    .ok());
  }
  void TearDown() override {
    db_.reset();
    std::filesystem::remove_all(dir_);
  }

  // One commit of one row of 3,000 bytes: two or three WAL frames (its leaf, the table's root).
  void CommitARow() {
    auto tx = WriteTx::Begin(*db_);
    ASSERT_TRUE(tx.ok()) << tx.status().ToString();
    auto insert = db_->Prepare("INSERT INTO rows (bytes) VALUES (?)");
    ASSERT_TRUE(insert.ok());
    ASSERT_TRUE(insert->BindBlob(1, std::string(3000, 'x')).Run().ok());
    ASSERT_TRUE(tx->Commit().ok());
  }

  std::uintmax_t WalBytes() const { return std::filesystem::file_size(path_ + "-wal"); }

  std::int64_t Rows() {
    auto count = db_->Prepare("SELECT count(*) FROM rows");
    EXPECT_TRUE(count.ok());
    EXPECT_TRUE(*count->Step());
    return count->ColumnInt(0);
  }

  std::filesystem::path dir_;
  std::string path_;
  std::optional<Db> db_;
};

// Thirty rounds of ten commits, each round past the 16-frame threshold, then a wait for the
// thread: it checkpoints each round (the commits never do), and the WAL, started over by a later
// round's first commit, holds a few rounds at most. Left to grow, it would hold all 300 commits
// (600-900 frames).
TEST_F(WalCheckpointerTest, TheThreadCopiesTheWalAndTheWalStartsOver) {
  auto checkpointer =
      WalCheckpointer::Start(db_->handle(), path_, /*pages=*/16, /*inline_pages=*/INT_MAX);
  ASSERT_TRUE(checkpointer.ok()) << checkpointer.status().ToString();
  std::uintmax_t largest_wal = 0;
  for (int round = 0; round < 30; ++round) {
    for (int i = 0; i < 10; ++i) CommitARow();
    largest_wal = std::max(largest_wal, WalBytes());
    (*checkpointer)->WaitIdle();
  }
  // About one a round (a second when commits went on past the threshold during the first; one
  // that met a commit and got SQLITE_BUSY is not counted).
  EXPECT_GE((*checkpointer)->checkpoints(), 20u);
  EXPECT_EQ((*checkpointer)->inline_checkpoints(), 0u);
  // One round is 20-30 frames (the first one also the table's creation, a frame or two), and the
  // next round's first commit starts the WAL over when the checkpoint copied every frame. One that
  // met a commit (the machine busy: seen once in a parallel ctest run) may have copied only part,
  // and the WAL then goes on for another round until the next one: three rounds at most, against
  // 600-900 frames (3.7 MB) with no checkpoint at all.
  EXPECT_LE(largest_wal, kWalHeaderBytes + 3 * 32 * kFrameBytes);
  EXPECT_GE(largest_wal, kWalHeaderBytes + 16 * kFrameBytes);  // it did get past the threshold
  EXPECT_EQ(Rows(), 300);
}

// A thread that is never asked (threshold out of reach): the committing connection checkpoints
// inline once the WAL holds 16 frames, as SQLite's own automatic checkpoint would have.
TEST_F(WalCheckpointerTest, PastTheHardLimitTheCommitCheckpointsInline) {
  auto checkpointer =
      WalCheckpointer::Start(db_->handle(), path_, /*pages=*/INT_MAX, /*inline_pages=*/16);
  ASSERT_TRUE(checkpointer.ok()) << checkpointer.status().ToString();
  for (int i = 0; i < 300; ++i) CommitARow();
  EXPECT_EQ((*checkpointer)->checkpoints(), 0u);
  // 600-900 frames in all, 16 to 18 a checkpoint.
  EXPECT_GE((*checkpointer)->inline_checkpoints(), 30u);
  EXPECT_LE(WalBytes(), kWalHeaderBytes + (16 + 3) * kFrameBytes);
  EXPECT_EQ(Rows(), 300);
}

TEST_F(WalCheckpointerTest, AMissingDatabaseIsNamed) {
  const std::string missing = (dir_ / "no-such-folder" / "test.db").string();
  auto checkpointer = WalCheckpointer::Start(db_->handle(), missing);
  ASSERT_FALSE(checkpointer.ok());
  EXPECT_EQ(checkpointer.status().code(), core::StatusCode::kUnavailable);
  EXPECT_NE(checkpointer.status().message().find(missing), std::string::npos)
      << checkpointer.status().ToString();
}

}  // namespace
}  // namespace seep::service
