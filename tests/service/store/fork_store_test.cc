// Forks in the store: a fork and the record of its first checkpoint stored together, its parent
// and its parent's children read back, a request_id that returns the fork stored first, and a
// deleted parent that leaves its forks as they are.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "store/job_store.h"
#include "store/job_store_fixture.h"

namespace seep::service {
namespace {

class ForkStoreTest : public JobStoreTest {
 protected:
  // A fork of `parent` at `step`, with the checkpoint record of its copy.
  JobRecord Fork(const std::string& id, const std::string& parent, std::uint64_t step,
                 std::optional<std::string> request_id = {}) const {
    JobRecord fork = NewJob(id, std::move(request_id));
    fork.parent_job_id = parent;
    fork.parent_step = step;
    return fork;
  }
  CheckpointRecord Copy(const std::string& id, std::uint64_t step) const {
    CheckpointRecord c;
    c.step = step;
    c.time_s = 0.25;
    c.path = (dir_ / "checkpoints" / id / ("ckpt-" + std::to_string(step) + ".bin")).string();
    c.bytes = 123;
    c.created_at_ms = 2000;
    return c;
  }
};

TEST_F(ForkStoreTest, AForkIsStoredWithItsFirstCheckpointAndNamesItsParent) {
  ASSERT_TRUE(store_->Insert(NewJob("p")).ok());
  ASSERT_TRUE(store_->InsertFork(Fork("f1", "p", 500), Copy("f1", 500)).ok());
  ASSERT_TRUE(store_->InsertFork(Fork("f2", "p", 1000), Copy("f2", 1000)).ok());

  const auto f1 = store_->Get("f1");
  ASSERT_TRUE(f1.ok()) << f1.status().ToString();
  EXPECT_EQ(f1->state, JobState::kQueued);
  EXPECT_EQ(f1->parent_job_id, std::optional<std::string>("p"));
  EXPECT_EQ(f1->parent_step, 500u);
  const auto checkpoints = store_->ListCheckpoints("f1");
  ASSERT_TRUE(checkpoints.ok());
  ASSERT_EQ(checkpoints->size(), 1u);
  EXPECT_EQ(checkpoints->front().step, 500u);
  EXPECT_EQ(checkpoints->front().path, Copy("f1", 500).path);
  EXPECT_EQ(checkpoints->front().bytes, 123);
  // Oldest first; a job without forks has none, and listing leaves them out.
  EXPECT_EQ(store_->Get("p")->child_job_ids, (std::vector<std::string>{"f1", "f2"}));
  EXPECT_EQ(store_->GetWithoutScene("p")->child_job_ids, (std::vector<std::string>{"f1", "f2"}));
  EXPECT_TRUE(store_->Get("f1")->child_job_ids.empty());
  const auto events = store_->ListEvents("f1");
  ASSERT_TRUE(events.ok());
  ASSERT_EQ(events->size(), 2u);
  EXPECT_NE((*events)[0].message.find("forked from job p at step 500"), std::string::npos);
  EXPECT_EQ((*events)[1].kind, "CHECKPOINT");
}

TEST_F(ForkStoreTest, ARepeatedRequestIdReturnsTheFirstForkAndRecordsNothing) {
  ASSERT_TRUE(store_->Insert(NewJob("p")).ok());
  ASSERT_TRUE(store_->InsertFork(Fork("f1", "p", 500, "r-1"), Copy("f1", 500)).ok());
  const auto again = store_->InsertFork(Fork("f2", "p", 500, "r-1"), Copy("f2", 500));
  ASSERT_TRUE(again.ok()) << again.status().ToString();
  EXPECT_FALSE(again->created);
  EXPECT_EQ(again->job.id, "f1");
  EXPECT_TRUE(store_->ListCheckpoints("f2")->empty());
  EXPECT_EQ(store_->ListCheckpoints("f1")->size(), 1u);
  // The same request_id for a fork of another step is another request.
  const auto other = store_->InsertFork(Fork("f3", "p", 600, "r-1"), Copy("f3", 600));
  EXPECT_EQ(other.status().code(), core::StatusCode::kAlreadyExists);
  EXPECT_EQ(store_->Get("p")->child_job_ids, std::vector<std::string>{"f1"});
}

TEST_F(ForkStoreTest, DeletingTheParentLeavesItsForks) {
  ASSERT_TRUE(store_->Insert(NewJob("p")).ok());
  auto claimed = store_->ClaimNextQueued("w", 100, 1'000'000);
  ASSERT_TRUE(claimed.ok() && claimed->has_value());
  ASSERT_TRUE(
      store_->Finish("p", (*claimed)->lease_epoch, JobState::kSucceeded, "", "", {}, 1.0, 200)
          .ok());
  ASSERT_TRUE(store_->InsertFork(Fork("f1", "p", 500), Copy("f1", 500)).ok());
  ASSERT_TRUE(store_->Delete("p").ok());
  const auto f1 = store_->Get("f1");
  ASSERT_TRUE(f1.ok()) << f1.status().ToString();
  EXPECT_EQ(f1->parent_job_id, std::optional<std::string>("p"));
  EXPECT_EQ(store_->ListCheckpoints("f1")->size(), 1u);
}

TEST_F(ForkStoreTest, InsertForkNeedsAParent) {
  EXPECT_EQ(store_->InsertFork(NewJob("f"), Copy("f", 1)).status().code(),
            core::StatusCode::kInternal);
  EXPECT_EQ(store_->Get("f").status().code(), core::StatusCode::kNotFound);
}

}  // namespace
}  // namespace seep::service
