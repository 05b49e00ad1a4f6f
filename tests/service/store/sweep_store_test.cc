// JobStore sweeps: the sweep and its jobs in one transaction (a clash leaves nothing), read back
// by position, deleted with all their jobs in one transaction (a running job leaves everything),
// and a job deleted on its own leaving its sweep.
#include "job_store_fixture.h"

namespace seep::service {
namespace {

class SweepStoreTest : public JobStoreTest {
 protected:
  static SweepRecord NewSweep(const std::string& id) {
    SweepRecord sweep;
    sweep.id = id;
    sweep.name = "sweep-" + id;
    sweep.definition = "definition of " + id;
    sweep.created_at_ms = 2000;
    return sweep;
  }
  std::size_t JobCount() {
    auto page = store_->List(1000, std::nullopt);
    EXPECT_TRUE(page.ok());
    return page.ok() ? page->jobs.size() : 0;
  }
};

TEST_F(SweepStoreTest, StoresTheSweepWithItsJobsByPosition) {
  const auto stored =
      store_->InsertSweep(NewSweep("s-1"), {NewJob("j-a"), NewJob("j-b"), NewJob("j-c")});
  ASSERT_TRUE(stored.ok()) << stored.status().ToString();
  EXPECT_TRUE(stored->created);
  const auto sweep = store_->GetSweep("s-1");
  ASSERT_TRUE(sweep.ok()) << sweep.status().ToString();
  EXPECT_EQ(sweep->name, "sweep-s-1");
  EXPECT_EQ(sweep->definition, "definition of s-1");
  EXPECT_EQ(sweep->created_at_ms, 2000);
  const std::vector<std::pair<std::uint32_t, std::string>> expected = {
      {0, "j-a"}, {1, "j-b"}, {2, "j-c"}};
  EXPECT_EQ(sweep->jobs, expected);
  EXPECT_EQ(store_->Get("j-b")->state, JobState::kQueued);
  EXPECT_EQ(store_->ListEvents("j-c")->front().kind, "SUBMITTED");
  EXPECT_EQ(store_->GetSweep("s-2").status().code(), core::StatusCode::kNotFound);
}

TEST_F(SweepStoreTest, AClashingJobLeavesNothingStored) {
  ASSERT_TRUE(store_->Insert(NewJob("j-b")).ok());
  // The second job's id is taken: the sweep and its first job roll back with it.
  const auto stored = store_->InsertSweep(NewSweep("s-1"), {NewJob("j-a"), NewJob("j-b")});
  EXPECT_FALSE(stored.ok());
  EXPECT_EQ(store_->GetSweep("s-1").status().code(), core::StatusCode::kNotFound);
  EXPECT_EQ(store_->Get("j-a").status().code(), core::StatusCode::kNotFound);
  EXPECT_EQ(JobCount(), 1u);
}

TEST_F(SweepStoreTest, ARepeatedRequestIdReturnsTheFirstSweepOrRefusesAnother) {
  SweepRecord first = NewSweep("s-1");
  first.request_id = "r-1";
  ASSERT_TRUE(store_->InsertSweep(first, {NewJob("j-a")}).ok());
  SweepRecord again = first;
  again.id = "s-2";
  const auto repeated = store_->InsertSweep(again, {NewJob("j-b")});
  ASSERT_TRUE(repeated.ok()) << repeated.status().ToString();
  EXPECT_FALSE(repeated->created);
  EXPECT_EQ(repeated->sweep.id, "s-1");
  EXPECT_EQ(store_->Get("j-b").status().code(), core::StatusCode::kNotFound);
  again.definition = "another";
  EXPECT_EQ(store_->InsertSweep(again, {NewJob("j-b")}).status().code(),
            core::StatusCode::kAlreadyExists);
  EXPECT_EQ(JobCount(), 1u);
}

TEST_F(SweepStoreTest, DeleteRemovesEveryJobOrNothingWhileOneRuns) {
  ASSERT_TRUE(store_->InsertSweep(NewSweep("s-1"), {NewJob("j-a"), NewJob("j-b")}).ok());
  ASSERT_TRUE(store_->Cancel("j-b", 3000).ok());
  const auto claimed = store_->ClaimNextQueued("worker", 3000, 60000);
  ASSERT_TRUE(claimed.ok() && claimed->has_value());
  EXPECT_EQ((*claimed)->id, "j-a");
  const auto refused = store_->DeleteSweep("s-1");
  EXPECT_EQ(refused.status().code(), core::StatusCode::kFailedPrecondition);
  EXPECT_NE(refused.status().message().find("job j-a is RUNNING"), std::string::npos)
      << refused.status().message();
  EXPECT_EQ(store_->GetSweep("s-1")->jobs.size(), 2u);
  EXPECT_TRUE(store_->Get("j-b").ok());  // the cancelled one was not removed either

  CheckpointRecord checkpoint;
  checkpoint.step = 5;
  checkpoint.path = (dir_ / "checkpoints" / "j-a" / "ckpt-5.bin").string();
  checkpoint.bytes = 123;
  ASSERT_TRUE(store_->RecordCheckpoint("j-a", (*claimed)->lease_epoch, checkpoint, 3).ok());
  ASSERT_TRUE(store_
                  ->Finish("j-a", (*claimed)->lease_epoch, JobState::kSucceeded, "", "",
                           {{"k", 1.0}}, 1.0, 4000)
                  .ok());
  const auto deleted = store_->DeleteSweep("s-1");
  ASSERT_TRUE(deleted.ok()) << deleted.status().ToString();
  EXPECT_EQ(deleted->job_ids, (std::vector<std::string>{"j-a", "j-b"}));
  ASSERT_EQ(deleted->checkpoints.size(), 1u);
  EXPECT_EQ(deleted->checkpoints[0].bytes, 123);
  EXPECT_EQ(store_->GetSweep("s-1").status().code(), core::StatusCode::kNotFound);
  EXPECT_EQ(JobCount(), 0u);
}

TEST_F(SweepStoreTest, AJobDeletedOnItsOwnLeavesItsSweep) {
  ASSERT_TRUE(store_->InsertSweep(NewSweep("s-1"), {NewJob("j-a"), NewJob("j-b")}).ok());
  ASSERT_TRUE(store_->Cancel("j-a", 3000).ok());
  ASSERT_TRUE(store_->Delete("j-a").ok());
  const auto sweep = store_->GetSweep("s-1");
  ASSERT_TRUE(sweep.ok());
  const std::vector<std::pair<std::uint32_t, std::string>> left = {{1, "j-b"}};
  EXPECT_EQ(sweep->jobs, left);
}

}  // namespace
}  // namespace seep::service
