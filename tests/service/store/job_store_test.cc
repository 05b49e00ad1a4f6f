#include "store/job_store.h"

#include <gtest/gtest.h>
#include <sqlite3.h>

#include <filesystem>

namespace seep::service {
namespace {

class JobStoreTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("seep-store-test-" + std::to_string(::getpid()) + "-" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
    path_ = (dir_ / "seep.db").string();
    auto store = JobStore::Open(path_);
    ASSERT_TRUE(store.ok()) << store.status().ToString();
    store_ = std::move(*store);
  }
  void TearDown() override {
    store_.reset();
    std::filesystem::remove_all(dir_);
  }

  static JobRecord NewJob(const std::string& id, std::optional<std::string> request_id = {}) {
    JobRecord job;
    job.id = id;
    job.name = "name-" + id;
    job.request_id = std::move(request_id);
    job.scene = std::string(
        "\x0a\x03"
        "abc",
        5);
    job.build_id = "test";
    job.created_at_ms = 1000;
    return job;
  }

  std::filesystem::path dir_;
  std::string path_;
  std::unique_ptr<JobStore> store_;
};

TEST_F(JobStoreTest, InsertThenGetRoundTrips) {
  auto inserted = store_->Insert(NewJob("a"));
  ASSERT_TRUE(inserted.ok()) << inserted.status().ToString();
  EXPECT_TRUE(inserted->created);
  auto job = store_->Get("a");
  ASSERT_TRUE(job.ok());
  EXPECT_EQ(job->name, "name-a");
  EXPECT_EQ(job->state, JobState::kQueued);
  EXPECT_EQ(job->scene, std::string("\x0a\x03"
                                    "abc",
                                    5));
  EXPECT_EQ(job->created_at_ms, 1000);
  EXPECT_EQ(store_->Get("missing").status().code(), core::StatusCode::kNotFound);
}

TEST_F(JobStoreTest, SameRequestIdReturnsTheFirstJob) {
  ASSERT_TRUE(store_->Insert(NewJob("a", "req-1")).ok());
  auto again = store_->Insert(NewJob("b", "req-1"));
  ASSERT_TRUE(again.ok());
  EXPECT_FALSE(again->created);
  EXPECT_EQ(again->job.id, "a");
  auto page = store_->List(10, std::nullopt);
  ASSERT_TRUE(page.ok());
  EXPECT_EQ(page->jobs.size(), 1u);
}

TEST_F(JobStoreTest, ClaimRunsOldestFirstAndFinishStoresMetrics) {
  ASSERT_TRUE(store_->Insert(NewJob("first")).ok());
  ASSERT_TRUE(store_->Insert(NewJob("second")).ok());
  auto claimed = store_->ClaimNextQueued(2000);
  ASSERT_TRUE(claimed.ok());
  ASSERT_TRUE(claimed->has_value());
  EXPECT_EQ((*claimed)->id, "first");
  EXPECT_EQ((*claimed)->state, JobState::kRunning);
  EXPECT_EQ((*claimed)->started_at_ms, 2000);

  ASSERT_TRUE(store_->UpdateProgress("first", {7, 0.5, 0.25, 3.0}).ok());
  EXPECT_EQ(store_->Get("first")->progress.step, 7u);
  ASSERT_TRUE(
      store_->Finish("first", JobState::kSucceeded, "", "", {{"k", 1.5}, {"a", -2.0}}, 0.75, 3000)
          .ok());
  auto done = store_->Get("first");
  ASSERT_TRUE(done.ok());
  EXPECT_EQ(done->state, JobState::kSucceeded);
  EXPECT_EQ(done->finished_at_ms, 3000);
  EXPECT_DOUBLE_EQ(done->wall_time_s, 0.75);
  ASSERT_EQ(done->metrics.size(), 2u);
  EXPECT_EQ(done->metrics[0].first, "a");  // sorted by name
  EXPECT_DOUBLE_EQ(done->metrics[0].second, -2.0);
  EXPECT_DOUBLE_EQ(done->metrics[1].second, 1.5);
  // A finished job cannot finish again.
  EXPECT_EQ(store_->Finish("first", JobState::kFailed, "X", "y", {}, 0, 4000).code(),
            core::StatusCode::kFailedPrecondition);
}

TEST_F(JobStoreTest, ListPagesNewestFirst) {
  for (int i = 0; i < 5; ++i) ASSERT_TRUE(store_->Insert(NewJob("j" + std::to_string(i))).ok());
  auto first = store_->List(2, std::nullopt);
  ASSERT_TRUE(first.ok());
  ASSERT_EQ(first->jobs.size(), 2u);
  EXPECT_EQ(first->jobs[0].id, "j4");
  EXPECT_EQ(first->jobs[1].id, "j3");
  ASSERT_TRUE(first->next_cursor.has_value());
  auto second = store_->List(2, first->next_cursor);
  ASSERT_EQ(second->jobs.size(), 2u);
  EXPECT_EQ(second->jobs[0].id, "j2");
  auto last = store_->List(2, second->next_cursor);
  ASSERT_EQ(last->jobs.size(), 1u);
  EXPECT_EQ(last->jobs[0].id, "j0");
  EXPECT_FALSE(last->next_cursor.has_value());
}

TEST_F(JobStoreTest, RunningJobsAreRequeuedAfterARestart) {
  ASSERT_TRUE(store_->Insert(NewJob("a")).ok());
  ASSERT_TRUE(store_->Insert(NewJob("b")).ok());
  ASSERT_TRUE(store_->ClaimNextQueued(1).ok());
  store_.reset();  // the process "dies" with a RUNNING
  auto reopened = JobStore::Open(path_);
  ASSERT_TRUE(reopened.ok());
  auto n = (*reopened)->RequeueRunning();
  ASSERT_TRUE(n.ok());
  EXPECT_EQ(*n, 1);
  EXPECT_EQ((*reopened)->Get("a")->state, JobState::kQueued);
}

TEST_F(JobStoreTest, RefusesADatabaseFromANewerSchema) {
  store_.reset();
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(path_.c_str(), &db), SQLITE_OK);
  ASSERT_EQ(sqlite3_exec(db, "PRAGMA user_version=99", nullptr, nullptr, nullptr), SQLITE_OK);
  sqlite3_close(db);
  auto reopened = JobStore::Open(path_);
  ASSERT_FALSE(reopened.ok());
  EXPECT_EQ(reopened.status().code(), core::StatusCode::kFailedPrecondition);
  EXPECT_NE(reopened.status().message().find("schema version 99"), std::string::npos);
}

}  // namespace
}  // namespace seep::service
