#include "store/job_store.h"

#include <gtest/gtest.h>
#include <sqlite3.h>

#include <cmath>
#include <filesystem>

#include "store/job_store_fixture.h"

namespace seep::service {
namespace {

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

TEST_F(JobStoreTest, GetWithoutSceneLeavesTheSceneOut) {
  ASSERT_TRUE(store_->Insert(NewJob("a")).ok());
  auto job = store_->GetWithoutScene("a");
  ASSERT_TRUE(job.ok()) << job.status().ToString();
  EXPECT_EQ(job->name, "name-a");
  EXPECT_TRUE(job->scene.empty());
  EXPECT_EQ(store_->GetWithoutScene("missing").status().code(), core::StatusCode::kNotFound);
}

TEST_F(JobStoreTest, CountByStateListsEveryStateWithItsJobs) {
  for (const char* id : {"a", "b", "c"}) ASSERT_TRUE(store_->Insert(NewJob(id)).ok());
  ASSERT_TRUE(store_->ClaimNextQueued("owner", 2000, 30000).ok());
  auto counts = store_->CountByState();
  ASSERT_TRUE(counts.ok()) << counts.status().ToString();
  const std::vector<std::pair<JobState, std::int64_t>> expected = {{JobState::kQueued, 2},
                                                                   {JobState::kRunning, 1},
                                                                   {JobState::kSucceeded, 0},
                                                                   {JobState::kFailed, 0},
                                                                   {JobState::kCancelled, 0}};
  EXPECT_EQ(*counts, expected);
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
  auto claimed = store_->ClaimNextQueued("w", 2000, 500);
  ASSERT_TRUE(claimed.ok());
  ASSERT_TRUE(claimed->has_value());
  EXPECT_EQ((*claimed)->id, "first");
  EXPECT_EQ((*claimed)->state, JobState::kRunning);
  EXPECT_EQ((*claimed)->started_at_ms, 2000);
  const std::int64_t epoch = (*claimed)->lease_epoch;

  ASSERT_TRUE(store_->UpdateProgress("first", epoch, JobProgress::At(7, 0.5, 0.25, 3.0)).ok());
  EXPECT_EQ(store_->Get("first")->progress.step, 7u);
  ASSERT_TRUE(store_
                  ->Finish("first", epoch, JobState::kSucceeded, "", "", {{"k", 1.5}, {"a", -2.0}},
                           0.75, 3000)
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
  // A finished job cannot finish again: its lease is gone.
  EXPECT_EQ(store_->Finish("first", epoch, JobState::kFailed, "X", "y", {}, 0, 4000).code(),
            core::StatusCode::kAborted);
  EXPECT_EQ(store_->Get("first")->state, JobState::kSucceeded);
}

TEST_F(JobStoreTest, ListPagesNewestFirst) {
  for (char i = '0'; i < '5'; ++i) ASSERT_TRUE(store_->Insert(NewJob(std::string{'j', i})).ok());
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
  ASSERT_TRUE(store_->ClaimNextQueued("old-process", 1, 1000).ok());
  store_.reset();  // the process "dies" with a RUNNING
  auto reopened = JobStore::Open(path_);
  ASSERT_TRUE(reopened.ok());
  auto n = (*reopened)->RequeueRunning("new-process");
  ASSERT_TRUE(n.ok());
  EXPECT_EQ(*n, 1);
  auto a = (*reopened)->Get("a");
  EXPECT_EQ(a->state, JobState::kQueued);
  EXPECT_FALSE(a->lease_owner.has_value());
  EXPECT_EQ((*reopened)->Get("b")->state, JobState::kQueued);
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

TEST_F(JobStoreTest, SameRequestIdWithAnotherSceneIsAlreadyExists) {
  ASSERT_TRUE(store_->Insert(NewJob("a", "req-1")).ok());
  JobRecord other = NewJob("b", "req-1");
  other.scene = "different";
  auto again = store_->Insert(other);
  ASSERT_FALSE(again.ok());
  EXPECT_EQ(again.status().code(), core::StatusCode::kAlreadyExists);
  EXPECT_EQ(again.status().message().rfind("request_id: 'req-1'", 0), 0u)
      << again.status().message();
  EXPECT_EQ(store_->Get("b").status().code(), core::StatusCode::kNotFound);
}

TEST_F(JobStoreTest, ClaimTakesALeaseAndEveryClaimRaisesTheEpoch) {
  ASSERT_TRUE(store_->Insert(NewJob("a")).ok());
  auto first = store_->ClaimNextQueued("w1", 100, 30);
  ASSERT_TRUE(first.ok() && first->has_value());
  EXPECT_EQ((*first)->lease_owner, "w1");
  EXPECT_EQ((*first)->lease_epoch, 1);
  EXPECT_EQ((*first)->lease_expires_at_ms, 130);
  EXPECT_EQ((*first)->attempt, 1u);
  // Nothing else is queued.
  auto none = store_->ClaimNextQueued("w1", 100, 30);
  ASSERT_TRUE(none.ok());
  EXPECT_FALSE(none->has_value());

  auto cancel = store_->Heartbeat("a", 1, 500);
  ASSERT_TRUE(cancel.ok()) << cancel.status().ToString();
  EXPECT_FALSE(*cancel);
  EXPECT_EQ(store_->Get("a")->lease_expires_at_ms, 500);

  ASSERT_EQ(*store_->RequeueRunning("w2"), 1);
  auto second = store_->ClaimNextQueued("w2", 200, 30);
  ASSERT_TRUE(second.ok() && second->has_value());
  EXPECT_EQ((*second)->lease_owner, "w2");
  EXPECT_EQ((*second)->lease_epoch, 2);
}

TEST_F(JobStoreTest, AStaleEpochCannotWrite) {
  ASSERT_TRUE(store_->Insert(NewJob("a")).ok());
  const std::int64_t stale = (*store_->ClaimNextQueued("old", 100, 30))->lease_epoch;
  ASSERT_TRUE(store_->UpdateProgress("a", stale, JobProgress::At(3, 0.1, 0.1, 0)).ok());
  // The lease passes to a new claimant (as after a restart).
  ASSERT_EQ(*store_->RequeueRunning("new"), 1);
  const std::int64_t current = (*store_->ClaimNextQueued("new", 200, 30))->lease_epoch;
  ASSERT_EQ(current, stale + 1);

  EXPECT_EQ(store_->Heartbeat("a", stale, 999).status().code(), core::StatusCode::kAborted);
  EXPECT_EQ(store_->UpdateProgress("a", stale, JobProgress::At(50, 5.0, 0.9, 0)).code(),
            core::StatusCode::kAborted);
  EXPECT_EQ(store_->Finish("a", stale, JobState::kSucceeded, "", "", {{"k", 1.0}}, 1.0, 300).code(),
            core::StatusCode::kAborted);
  auto job = store_->Get("a");
  ASSERT_TRUE(job.ok());
  EXPECT_EQ(job->state, JobState::kRunning);
  EXPECT_EQ(job->progress.step, 0u);  // the re-queue reset it; the stale write did not land
  EXPECT_EQ(job->lease_expires_at_ms, 230);
  EXPECT_TRUE(job->metrics.empty());

  // The current holder writes normally.
  ASSERT_TRUE(store_->UpdateProgress("a", current, JobProgress::At(4, 0.2, 0.2, 0)).ok());
  ASSERT_TRUE(
      store_->Finish("a", current, JobState::kSucceeded, "", "", {{"k", 2.0}}, 1.0, 400).ok());
  job = store_->Get("a");
  EXPECT_EQ(job->state, JobState::kSucceeded);
  ASSERT_EQ(job->metrics.size(), 1u);
  EXPECT_DOUBLE_EQ(job->metrics[0].second, 2.0);
}

TEST_F(JobStoreTest, CancelQueuedIsImmediateAndTerminalOrUnknownJobsAreRefused) {
  ASSERT_TRUE(store_->Insert(NewJob("a")).ok());
  auto cancelled = store_->Cancel("a", 5000);
  ASSERT_TRUE(cancelled.ok()) << cancelled.status().ToString();
  EXPECT_EQ(cancelled->state, JobState::kCancelled);
  EXPECT_EQ(cancelled->finished_at_ms, 5000);
  EXPECT_EQ(cancelled->error_code, "CANCELLED");
  // It is no longer claimable.
  EXPECT_FALSE(store_->ClaimNextQueued("w", 1, 1)->has_value());

  const Status again = store_->Cancel("a", 6000).status();
  EXPECT_EQ(again.code(), core::StatusCode::kFailedPrecondition);
  EXPECT_NE(again.message().find("already CANCELLED"), std::string::npos) << again.message();
  EXPECT_EQ(store_->Cancel("missing", 1).status().code(), core::StatusCode::kNotFound);
}

// A renewal with keep_beyond_ms keeps a stored expiry that far ahead (nothing written) and writes
// the new one otherwise; either way the lease is checked and a pending cancel is said.
TEST_F(JobStoreTest, ARenewalKeepsAnExpiryFarEnoughAheadAndStillChecksTheLease) {
  ASSERT_TRUE(store_->Insert(NewJob("a")).ok());
  const std::int64_t epoch = (*store_->ClaimNextQueued("w", 100, 1000))->lease_epoch;
  ASSERT_EQ(store_->Get("a")->lease_expires_at_ms, 1100);
  // Stored 1100 >= 1050: kept.
  EXPECT_FALSE(*store_->Heartbeat("a", epoch, 1500, 1050));
  EXPECT_EQ(store_->Get("a")->lease_expires_at_ms, 1100);
  // Stored 1100 < 1150: the new expiry is written.
  EXPECT_FALSE(*store_->Heartbeat("a", epoch, 1600, 1150));
  EXPECT_EQ(store_->Get("a")->lease_expires_at_ms, 1600);
  EXPECT_EQ(store_->Heartbeat("a", epoch + 1, 1700, 1000).status().code(),
            core::StatusCode::kAborted);
  ASSERT_TRUE(store_->Cancel("a", 1200).ok());
  EXPECT_TRUE(*store_->Heartbeat("a", epoch, 1700, 1000));  // kept, and the cancel said
  EXPECT_EQ(store_->Get("a")->lease_expires_at_ms, 1600);
  // A released lease (no expiry) is always written.
  ASSERT_TRUE(store_->ReleaseLease("a", epoch).ok());
  EXPECT_TRUE(*store_->Heartbeat("a", epoch, 1800, 1000));
  EXPECT_EQ(store_->Get("a")->lease_expires_at_ms, 1800);
}

TEST_F(JobStoreTest, CancelRunningIsRecordedByTheLeaseHolder) {
  ASSERT_TRUE(store_->Insert(NewJob("a")).ok());
  const std::int64_t epoch = (*store_->ClaimNextQueued("w", 100, 30))->lease_epoch;
  EXPECT_FALSE(*store_->Heartbeat("a", epoch, 200));
  auto requested = store_->Cancel("a", 150);
  ASSERT_TRUE(requested.ok());
  EXPECT_EQ(requested->state, JobState::kRunning);
  EXPECT_TRUE(requested->cancel_requested);
  // The worker learns of it through its heartbeat, then records the outcome.
  EXPECT_TRUE(*store_->Heartbeat("a", epoch, 300));
  ASSERT_TRUE(
      store_
          ->Finish("a", epoch, JobState::kCancelled, "CANCELLED", "stopped at step 3", {}, 0.1, 400)
          .ok());
  auto job = store_->Get("a");
  EXPECT_EQ(job->state, JobState::kCancelled);
  EXPECT_EQ(job->error_message, "stopped at step 3");
  EXPECT_EQ(store_->Cancel("a", 500).status().code(), core::StatusCode::kFailedPrecondition);
}

TEST_F(JobStoreTest, APendingCancelIsHonouredAfterARestart) {
  ASSERT_TRUE(store_->Insert(NewJob("a")).ok());
  ASSERT_TRUE(store_->ClaimNextQueued("old", 100, 30).ok());
  ASSERT_TRUE(store_->Cancel("a", 150).ok());
  EXPECT_EQ(*store_->RequeueRunning("new"), 0);
  EXPECT_EQ(store_->Get("a")->state, JobState::kCancelled);
}

TEST_F(JobStoreTest, RequeueLeavesTheCurrentProcessesLeasesAlone) {
  ASSERT_TRUE(store_->Insert(NewJob("a")).ok());
  ASSERT_TRUE(store_->ClaimNextQueued("me", 100, 30).ok());
  EXPECT_EQ(*store_->RequeueRunning("me"), 0);
  EXPECT_EQ(store_->Get("a")->state, JobState::kRunning);
}

TEST_F(JobStoreTest, ExpiredLeasesAreRescuedWhileServingAndTheOldEpochCannotWrite) {
  ASSERT_TRUE(store_->Insert(NewJob("hung")).ok());
  ASSERT_TRUE(store_->Insert(NewJob("alive")).ok());
  ASSERT_TRUE(store_->Insert(NewJob("cancelled")).ok());
  ASSERT_TRUE(store_->ClaimNextQueued("me", 1000, 100).ok());  // hung: until 1100
  ASSERT_TRUE(store_->ClaimNextQueued("me", 1000, 100).ok());  // alive: renewed below
  ASSERT_TRUE(store_->ClaimNextQueued("me", 1000, 100).ok());  // cancelled: until 1100
  ASSERT_TRUE(store_->Cancel("cancelled", 1050).ok());
  ASSERT_TRUE(store_->Heartbeat("alive", 1, 5000).ok());

  auto none = store_->RequeueExpired(1099);
  ASSERT_TRUE(none.ok()) << none.status().ToString();
  EXPECT_TRUE(none->empty());

  auto rescued = store_->RequeueExpired(1101);
  ASSERT_TRUE(rescued.ok()) << rescued.status().ToString();
  ASSERT_EQ(rescued->size(), 2u);
  EXPECT_EQ((*rescued)[0].id, "hung");
  EXPECT_EQ((*rescued)[0].lease_epoch, 1);
  EXPECT_EQ((*rescued)[0].lease_owner, "me");
  EXPECT_EQ((*rescued)[1].id, "cancelled");
  EXPECT_TRUE((*rescued)[1].cancel_requested);

  const JobRecord hung = *store_->Get("hung");
  EXPECT_EQ(hung.state, JobState::kQueued);
  EXPECT_FALSE(hung.lease_owner.has_value());
  EXPECT_EQ(store_->Get("alive")->state, JobState::kRunning);
  const JobRecord cancelled = *store_->Get("cancelled");
  EXPECT_EQ(cancelled.state, JobState::kCancelled);
  EXPECT_EQ(cancelled.error_message, "cancelled after its worker's lease expired");

  // The hung worker's lease is gone: its writes are refused, the next claim gets epoch 2.
  EXPECT_EQ(store_->Heartbeat("hung", 1, 9000).status().code(), core::StatusCode::kAborted);
  EXPECT_EQ(store_->UpdateProgress("hung", 1, JobProgress::At(5, 0.1, 0.5, 0.0)).code(),
            core::StatusCode::kAborted);
  auto again = store_->ClaimNextQueued("me", 2000, 100);
  ASSERT_TRUE(again.ok() && again->has_value());
  EXPECT_EQ((*again)->id, "hung");
  EXPECT_EQ((*again)->lease_epoch, 2);
  EXPECT_TRUE(store_->RequeueExpired(2050)->empty());
}

TEST_F(JobStoreTest, ANonFiniteMetricIsRefusedNamingItAndAFailedJobKeepsNoResult) {
  ASSERT_TRUE(store_->Insert(NewJob("a")).ok());
  ASSERT_TRUE(store_->ClaimNextQueued("me", 1000, 100).ok());
  const Status nan =
      store_->Finish("a", 1, JobState::kSucceeded, "", "",
                     {{"inflow_m2_per_s", 1.0}, {"permeability_m2", std::nan("")}}, 0.5, 2000);
  EXPECT_EQ(nan.code(), core::StatusCode::kInvalidArgument);
  EXPECT_EQ(nan.message(), "store: metric 'permeability_m2' is not a finite number (got nan)");
  JobRecord job = *store_->Get("a");
  EXPECT_EQ(job.state, JobState::kRunning);  // nothing written
  EXPECT_TRUE(job.metrics.empty());
  EXPECT_EQ(CheckFiniteMetrics({{"p_max", -INFINITY}}, "job result").message(),
            "job result: metric 'p_max' is not a finite number (got -inf)");

  // A series stored before a final write that then failed does not outlive a FAILED job.
  ASSERT_TRUE(store_->StoreResultSeries("a", 1, {"time_s"}, {0.0, 1.0}, std::string(64, 'f')).ok());
  ASSERT_TRUE(
      store_->Finish("a", 1, JobState::kFailed, "UNAVAILABLE", "disk full", {}, 0.5, 2000).ok());
  job = *store_->Get("a");
  EXPECT_EQ(job.state, JobState::kFailed);
  EXPECT_TRUE(job.state_sha256.empty());
  EXPECT_TRUE(job.series_values.empty());
}

TEST_F(JobStoreTest, ThreeInterruptionsInARowWithoutProgressFailTheJob) {
  ASSERT_TRUE(store_->Insert(NewJob("a")).ok());
  const auto interrupt = [&](const std::string& owner) {
    auto claimed = store_->ClaimNextQueued(owner, 1000, 100);
    EXPECT_TRUE(claimed.ok() && claimed->has_value());
    store_.reset();  // the process "dies" with the job RUNNING
    auto reopened = JobStore::Open(path_);
    EXPECT_TRUE(reopened.ok());
    store_ = std::move(*reopened);
    std::vector<CrashLoopFailure> failed;
    EXPECT_TRUE(store_->RequeueRunning(owner + "-next", 3, &failed).ok());
    return failed;
  };
  EXPECT_TRUE(interrupt("p1").empty());
  EXPECT_TRUE(interrupt("p2").empty());
  // Progress (a newer checkpoint) starts the count again.
  ASSERT_TRUE(store_->ClaimNextQueued("p3", 1000, 100).ok());
  CheckpointRecord checkpoint;
  checkpoint.step = 40;
  checkpoint.path = "/nowhere/ckpt-40.bin";
  ASSERT_TRUE(store_->RecordCheckpoint("a", 3, checkpoint, 3).ok());
  EXPECT_EQ(*store_->RequeueRunning("p3-next"), 1);
  EXPECT_TRUE(interrupt("p4").empty());
  // A shutdown releases the lease: not an interruption without progress.
  ASSERT_TRUE(store_->ClaimNextQueued("p5", 1000, 100).ok());
  ASSERT_TRUE(store_->ReleaseLease("a", 5).ok());
  EXPECT_EQ(*store_->RequeueRunning("p5-next"), 1);
  EXPECT_EQ(store_->ReleaseLease("a", 5).code(), core::StatusCode::kAborted);
  const std::vector<CrashLoopFailure> failed = interrupt("p6");  // third at step 40
  ASSERT_EQ(failed.size(), 1u);
  EXPECT_EQ(failed[0].id, "a");
  const JobRecord job = *store_->Get("a");
  EXPECT_EQ(job.state, JobState::kFailed);
  EXPECT_EQ(job.error_code, "ABORTED");
  EXPECT_EQ(job.error_message, failed[0].message);
  EXPECT_EQ(job.error_message.rfind("interrupted 3 times in a row without progress (a crash, a "
                                    "hung or dead worker; no checkpoint beyond step 40)",
                                    0),
            0u)
      << job.error_message;
  const auto events = *store_->ListEvents("a");
  ASSERT_FALSE(events.empty());
  EXPECT_EQ(events.back().kind, "INTERRUPTED_TOO_OFTEN");
  // Resume gives it a fresh count.
  ASSERT_TRUE(store_->Resume("a").ok());
  EXPECT_TRUE(interrupt("p7").empty());
  EXPECT_EQ(store_->Get("a")->state, JobState::kQueued);
}

TEST_F(JobStoreTest, ClaimTakesTheHighestPriorityFirstAndTheOldestWithinOne) {
  const std::vector<std::pair<std::string, std::int32_t>> jobs = {
      {"low", -5}, {"first-default", 0}, {"high", 7}, {"second-default", 0}, {"higher", 9}};
  for (const auto& [id, priority] : jobs) {
    JobRecord job = NewJob(id);
    job.priority = priority;
    ASSERT_TRUE(store_->Insert(job).ok());
  }
  EXPECT_EQ(store_->Get("high")->priority, 7);
  std::vector<std::string> order;
  for (;;) {
    auto claimed = store_->ClaimNextQueued("w", 1000, 100);
    ASSERT_TRUE(claimed.ok());
    if (!claimed->has_value()) break;
    order.push_back((*claimed)->id);
  }
  EXPECT_EQ(order,
            (std::vector<std::string>{"higher", "high", "first-default", "second-default", "low"}));
}

TEST_F(JobStoreTest, ResumeQueuesAFailedOrCancelledJobAsTheNextAttempt) {
  ASSERT_TRUE(store_->Insert(NewJob("a")).ok());
  ASSERT_TRUE(store_->Insert(NewJob("b")).ok());
  const std::int64_t epoch = (*store_->ClaimNextQueued("w", 100, 30))->lease_epoch;
  ASSERT_TRUE(store_->UpdateProgress("a", epoch, JobProgress::At(9, 1.0, 0.5, 0)).ok());
  ASSERT_TRUE(store_->Finish("a", epoch, JobState::kFailed, "INTERNAL", "boom", {}, 0.5, 200).ok());
  ASSERT_TRUE(store_->Cancel("b", 300).ok());

  auto a = store_->Resume("a");
  ASSERT_TRUE(a.ok()) << a.status().ToString();
  EXPECT_EQ(a->state, JobState::kQueued);
  EXPECT_EQ(a->attempt, 2u);
  EXPECT_EQ(a->error_code, "");
  EXPECT_EQ(a->error_message, "");
  EXPECT_EQ(a->progress.step, 0u);
  EXPECT_FALSE(a->started_at_ms.has_value());
  EXPECT_FALSE(a->finished_at_ms.has_value());
  auto b = store_->Resume("b");
  ASSERT_TRUE(b.ok());
  EXPECT_EQ(b->state, JobState::kQueued);
  EXPECT_EQ(b->attempt, 2u);

  // The re-run is claimed with a new epoch and can finish this time.
  auto again = store_->ClaimNextQueued("w", 400, 30);
  ASSERT_TRUE(again.ok() && again->has_value());
  EXPECT_EQ((*again)->id, "a");
  EXPECT_EQ((*again)->lease_epoch, epoch + 1);

  // QUEUED (b), RUNNING (a) and unknown jobs cannot be resumed.
  EXPECT_EQ(store_->Resume("b").status().code(), core::StatusCode::kFailedPrecondition);
  EXPECT_EQ(store_->Resume("a").status().code(), core::StatusCode::kFailedPrecondition);
  EXPECT_EQ(store_->Resume("missing").status().code(), core::StatusCode::kNotFound);
  ASSERT_TRUE(
      store_->Finish("a", epoch + 1, JobState::kSucceeded, "", "", {{"k", 1}}, 0.5, 500).ok());
  const Status done = store_->Resume("a").status();
  EXPECT_EQ(done.code(), core::StatusCode::kFailedPrecondition);
  EXPECT_NE(done.message().find("is SUCCEEDED"), std::string::npos) << done.message();
  EXPECT_EQ(store_->Get("a")->attempt, 2u);
}

TEST_F(JobStoreTest, ListFiltersByStateAndNameAndStillPages) {
  // names: name-alpha0, name-beta1, name-alpha2, name-beta3, name-alpha4 (oldest first)
  for (int i = 0; i < 5; ++i) {
    std::string id = i % 2 == 0 ? "alpha" : "beta";
    id.append(1, static_cast<char>('0' + i));
    JobRecord job = NewJob(id);
    ASSERT_TRUE(store_->Insert(job).ok());
  }
  ASSERT_TRUE(store_->Cancel("alpha2", 1).ok());
  ASSERT_TRUE(store_->Cancel("beta3", 1).ok());

  auto cancelled = store_->List(10, std::nullopt, {{JobState::kCancelled}, "", {}, {}});
  ASSERT_TRUE(cancelled.ok()) << cancelled.status().ToString();
  ASSERT_EQ(cancelled->jobs.size(), 2u);
  EXPECT_EQ(cancelled->jobs[0].id, "beta3");
  EXPECT_EQ(cancelled->jobs[1].id, "alpha2");

  auto alpha = store_->List(10, std::nullopt, {{}, "alpha", {}, {}});
  ASSERT_EQ(alpha->jobs.size(), 3u);
  EXPECT_EQ(alpha->jobs[0].id, "alpha4");

  auto queued_alpha = store_->List(10, std::nullopt, {{JobState::kQueued}, "alpha", {}, {}});
  ASSERT_EQ(queued_alpha->jobs.size(), 2u);
  EXPECT_EQ(queued_alpha->jobs[0].id, "alpha4");
  EXPECT_EQ(queued_alpha->jobs[1].id, "alpha0");

  auto two_states =
      store_->List(10, std::nullopt, {{JobState::kQueued, JobState::kCancelled}, "beta", {}, {}});
  ASSERT_EQ(two_states->jobs.size(), 2u);

  // Paging with a filter: one per page, newest first, then no cursor.
  auto p1 = store_->List(1, std::nullopt, {{}, "alpha", {}, {}});
  ASSERT_EQ(p1->jobs.size(), 1u);
  EXPECT_EQ(p1->jobs[0].id, "alpha4");
  auto p2 = store_->List(1, p1->next_cursor, {{}, "alpha", {}, {}});
  EXPECT_EQ(p2->jobs[0].id, "alpha2");
  auto p3 = store_->List(1, p2->next_cursor, {{}, "alpha", {}, {}});
  EXPECT_EQ(p3->jobs[0].id, "alpha0");
  EXPECT_FALSE(p3->next_cursor.has_value());

  // A pattern character is matched literally.
  EXPECT_TRUE(store_->List(10, std::nullopt, {{}, "%", {}, {}})->jobs.empty());
  EXPECT_TRUE(store_->List(10, std::nullopt, {{JobState::kRunning}, "", {}, {}})->jobs.empty());
}

TEST_F(JobStoreTest, MigratesAVersion1Database) {
  store_.reset();
  std::filesystem::remove_all(dir_);
  std::filesystem::create_directories(dir_);
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(path_.c_str(), &db), SQLITE_OK);
  // The version-1 schema as released, with one finished job in it.
  const char* v1 = R"sql(
CREATE TABLE jobs (
  id TEXT PRIMARY KEY, request_id TEXT UNIQUE, name TEXT NOT NULL,
  state TEXT NOT NULL CHECK (state IN ('QUEUED','RUNNING','SUCCEEDED','FAILED','CANCELLED')),
  scene BLOB NOT NULL, build_id TEXT NOT NULL, created_at_ms INTEGER NOT NULL,
  started_at_ms INTEGER, finished_at_ms INTEGER, step INTEGER NOT NULL DEFAULT 0,
  time_s REAL NOT NULL DEFAULT 0, fraction_done REAL NOT NULL DEFAULT 0,
  error_code TEXT NOT NULL DEFAULT '', error_message TEXT NOT NULL DEFAULT '',
  wall_time_s REAL NOT NULL DEFAULT 0) STRICT;
CREATE INDEX jobs_by_state ON jobs(state);
CREATE TABLE results (job_id TEXT NOT NULL REFERENCES jobs(id) ON DELETE CASCADE,
  name TEXT NOT NULL, value REAL NOT NULL, PRIMARY KEY (job_id, name)) STRICT;
INSERT INTO jobs (id, name, state, scene, build_id, created_at_ms)
  VALUES ('old', 'n', 'FAILED', x'00', 'b', 7);
PRAGMA user_version=1;
)sql";
  ASSERT_EQ(sqlite3_exec(db, v1, nullptr, nullptr, nullptr), SQLITE_OK) << sqlite3_errmsg(db);
  sqlite3_close(db);

  auto reopened = JobStore::Open(path_);
  ASSERT_TRUE(reopened.ok()) << reopened.status().ToString();
  auto old = (*reopened)->Get("old");
  ASSERT_TRUE(old.ok()) << old.status().ToString();
  EXPECT_EQ(old->attempt, 1u);
  EXPECT_EQ(old->lease_epoch, 0);
  EXPECT_FALSE(old->cancel_requested);
  EXPECT_EQ(old->kind, JobKind::kSimulation);  // v4's default for the jobs it finds
  auto resumed = (*reopened)->Resume("old");
  ASSERT_TRUE(resumed.ok());
  EXPECT_EQ(resumed->attempt, 2u);
  (*reopened).reset();

  ASSERT_EQ(sqlite3_open(path_.c_str(), &db), SQLITE_OK);
  sqlite3_stmt* stmt = nullptr;
  ASSERT_EQ(sqlite3_prepare_v2(db, "PRAGMA user_version", -1, &stmt, nullptr), SQLITE_OK);
  ASSERT_EQ(sqlite3_step(stmt), SQLITE_ROW);
  EXPECT_EQ(sqlite3_column_int(stmt, 0), JobStore::kSchemaVersion);
  EXPECT_EQ(JobStore::kSchemaVersion, 14);
  sqlite3_finalize(stmt);
  sqlite3_close(db);
}

// A staged run's progress names its stage; the stored job keeps it (seep show after the run) and
// a resumed attempt starts without it.
TEST_F(JobStoreTest, ProgressKeepsTheStageAndResumeClearsIt) {
  ASSERT_TRUE(store_->Insert(NewJob("a")).ok());
  const std::int64_t epoch = (*store_->ClaimNextQueued("w", 100, 30))->lease_epoch;
  JobProgress progress = JobProgress::At(9, 1.0, 0.5, 0);
  progress.stage_index = 2;
  progress.stage_count = 3;
  progress.stage_name = "inject";
  ASSERT_TRUE(store_->UpdateProgress("a", epoch, progress).ok());
  for (const bool with_scene : {true, false}) {
    auto job = with_scene ? store_->Get("a") : store_->GetWithoutScene("a");
    ASSERT_TRUE(job.ok()) << job.status().ToString();
    EXPECT_EQ(job->progress.step, 9u);
    EXPECT_EQ(job->progress.stage_index, 2u);
    EXPECT_EQ(job->progress.stage_count, 3u);
    EXPECT_EQ(job->progress.stage_name, "inject");
  }
  auto page = store_->List(10, std::nullopt);
  ASSERT_TRUE(page.ok());
  ASSERT_EQ(page->jobs.size(), 1u);
  EXPECT_EQ(page->jobs[0].progress.stage_name, "inject");

  ASSERT_TRUE(store_->Finish("a", epoch, JobState::kFailed, "INTERNAL", "x", {}, 1.0, 200).ok());
  EXPECT_EQ(store_->Get("a")->progress.stage_index, 2u);  // where the run ended
  auto resumed = store_->Resume("a");
  ASSERT_TRUE(resumed.ok()) << resumed.status().ToString();
  auto again = store_->Get("a");
  ASSERT_TRUE(again.ok());
  EXPECT_EQ(again->progress.stage_index, 0u);
  EXPECT_EQ(again->progress.stage_count, 0u);
  EXPECT_EQ(again->progress.stage_name, "");
}

TEST_F(JobStoreTest, CheckpointsAreFencedListedNewestFirstAndRotated) {
  ASSERT_TRUE(store_->Insert(NewJob("a")).ok());
  const std::int64_t epoch = (*store_->ClaimNextQueued("w", 100, 30))->lease_epoch;
  std::vector<CheckpointRecord> dropped_all;
  for (std::uint64_t step : {10u, 20u, 30u, 40u}) {
    CheckpointRecord c;
    c.step = step;
    c.time_s = 0.5 * static_cast<double>(step);
    c.path = "/x/ckpt-" + std::to_string(step) + ".bin";
    c.bytes = 100 + static_cast<std::int64_t>(step);
    auto dropped = store_->RecordCheckpoint("a", epoch, c, /*keep=*/2);
    ASSERT_TRUE(dropped.ok()) << dropped.status().ToString();
    dropped_all.insert(dropped_all.end(), dropped->begin(), dropped->end());
  }
  // Keeping 2: steps 10 and 20 were handed back for deletion, in that order of rotation.
  ASSERT_EQ(dropped_all.size(), 2u);
  EXPECT_EQ(dropped_all[0].step, 10u);
  EXPECT_EQ(dropped_all[1].path, "/x/ckpt-20.bin");
  auto listed = store_->ListCheckpoints("a");
  ASSERT_TRUE(listed.ok());
  ASSERT_EQ(listed->size(), 2u);
  EXPECT_EQ((*listed)[0].step, 40u);
  EXPECT_EQ((*listed)[0].bytes, 140);
  EXPECT_DOUBLE_EQ((*listed)[0].time_s, 20.0);
  EXPECT_EQ((*listed)[1].step, 30u);
  // A worker with an older lease records nothing.
  CheckpointRecord stale;
  stale.step = 50;
  stale.path = "/x/ckpt-50.bin";
  EXPECT_EQ(store_->RecordCheckpoint("a", epoch - 1, stale, 2).status().code(),
            core::StatusCode::kAborted);
  EXPECT_EQ(store_->ListCheckpoints("a")->size(), 2u);
}

TEST_F(JobStoreTest, ResultSeriesAndStateHashComeBackWithTheJob) {
  ASSERT_TRUE(store_->Insert(NewJob("a")).ok());
  const std::int64_t epoch = (*store_->ClaimNextQueued("w", 100, 30))->lease_epoch;
  const std::vector<std::string> columns = {"time_s", "inflow_m2_per_s"};
  const std::vector<double> values = {0.0, 1.5, 0.25, -2.0e-300};
  ASSERT_TRUE(store_->StoreResultSeries("a", epoch, columns, values, "ab12").ok());
  EXPECT_EQ(store_->StoreResultSeries("a", epoch + 1, columns, values, "x").code(),
            core::StatusCode::kAborted);
  EXPECT_EQ(store_->StoreResultSeries("a", epoch, {"bad,name"}, {}, "x").code(),
            core::StatusCode::kInvalidArgument);
  ASSERT_TRUE(
      store_->Finish("a", epoch, JobState::kSucceeded, "", "", {{"k", 2.0}}, 1.0, 300).ok());
  auto job = store_->Get("a");
  ASSERT_TRUE(job.ok());
  EXPECT_EQ(job->series_columns, columns);
  EXPECT_EQ(job->series_values, values);  // bit-exact through the blob
  EXPECT_EQ(job->state_sha256, "ab12");
}

TEST_F(JobStoreTest, EventsAreKeptInOrderPerJob) {
  ASSERT_TRUE(store_->Insert(NewJob("a")).ok());
  ASSERT_TRUE(store_->Insert(NewJob("b")).ok());
  ASSERT_TRUE(store_->AddEvent("a", 5, "CLAIMED", "attempt 1").ok());
  ASSERT_TRUE(store_->AddEvent("b", 6, "CLAIMED", "attempt 1").ok());
  ASSERT_TRUE(store_->AddEvent("a", 7, "RESUMED", "from step 40").ok());
  EXPECT_EQ(store_->AddEvent("missing", 8, "X", "").code(), core::StatusCode::kNotFound);
  auto events = store_->ListEvents("a");
  ASSERT_TRUE(events.ok());
  ASSERT_EQ(events->size(), 3u);
  EXPECT_EQ((*events)[0].kind, "SUBMITTED");  // the store's own, at insert
  EXPECT_EQ((*events)[1].kind, "CLAIMED");
  EXPECT_EQ((*events)[2].at_ms, 7);
  EXPECT_EQ((*events)[2].message, "from step 40");
}

}  // namespace
}  // namespace seep::service
