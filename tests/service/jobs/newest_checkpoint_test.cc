// LoadNewestCheckpoint, the one routine behind resume and GetJobFields: newest first, a damaged,
// foreign or unrestorable file is reported and passed over, and none usable is nullopt.
#include "jobs/newest_checkpoint.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "codec/scene_codec.h"
#include "codec/simulation_state_codec.h"
#include "test_support.h"

namespace seep::service {
namespace {

class NewestCheckpointTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = testing::FreshTestDir("newest");
    const v1::Scene scene = testing::ExampleScene("transient_1d.textproto");
    job_.id = "j-newest";
    ASSERT_TRUE(scene.SerializeToString(&job_.scene));
    auto spec = SceneFromProto(scene);
    ASSERT_TRUE(spec.ok()) << spec.status().ToString();
    spec_ = *spec;
    auto sim = core::Simulation::Create(spec_, nullptr);
    ASSERT_TRUE(sim.ok()) << sim.status().ToString();
    start_ = SerializeSimulationState(sim->TakeSnapshot());
    ASSERT_TRUE(sim->Run({}).ok());
    end_step_ = sim->step();
    ASSERT_GT(end_step_, 0u);
    end_ = SerializeSimulationState(sim->TakeSnapshot());
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  CheckpointRecord Write(std::uint64_t step, const std::string& state,
                         const std::string& job_id = "j-newest") {
    CheckpointRecord record;
    record.step = step;
    record.path = (dir_ / ("ckpt-" + std::to_string(step) + ".bin")).string();
    CheckpointMeta meta;
    meta.build_id = "test";
    meta.job_id = job_id;
    meta.scene_sha256 = Sha256(job_.scene);
    meta.step = step;
    EXPECT_TRUE(WriteCheckpointFile(record.path, meta, state).ok());
    return record;
  }

  core::Simulation Fresh() {
    auto sim = core::Simulation::Create(spec_, nullptr);
    EXPECT_TRUE(sim.ok());
    return std::move(*sim);
  }

  std::filesystem::path dir_;
  JobRecord job_;
  core::SceneSpec spec_;
  std::string start_, end_;
  std::uint64_t end_step_ = 0;
};

TEST_F(NewestCheckpointTest, TakesTheNewestThatVerifies) {
  const std::vector<CheckpointRecord> records = {Write(end_step_, end_), Write(0, start_)};
  core::Simulation sim = Fresh();
  int skipped = 0;
  const auto restored =
      LoadNewestCheckpoint(job_, records, sim, [&](const SkippedCheckpoint&) { ++skipped; });
  ASSERT_TRUE(restored.has_value());
  EXPECT_EQ(&restored->record, &records[0]);
  EXPECT_EQ(restored->meta.build_id, "test");
  EXPECT_EQ(sim.step(), end_step_);
  EXPECT_EQ(skipped, 0);
}

TEST_F(NewestCheckpointTest, PassesOverADamagedAndAForeignFileWithTheirReasons) {
  const std::vector<CheckpointRecord> records = {Write(end_step_ + 1, end_, "j-other"),
                                                 Write(end_step_, end_), Write(0, start_)};
  {
    std::ifstream in(records[1].path, std::ios::binary);
    std::stringstream bytes;
    bytes << in.rdbuf();
    const std::string full = bytes.str();
    std::ofstream(records[1].path, std::ios::binary | std::ios::trunc)
        << full.substr(0, full.size() - 10);  // truncated by a crash
  }
  core::Simulation sim = Fresh();
  std::vector<std::pair<std::uint64_t, core::Status>> skips;
  std::vector<bool> foreign;
  const auto restored = LoadNewestCheckpoint(job_, records, sim, [&](const SkippedCheckpoint& s) {
    skips.emplace_back(s.record.step, s.why);
    foreign.push_back(s.foreign);
  });
  ASSERT_TRUE(restored.has_value());
  EXPECT_EQ(restored->record.step, 0u);
  EXPECT_EQ(sim.step(), 0u);
  ASSERT_EQ(skips.size(), 2u);
  EXPECT_EQ(skips[0].first, end_step_ + 1);
  EXPECT_TRUE(foreign[0]);
  EXPECT_EQ(skips[0].second.code(), core::StatusCode::kDataLoss);
  EXPECT_EQ(skips[1].first, end_step_);
  EXPECT_FALSE(foreign[1]);
  EXPECT_EQ(skips[1].second.code(), core::StatusCode::kDataLoss);
  EXPECT_NE(skips[1].second.message().find("ckpt-" + std::to_string(end_step_) + ".bin"),
            std::string::npos)
      << skips[1].second.ToString();
}

TEST_F(NewestCheckpointTest, NoneUsableIsNulloptAfterReportingEach) {
  const std::vector<CheckpointRecord> records = {Write(1, "not a state"), Write(0, start_)};
  std::ofstream(records[1].path, std::ios::trunc) << "garbage";
  core::Simulation sim = Fresh();
  int skipped = 0;
  EXPECT_FALSE(
      LoadNewestCheckpoint(job_, records, sim, [&](const SkippedCheckpoint&) { ++skipped; }));
  EXPECT_EQ(skipped, 2);
  EXPECT_EQ(sim.step(), 0u);
}

}  // namespace
}  // namespace seep::service
