// JobStore::RecordSuccess: a run's final state (its bytes in its record, or its file), series,
// hash, progress, metrics and SUCCEEDED in one transaction, or nothing.
#include <gtest/gtest.h>

#include <chrono>
#include <string>
#include <thread>
#include <vector>

#include "store/checkpoint_io.h"
#include "store/job_store_fixture.h"

namespace seep::service {
namespace {

class SuccessStore : public JobStoreTest {
 protected:
  std::int64_t Claim(const std::string& id) {
    auto claimed = store_->ClaimNextQueued("w", 100, 1'000'000);
    EXPECT_TRUE(claimed.ok() && claimed->has_value());
    if (!claimed.ok() || !claimed->has_value()) return 0;
    EXPECT_EQ((*claimed)->id, id);
    return (*claimed)->lease_epoch;
  }
  static CheckpointRecord FileCheckpoint(std::uint64_t step) {
    CheckpointRecord c;
    c.step = step;
    c.path = "/x/ckpt-" + std::to_string(step) + ".bin";
    c.bytes = 100;
    c.created_at_ms = static_cast<std::int64_t>(step);
    return c;
  }
  static RunSuccess Success() {
    RunSuccess run;
    run.series_columns = {"time_s", "inflow_m2_per_s"};
    run.series_values = {0.0, 1.5, 0.25, -2.0e-300};
    run.state_sha256 = std::string(64, 'c');
    run.final_progress = JobProgress::At(30, 0.75, 1.0, 0);
    run.metrics = {{"k", 2.5}, {"q", -1.0}};
    run.wall_time_s = 0.125;
    return run;
  }
};

// The final state's bytes (zero bytes among them) come back from the store bit for bit, with
// the rest of the success, and the records beyond `keep` are handed back for their files to go.
TEST_F(SuccessStore, KeepsTheFinalStateWithTheSeriesAndTheOutcome) {
  ASSERT_TRUE(store_->Insert(NewJob("a")).ok());
  const std::int64_t epoch = Claim("a");
  for (const std::uint64_t step : {10u, 20u}) {
    ASSERT_TRUE(store_->RecordCheckpoint("a", epoch, FileCheckpoint(step), 100).ok());
  }
  CheckpointRecord final_state;
  final_state.step = 30;
  final_state.time_s = 0.75;
  final_state.content = std::string("SEEPCKPT\0\x01\xff state", 17);
  final_state.bytes = static_cast<std::int64_t>(final_state.content.size());
  final_state.created_at_ms = 30;

  auto dropped = store_->RecordSuccess("a", epoch, Success(), &final_state, /*keep=*/2, 400);
  ASSERT_TRUE(dropped.ok()) << dropped.status().ToString();
  ASSERT_EQ(dropped->size(), 1u);
  EXPECT_EQ((*dropped)[0].step, 10u);
  EXPECT_EQ((*dropped)[0].path, "/x/ckpt-10.bin");

  auto job = store_->Get("a");
  ASSERT_TRUE(job.ok());
  EXPECT_EQ(job->state, JobState::kSucceeded);
  EXPECT_EQ(job->finished_at_ms, 400);
  EXPECT_EQ(job->metrics, (std::vector<std::pair<std::string, double>>{{"k", 2.5}, {"q", -1.0}}));
  EXPECT_EQ(job->series_columns, Success().series_columns);
  EXPECT_EQ(job->series_values, Success().series_values);
  EXPECT_EQ(job->state_sha256, std::string(64, 'c'));
  EXPECT_EQ(job->progress.step, 30u);
  EXPECT_DOUBLE_EQ(job->progress.fraction_done, 1.0);

  auto listed = store_->ListCheckpoints("a");
  ASSERT_TRUE(listed.ok());
  ASSERT_EQ(listed->size(), 2u);
  EXPECT_EQ((*listed)[0].step, 30u);
  EXPECT_EQ((*listed)[0].path, "");
  EXPECT_EQ((*listed)[0].content, final_state.content);
  EXPECT_EQ((*listed)[0].bytes, 17);
  EXPECT_EQ((*listed)[1].path, "/x/ckpt-20.bin");
  EXPECT_EQ((*listed)[1].content, "");
  // The start-up sweep keeps only recorded files: the state in the store is not one.
  EXPECT_EQ(*store_->AllCheckpointPaths(), std::vector<std::filesystem::path>{"/x/ckpt-20.bin"});

  auto events = store_->ListEvents("a");
  ASSERT_TRUE(events.ok());
  std::vector<std::string> kinds;
  for (const JobEventRecord& e : *events) kinds.push_back(e.kind);
  EXPECT_EQ(kinds, (std::vector<std::string>{"SUBMITTED", "CLAIMED", "CHECKPOINT", "CHECKPOINT",
                                             "CHECKPOINT", "SUCCEEDED"}));
}

// Without a final state (checkpoints off) the success is recorded alone; deleting the job hands
// back its in-store record with no path, so no caller removes a file for it.
TEST_F(SuccessStore, WithoutAFinalStateAndOnDelete) {
  ASSERT_TRUE(store_->Insert(NewJob("a")).ok());
  ASSERT_TRUE(store_->Insert(NewJob("b")).ok());
  const std::int64_t epoch_a = Claim("a");
  ASSERT_TRUE(store_->RecordSuccess("a", epoch_a, Success(), nullptr, 3, 400).ok());
  EXPECT_EQ(store_->Get("a")->state, JobState::kSucceeded);
  EXPECT_TRUE(store_->ListCheckpoints("a")->empty());

  const std::int64_t epoch_b = Claim("b");
  CheckpointRecord final_state;
  final_state.step = 5;
  final_state.content = "bytes";
  ASSERT_TRUE(store_->RecordSuccess("b", epoch_b, Success(), &final_state, 3, 500).ok());
  auto removed = store_->Delete("b");
  ASSERT_TRUE(removed.ok()) << removed.status().ToString();
  ASSERT_EQ(removed->size(), 1u);
  EXPECT_EQ((*removed)[0].path, "");
}

// A stale lease, a metric that is not finite or a bad series column: an error, and the job is
// as it was (RUNNING, no checkpoint, no series, no metric, no event).
TEST_F(SuccessStore, WritesNothingWhenAnyPartIsRefused) {
  ASSERT_TRUE(store_->Insert(NewJob("a")).ok());
  const std::int64_t epoch = Claim("a");
  CheckpointRecord final_state;
  final_state.step = 30;
  final_state.content = "bytes";
  const std::size_t events_before = store_->ListEvents("a")->size();

  EXPECT_EQ(store_->RecordSuccess("a", epoch + 1, Success(), &final_state, 3, 400).status().code(),
            core::StatusCode::kAborted);
  RunSuccess nan_metric = Success();
  nan_metric.metrics.emplace_back("bad_metric", std::nan(""));
  const auto refused = store_->RecordSuccess("a", epoch, nan_metric, &final_state, 3, 400);
  EXPECT_EQ(refused.status().code(), core::StatusCode::kInvalidArgument);
  EXPECT_NE(refused.status().message().find("bad_metric"), std::string::npos)
      << refused.status().message();
  RunSuccess bad_column = Success();
  bad_column.series_columns[1] = "a,b";
  EXPECT_EQ(store_->RecordSuccess("a", epoch, bad_column, &final_state, 3, 400).status().code(),
            core::StatusCode::kInvalidArgument);

  auto job = store_->Get("a");
  ASSERT_TRUE(job.ok());
  EXPECT_EQ(job->state, JobState::kRunning);
  EXPECT_TRUE(job->metrics.empty());
  EXPECT_TRUE(job->series_columns.empty());
  EXPECT_TRUE(store_->ListCheckpoints("a")->empty());
  EXPECT_EQ(store_->ListEvents("a")->size(), events_before);
}

// The bytes a record holds are verified as a file's are: a flipped byte is DATA_LOSS naming the
// checkpoint as the store's.
TEST_F(SuccessStore, ARecordsBytesAreVerifiedAsAFilesAre) {
  CheckpointMeta meta;
  meta.job_id = "a";
  meta.step = 30;
  meta.time_s = 0.75;
  const std::string state(5000, '\x7f');
  CheckpointRecord record;
  record.step = 30;
  record.content = EncodeCheckpoint(meta, state);
  auto read = ReadCheckpoint(record);
  ASSERT_TRUE(read.ok()) << read.status().ToString();
  EXPECT_EQ(read->state, state);
  EXPECT_EQ(read->meta.step, 30u);

  record.content[record.content.size() / 2] ^= 0x01;
  const auto corrupt = ReadCheckpoint(record);
  EXPECT_EQ(corrupt.status().code(), core::StatusCode::kDataLoss);
  EXPECT_NE(corrupt.status().message().find("ckpt-000000000030.bin (in the store)"),
            std::string::npos)
      << corrupt.status().message();
}

// A durable success needs no sync of the window; a windowed one is synced by it, once.
TEST_F(SuccessStore, AWindowedSuccessIsSyncedByTheWindowAndADurableOneNeedsNone) {
  ASSERT_TRUE(store_->Insert(NewJob("durable")).ok());
  ASSERT_TRUE(store_->RecordSuccess("durable", Claim("durable"), Success(), nullptr, 1, 200).ok());
  EXPECT_FALSE(store_->WindowedCommitPending());
  EXPECT_EQ(store_->WindowedSyncs(), 0u);

  ASSERT_TRUE(store_->Insert(NewJob("windowed")).ok());
  ASSERT_TRUE(store_
                  ->RecordSuccess("windowed", Claim("windowed"), Success(), nullptr, 1, 300,
                                  CommitSync::kWindowed)
                  .ok());
  // Within JobStore::kDurabilityWindow; a minute allows for sanitizer builds on a busy machine.
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::minutes(1);
  while (store_->WindowedCommitPending() && std::chrono::steady_clock::now() < give_up) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  EXPECT_FALSE(store_->WindowedCommitPending());
  EXPECT_EQ(store_->WindowedSyncs(), 1u);
  EXPECT_EQ(store_->Get("windowed")->state, JobState::kSucceeded);
}

}  // namespace
}  // namespace seep::service
