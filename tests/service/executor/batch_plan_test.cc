// PlanBatchJobs: how many batch jobs the Slurm executor submits and which it cancels, one batch
// job per seep job and packed, against counts worked out by hand.
#include "executor/batch_plan.h"

#include <gtest/gtest.h>

namespace seep::service {
namespace {

BatchJobRecord Live(const std::string& id, const std::string& state) {
  BatchJobRecord batch;
  batch.id = id;
  batch.state = state;
  return batch;
}

constexpr BatchPlanOptions kOnePerJob{1, 1, 100};
constexpr BatchPlanOptions kPackedFour{4, 0, 100};

TEST(BatchPlan, OnePerJobSubmitsOneForEachQueuedJobWithoutAWorker) {
  BatchDemand demand;
  demand.queued_simulations = 5;
  // Two live batch jobs: one whose worker has not claimed yet (it will take one of the five),
  // one whose worker runs its job (it takes no other).
  demand.by_batch_job["2"] = {1, 1, 0};
  const BatchPlan plan =
      PlanBatchJobs(demand, {Live("1", "PENDING"), Live("2", "RUNNING")}, kOnePerJob);
  EXPECT_EQ(plan.submit, 4);
  EXPECT_TRUE(plan.cancel.empty());
}

TEST(BatchPlan, NoMoreThanTheLiveLimit) {
  BatchDemand demand;
  demand.queued_simulations = 500;
  const BatchPlan plan = PlanBatchJobs(demand, {Live("1", "PENDING")}, {1, 1, 10});
  EXPECT_EQ(plan.submit, 9);
}

TEST(BatchPlan, EndedBatchJobsCountForNothing) {
  BatchDemand demand;
  demand.queued_simulations = 2;
  const BatchPlan plan = PlanBatchJobs(
      demand, {Live("1", "COMPLETED"), Live("2", "CANCELLED by 0"), Live("3", "NODE_FAIL")},
      kOnePerJob);
  EXPECT_EQ(plan.submit, 2);
  EXPECT_TRUE(IsEndedBatchState("TIMEOUT"));
  // Preempted with --requeue: it comes back.
  EXPECT_FALSE(IsEndedBatchState("PREEMPTED"));
}

TEST(BatchPlan, ACancelledJobsOwnBatchJobIsCancelled) {
  BatchDemand demand;
  demand.by_batch_job["7"] = {1, 1, 1};  // running its one job, which a user cancelled
  demand.by_batch_job["8"] = {1, 1, 0};
  const BatchPlan plan =
      PlanBatchJobs(demand, {Live("7", "RUNNING"), Live("8", "RUNNING")}, kOnePerJob);
  EXPECT_EQ(plan.submit, 0);
  EXPECT_EQ(plan.cancel, std::vector<std::string>{"7"});
}

TEST(BatchPlan, PendingBatchJobsNoLongerNeededAreCancelledNewestFirst) {
  BatchDemand demand;
  demand.queued_simulations = 1;
  const BatchPlan plan = PlanBatchJobs(
      demand,
      {Live("1", "PENDING"), Live("2", "PENDING"), Live("3", "PENDING"), Live("4", "RUNNING")},
      kOnePerJob);
  EXPECT_EQ(plan.submit, 0);
  // Four slots for one job: the three newest go, but a running one is left to end by itself.
  EXPECT_EQ(plan.cancel, (std::vector<std::string>{"3", "2", "1"}));
}

TEST(BatchPlan, PackedSubmitsEnoughAllocationsForTheQueue) {
  BatchDemand demand;
  demand.queued_simulations = 10;
  demand.by_batch_job["1"] = {3, 7, 0};  // three of its four slots busy
  const BatchPlan plan = PlanBatchJobs(demand, {Live("1", "RUNNING")}, kPackedFour);
  // One free slot; nine jobs left over need three allocations of four.
  EXPECT_EQ(plan.submit, 3);
  // A packed worker's cancelled job is its own worker's business: nothing is cancelled.
  demand.by_batch_job["1"].cancel_requested = 1;
  EXPECT_TRUE(PlanBatchJobs(demand, {Live("1", "RUNNING")}, kPackedFour).cancel.empty());
}

TEST(BatchPlan, PackedKeepsAPendingAllocationWhileItIsNeeded) {
  BatchDemand demand;
  demand.queued_simulations = 4;
  const BatchPlan plan =
      PlanBatchJobs(demand, {Live("1", "PENDING"), Live("2", "PENDING")}, kPackedFour);
  EXPECT_EQ(plan.submit, 0);
  EXPECT_EQ(plan.cancel, std::vector<std::string>{"2"});
}

}  // namespace
}  // namespace seep::service
