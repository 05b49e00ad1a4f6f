#include "jobs/checkpoint_sweep.h"

#include <gtest/gtest.h>
#include <spdlog/sinks/ostream_sink.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "test_support.h"

namespace seep::service {
namespace {

namespace fs = std::filesystem;

TEST(CheckpointSweep, RemovesOrphansTempFilesAndEmptyFoldersAndKeepsRecordedFiles) {
  const fs::path dir = testing::FreshTestDir("sweep");
  auto store = JobStore::Open((dir / "seep.db").string());
  ASSERT_TRUE(store.ok()) << store.status().ToString();
  JobRecord job;
  job.id = "j-1";
  job.name = "n";
  job.scene = "s";
  ASSERT_TRUE((*store)->Insert(job).ok());
  const std::int64_t epoch = (*(*store)->ClaimNextQueued("w", 0, 1'000'000))->lease_epoch;
  const fs::path ckpt = dir / "checkpoints";
  fs::create_directories(ckpt / "j-1");
  fs::create_directories(ckpt / "j-gone");
  const auto touch = [](const fs::path& p, std::size_t bytes) {
    std::ofstream(p) << std::string(bytes, 'x');
  };
  touch(ckpt / "j-1" / "ckpt-000000000010.bin", 10);             // recorded
  touch(ckpt / "j-1" / "ckpt-000000000020.bin", 20);             // orphan
  touch(ckpt / "j-1" / "ckpt-000000000030.bin.tmp-Xy12Ab", 30);  // interrupted write
  touch(ckpt / "j-gone" / "ckpt-000000000040.bin", 40);          // a deleted job's file
  touch(dir / "seepd.log", 5);  // beside the checkpoint folder: never swept
  // As an older seepd left them: readable by others.
  fs::permissions(ckpt / "j-1" / "ckpt-000000000010.bin",
                  fs::perms::owner_read | fs::perms::owner_write | fs::perms::group_read |
                      fs::perms::others_read);
  fs::permissions(ckpt / "j-1", fs::perms::owner_all | fs::perms::group_read |
                                    fs::perms::group_exec | fs::perms::others_read |
                                    fs::perms::others_exec);
  fs::permissions(ckpt, fs::perms::owner_all | fs::perms::group_read | fs::perms::group_exec);
  CheckpointRecord kept;
  kept.step = 10;
  kept.path = (ckpt / "j-1" / "ckpt-000000000010.bin").string();
  ASSERT_TRUE((*store)->RecordCheckpoint("j-1", epoch, kept, 3).ok());

  std::ostringstream out;
  spdlog::logger log("test", std::make_shared<spdlog::sinks::ostream_sink_st>(out));
  auto counts = SweepCheckpointFolder(**store, ckpt, log);
  ASSERT_TRUE(counts.ok()) << counts.status().ToString();
  EXPECT_EQ(counts->orphan_files, 2);
  EXPECT_EQ(counts->temp_files, 1);
  EXPECT_EQ(counts->empty_folders, 1);
  EXPECT_EQ(counts->bytes, 90u);
  EXPECT_EQ(counts->failures, 0);
  EXPECT_EQ(counts->tightened, 3);  // the kept file, its folder, the checkpoint folder
  EXPECT_EQ(fs::status(ckpt / "j-1" / "ckpt-000000000010.bin").permissions() & fs::perms::all,
            fs::perms::owner_read | fs::perms::owner_write);
  EXPECT_EQ(fs::status(ckpt / "j-1").permissions() & fs::perms::all, fs::perms::owner_all);
  EXPECT_EQ(fs::status(ckpt).permissions() & fs::perms::all, fs::perms::owner_all);
  EXPECT_TRUE(fs::exists(ckpt / "j-1" / "ckpt-000000000010.bin"));
  EXPECT_FALSE(fs::exists(ckpt / "j-1" / "ckpt-000000000020.bin"));
  EXPECT_FALSE(fs::exists(ckpt / "j-1" / "ckpt-000000000030.bin.tmp-Xy12Ab"));
  EXPECT_FALSE(fs::exists(ckpt / "j-gone"));
  EXPECT_TRUE(fs::exists(dir / "seepd.log"));
  EXPECT_TRUE(fs::exists(dir / "seep.db"));
  EXPECT_NE(out.str().find("removed 2 orphan file(s) (no checkpoint record), 1 temporary file(s) "
                           "of interrupted writes, 1 empty folder(s); 90 bytes freed, 0 could "
                           "not be removed; 3 kept file(s) or folder(s) made private"),
            std::string::npos)
      << out.str();
  EXPECT_NE(out.str().find("removed checkpoints/j-1/ckpt-000000000020.bin: no checkpoint record"),
            std::string::npos)
      << out.str();

  // Nothing left to do: no files touched, no log line.
  std::ostringstream again_out;
  spdlog::logger quiet("test", std::make_shared<spdlog::sinks::ostream_sink_st>(again_out));
  auto again = SweepCheckpointFolder(**store, ckpt, quiet);
  ASSERT_TRUE(again.ok());
  EXPECT_EQ(again->orphan_files + again->temp_files + again->empty_folders + again->tightened, 0);
  EXPECT_TRUE(again_out.str().empty()) << again_out.str();
  store->reset();
  fs::remove_all(dir);
}

// A store with no job beside checkpoint files has lost its database: the sweep refuses, naming
// the files and the flag, and removes nothing (temporary files included); accepted, it moves each
// file whole to lost-checkpoints and removes only the temporary ones.
TEST(CheckpointSweep, AnEmptyStoreBesideCheckpointFilesRefusesUnlessTheLossIsAccepted) {
  const fs::path dir = testing::FreshTestDir("sweep-lost");
  auto store = JobStore::Open((dir / "seep.db").string());
  ASSERT_TRUE(store.ok()) << store.status().ToString();
  const fs::path ckpt = dir / "checkpoints";
  fs::create_directories(ckpt / "j-7");
  std::ofstream(ckpt / "j-7" / "ckpt-000000000010.bin") << "state";
  std::ofstream(ckpt / "j-7" / "ckpt-000000000020.bin.tmp-Ab12Cd") << "half";
  std::ostringstream out;
  spdlog::logger log("test", std::make_shared<spdlog::sinks::ostream_sink_st>(out));

  auto refused = SweepCheckpointFolder(**store, ckpt, log);
  ASSERT_EQ(refused.status().code(), core::StatusCode::kFailedPrecondition);
  for (const char* part :
       {"the store holds no job, but checkpoints holds 1 checkpoint file(s) "
        "(checkpoints/j-7/ckpt-000000000010.bin)",
        "Nothing was removed", "--accept-lost-database", "to move the files to lost-checkpoints"}) {
    EXPECT_NE(refused.status().message().find(part), std::string::npos)
        << part << " not in: " << refused.status().message();
  }
  EXPECT_TRUE(fs::exists(ckpt / "j-7" / "ckpt-000000000010.bin"));
  EXPECT_TRUE(fs::exists(ckpt / "j-7" / "ckpt-000000000020.bin.tmp-Ab12Cd"));

  auto accepted = SweepCheckpointFolder(**store, ckpt, log, /*accept_lost_database=*/true);
  ASSERT_TRUE(accepted.ok()) << accepted.status().ToString();
  EXPECT_EQ(accepted->lost_files, 1);
  EXPECT_EQ(accepted->orphan_files, 0);
  EXPECT_EQ(accepted->temp_files, 1);
  EXPECT_TRUE(fs::exists(dir / "lost-checkpoints" / "j-7" / "ckpt-000000000010.bin"));
  EXPECT_FALSE(fs::exists(ckpt / "j-7"));
  EXPECT_EQ(fs::status(dir / "lost-checkpoints").permissions() & fs::perms::all,
            fs::perms::owner_all);
  EXPECT_NE(out.str().find("checkpoints/j-7/ckpt-000000000010.bin moved to "
                           "lost-checkpoints/j-7/ckpt-000000000010.bin"),
            std::string::npos)
      << out.str();
  store->reset();
  fs::remove_all(dir);
}

}  // namespace
}  // namespace seep::service
