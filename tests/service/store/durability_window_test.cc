// DurabilityWindow: one fdatasync of the WAL covers every windowed commit of its window, no
// sooner than the window and within it; a flush syncs at once; stopping does not wait the window.
// (Through JobStore: SuccessStore.AWindowedSuccessIsSyncedByTheWindowAndADurableOneNeedsNone.)
#include "store/durability_window.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <thread>

namespace seep::service {
namespace {

using std::chrono::milliseconds;
using Clock = std::chrono::steady_clock;

class DurabilityWindowTest : public ::testing::Test {
 protected:
  void SetUp() override {
    wal_ = std::filesystem::temp_directory_path() /
           ("seep-window-test-" + std::to_string(::getpid()) + "-" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name() + "-wal");
    std::ofstream(wal_) << "frames";
  }
  void TearDown() override { std::filesystem::remove(wal_); }

  // Waits (up to a minute: sanitizer builds on a busy machine) until nothing is pending.
  static bool WaitUntilSynced(const DurabilityWindow& window) {
    const auto give_up = Clock::now() + std::chrono::minutes(1);
    while (window.pending() && Clock::now() < give_up) {
      std::this_thread::sleep_for(milliseconds(5));
    }
    return !window.pending();
  }

  std::filesystem::path wal_;
};

TEST_F(DurabilityWindowTest, OpeningAMissingWalFileNamesIt) {
  auto window = DurabilityWindow::Open(wal_.string() + ".missing", milliseconds(100));
  ASSERT_FALSE(window.ok());
  EXPECT_EQ(window.status().code(), core::StatusCode::kFailedPrecondition);
  EXPECT_NE(window.status().message().find(wal_.string() + ".missing"), std::string::npos)
      << window.status().ToString();
}

// Three commits in a row wait for the first one's window, then share one sync.
TEST_F(DurabilityWindowTest, OneSyncCoversEveryCommitOfItsWindow) {
  constexpr milliseconds kWindow(1500);
  auto window = DurabilityWindow::Open(wal_, kWindow);
  ASSERT_TRUE(window.ok()) << window.status().ToString();
  EXPECT_FALSE((*window)->pending());
  const auto first = Clock::now();
  for (int i = 0; i < 3; ++i) (*window)->Committed();
  EXPECT_TRUE((*window)->pending());
  ASSERT_TRUE(WaitUntilSynced(**window));
  EXPECT_GE(Clock::now() - first, kWindow);  // not before the oldest commit's window is out
  EXPECT_EQ((*window)->syncs(), 1u);
  // A commit after that sync waits for a sync of its own.
  (*window)->Committed();
  ASSERT_TRUE(WaitUntilSynced(**window));
  EXPECT_EQ((*window)->syncs(), 2u);
}

TEST_F(DurabilityWindowTest, FlushSyncsAtOnceAndOnlyWhatIsPending) {
  auto window = DurabilityWindow::Open(wal_, std::chrono::hours(1));
  ASSERT_TRUE(window.ok()) << window.status().ToString();
  ASSERT_TRUE((*window)->Flush().ok());
  EXPECT_EQ((*window)->syncs(), 0u);  // nothing committed: nothing to sync
  (*window)->Committed();
  (*window)->Committed();
  ASSERT_TRUE((*window)->Flush().ok());
  EXPECT_FALSE((*window)->pending());
  EXPECT_EQ((*window)->syncs(), 1u);
}

// Stopping syncs what is pending instead of sleeping out the rest of its window.
TEST_F(DurabilityWindowTest, StoppingDoesNotWaitForTheWindow) {
  auto window = DurabilityWindow::Open(wal_, std::chrono::hours(1));
  ASSERT_TRUE(window.ok()) << window.status().ToString();
  (*window)->Committed();
  const auto start = Clock::now();
  window->reset();
  EXPECT_LT(Clock::now() - start, std::chrono::seconds(30));
}

}  // namespace
}  // namespace seep::service
