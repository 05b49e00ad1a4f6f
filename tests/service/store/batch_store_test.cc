// Batch jobs in the store (schema v12): a remote worker's placement recorded at its claim and
// cleared by a claim without one; the batch jobs of the executor, live until they end; and the
// demand the executor plans from (queued simulations; per live batch job, what its worker runs,
// has claimed and has had cancelled).
#include <gtest/gtest.h>

#include "store/job_store.h"
#include "store/job_store_fixture.h"

namespace seep::service {
namespace {

class BatchStoreTest : public JobStoreTest {
 protected:
  static BatchJobRecord Batch(const std::string& id, std::int64_t submitted_at_ms) {
    BatchJobRecord batch;
    batch.id = id;
    batch.workers = 1;
    batch.max_jobs = 1;
    batch.state = "PENDING";
    batch.submitted_at_ms = submitted_at_ms;
    return batch;
  }
};

TEST_F(BatchStoreTest, AClaimRecordsWhereItsWorkerRunsAndALocalClaimClearsIt) {
  ASSERT_TRUE(store_->Insert(NewJob("a")).ok());
  auto claimed = store_->ClaimNextQueued("w1", 1000, 5000, JobKind::kSimulation,
                                         WorkerPlacement{"4711", "node17"});
  ASSERT_TRUE(claimed.ok() && claimed->has_value()) << claimed.status().ToString();
  ASSERT_TRUE((*claimed)->placement.has_value());
  EXPECT_EQ((*claimed)->placement->batch_job_id, "4711");
  EXPECT_EQ((*claimed)->placement->node, "node17");
  auto read = store_->Get("a");
  ASSERT_TRUE(read.ok());
  ASSERT_TRUE(read->placement.has_value());
  EXPECT_EQ(read->placement->batch_job_id, "4711");

  // Its lease expires; seepd's own worker claims it again: no placement any more.
  ASSERT_TRUE(store_->RequeueExpired(10'000).ok());
  claimed = store_->ClaimNextQueued("seepd", 11'000, 5000);
  ASSERT_TRUE(claimed.ok() && claimed->has_value());
  EXPECT_FALSE((*claimed)->placement.has_value());
  EXPECT_FALSE(store_->Get("a")->placement.has_value());
}

TEST_F(BatchStoreTest, BatchJobsAreLiveUntilTheyEndAndKeepTheirLastState) {
  ASSERT_TRUE(store_->InsertBatchJob(Batch("12", 2000)).ok());
  ASSERT_TRUE(store_->InsertBatchJob(Batch("11", 1000)).ok());
  auto live = store_->LiveBatchJobs();
  ASSERT_TRUE(live.ok());
  ASSERT_EQ(live->size(), 2u);
  EXPECT_EQ((*live)[0].id, "11");  // oldest first
  ASSERT_TRUE(store_->UpdateBatchJob("11", "RUNNING", "node3", std::nullopt).ok());
  // A state without a node (squeue prints none once a job completes) keeps the node.
  ASSERT_TRUE(store_->UpdateBatchJob("11", "COMPLETED", "", 3000).ok());
  live = store_->LiveBatchJobs();
  ASSERT_TRUE(live.ok());
  ASSERT_EQ(live->size(), 1u);
  EXPECT_EQ((*live)[0].id, "12");
  auto ended = store_->GetBatchJob("11");
  ASSERT_TRUE(ended.ok());
  EXPECT_EQ(ended->state, "COMPLETED");
  EXPECT_EQ(ended->node, "node3");
  EXPECT_EQ(ended->ended_at_ms, 3000);
  EXPECT_EQ(store_->GetBatchJob("99").status().code(), core::StatusCode::kNotFound);
}

TEST_F(BatchStoreTest, DemandCountsTheQueueAndWhatEachLiveBatchJobHolds) {
  for (const char* id : {"a", "b", "c", "d"}) ASSERT_TRUE(store_->Insert(NewJob(id)).ok());
  ASSERT_TRUE(store_->InsertBatchJob(Batch("1", 1000)).ok());
  ASSERT_TRUE(store_->InsertBatchJob(Batch("2", 1000)).ok());
  // Batch job 1's worker runs a and b; a user cancels b; batch job 2's worker finished c.
  for (const char* batch : {"1", "1", "2"}) {
    ASSERT_TRUE(store_
                    ->ClaimNextQueued(std::string("w") + batch, 1000, 60'000, JobKind::kSimulation,
                                      WorkerPlacement{batch, "n"})
                    .ok());
  }
  ASSERT_TRUE(store_->Cancel("b", 2000).ok());
  const JobRecord c = *store_->Get("c");
  ASSERT_TRUE(store_->Finish("c", c.lease_epoch, JobState::kSucceeded, "", "", {}, 1.0, 3000).ok());

  auto demand = store_->BatchDemandNow();
  ASSERT_TRUE(demand.ok()) << demand.status().ToString();
  EXPECT_EQ(demand->queued_simulations, 1);  // d
  ASSERT_EQ(demand->by_batch_job.count("1"), 1u);
  EXPECT_EQ(demand->by_batch_job.at("1").running, 2);
  EXPECT_EQ(demand->by_batch_job.at("1").claimed, 2);
  EXPECT_EQ(demand->by_batch_job.at("1").cancel_requested, 1);
  EXPECT_EQ(demand->by_batch_job.at("2").running, 0);
  EXPECT_EQ(demand->by_batch_job.at("2").claimed, 1);

  // An ended batch job is no longer counted.
  ASSERT_TRUE(store_->UpdateBatchJob("2", "COMPLETED", "", 4000).ok());
  demand = store_->BatchDemandNow();
  ASSERT_TRUE(demand.ok());
  EXPECT_EQ(demand->by_batch_job.count("2"), 0u);
}

}  // namespace
}  // namespace seep::service
