// StoreLedger::RecordSuccess: a small final state goes into the success's own record (no folder,
// no file); one above kStoredCheckpointMaxBytes goes to its file first. Either way a resume or an
// export finds it where NewestCheckpoint looks, verified.
#include "jobs/store_ledger.h"

#include <gtest/gtest.h>
#include <spdlog/sinks/null_sink.h>

#include <filesystem>
#include <fstream>
#include <optional>
#include <string>

#include "store/job_store.h"
#include "test_support.h"

namespace seep::service {
namespace {

class StoreLedgerSuccess : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = testing::FreshTestDir("store-ledger-success");
    auto store = JobStore::Open((dir_ / "seep.db").string());
    ASSERT_TRUE(store.ok()) << store.status().ToString();
    store_ = std::move(*store);
    ledger_.emplace(
        *store_, dir_ / "checkpoints",
        std::make_shared<spdlog::logger>("test", std::make_shared<spdlog::sinks::null_sink_mt>()));
    JobRecord job;
    job.id = "j-1";
    job.name = "n";
    job.scene = "scene bytes";
    ASSERT_TRUE(store_->Insert(job).ok());
    auto claimed = ledger_->Claim("w", std::chrono::minutes(5));
    ASSERT_TRUE(claimed.ok() && claimed->has_value());
    job_ = **claimed;
  }

  // Records the run's success with a final state of `state_bytes` bytes at step 40.
  FinalStateKept Succeed(std::size_t state_bytes) {
    state_ = std::string(state_bytes, '\0');
    for (std::size_t i = 0; i < state_.size(); ++i) state_[i] = static_cast<char>(i * 7919 % 251);
    FinalState final_state;
    final_state.meta.build_id = "test";
    final_state.meta.job_id = job_.id;
    final_state.meta.scene_sha256 = Sha256(job_.scene);
    final_state.meta.step = 40;
    final_state.state = state_;
    final_state.keep = 3;
    RunSuccess run;
    run.series_columns = {"time_s"};
    run.series_values = {0.0};
    auto kept = ledger_->RecordSuccess(job_, job_.lease_epoch, final_state, run);
    EXPECT_TRUE(kept.ok()) << kept.status().ToString();
    return kept.ok() ? *kept : FinalStateKept{};
  }

  // The state a resume (or an export) would get: the newest checkpoint, verified.
  std::string NewestState() {
    auto fetched = ledger_->NewestCheckpoint(job_, std::nullopt);
    EXPECT_TRUE(fetched.ok() && fetched->has_value());
    return fetched.ok() && fetched->has_value() ? (*fetched)->state : "";
  }

  std::filesystem::path dir_;
  std::unique_ptr<JobStore> store_;
  std::optional<StoreLedger> ledger_;
  JobRecord job_;
  std::string state_;
};

TEST_F(StoreLedgerSuccess, ASmallFinalStateIsKeptInItsRecord) {
  const FinalStateKept kept = Succeed(23'000);
  ASSERT_TRUE(kept.bytes.has_value());
  EXPECT_TRUE(kept.failure.ok());
  EXPECT_FALSE(std::filesystem::exists(dir_ / "checkpoints"));  // no folder, no file
  auto records = store_->ListCheckpoints(job_.id);
  ASSERT_EQ(records->size(), 1u);
  EXPECT_EQ((*records)[0].path, "");
  EXPECT_EQ((*records)[0].bytes, *kept.bytes);
  EXPECT_EQ(static_cast<std::int64_t>((*records)[0].content.size()), *kept.bytes);
  EXPECT_EQ(store_->Get(job_.id)->state, JobState::kSucceeded);
  EXPECT_EQ(NewestState(), state_);
}

TEST_F(StoreLedgerSuccess, ALargeFinalStateIsKeptInItsFile) {
  const FinalStateKept kept = Succeed(kStoredCheckpointMaxBytes + 1);
  ASSERT_TRUE(kept.bytes.has_value());
  auto records = store_->ListCheckpoints(job_.id);
  ASSERT_EQ(records->size(), 1u);
  EXPECT_EQ((*records)[0].content, "");
  EXPECT_EQ(std::filesystem::path((*records)[0].path),
            dir_ / "checkpoints" / job_.id / "ckpt-000000000040.bin");
  EXPECT_EQ(static_cast<std::int64_t>(std::filesystem::file_size((*records)[0].path)), *kept.bytes);
  EXPECT_EQ(NewestState(), state_);
}

// A large final state whose file cannot be written (a file stands where its folder goes): the
// success is recorded without it, with a CHECKPOINT_FAILED event naming the step, and the
// failure is returned for the runner's log.
TEST_F(StoreLedgerSuccess, AFinalStateThatCannotBeWrittenLeavesTheSuccessStanding) {
  std::ofstream(dir_ / "checkpoints") << "not a folder";
  const FinalStateKept kept = Succeed(kStoredCheckpointMaxBytes + 1);
  EXPECT_FALSE(kept.bytes.has_value());
  EXPECT_FALSE(kept.failure.ok());
  EXPECT_EQ(store_->Get(job_.id)->state, JobState::kSucceeded);
  EXPECT_TRUE(store_->ListCheckpoints(job_.id)->empty());
  auto events = store_->ListEvents(job_.id);
  ASSERT_TRUE(events.ok());
  bool failed_event = false;
  for (const JobEventRecord& e : *events) {
    failed_event =
        failed_event || (e.kind == "CHECKPOINT_FAILED" && e.message.rfind("step 40: ", 0) == 0);
  }
  EXPECT_TRUE(failed_event);
}

}  // namespace
}  // namespace seep::service
