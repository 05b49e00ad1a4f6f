// A lost database through the real seepd (jobs/checkpoint_sweep.h): with seep.db deleted while a
// job had checkpoints, seepd refuses to start, naming the files and the flag, and removes
// nothing (it used to start on an empty store and sweep every file away as an orphan, the running
// job's included); with --accept-lost-database it moves them to lost-checkpoints and serves; with
// --recover-from-checkpoints it rebuilds the jobs from the files (which carry their scenes), and
// they end with the hashes of their uninterrupted runs.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <thread>

#include "grpc_seepd_fixture.h"
#include "store/durable_files.h"

namespace seep::testing {
namespace {

namespace fs = std::filesystem;

class LostDatabase : public GrpcSeepdTest {
 protected:
  LostDatabase() : GrpcSeepdTest("e2e-lost-db") {}
};

// The checkpoint files under `root` (temporary files of interrupted writes aside), relative to it.
std::set<fs::path> StateFiles(const fs::path& root) {
  std::set<fs::path> files;
  std::error_code ec;
  for (auto it = fs::recursive_directory_iterator(root, ec);
       !ec && it != fs::recursive_directory_iterator(); it.increment(ec)) {
    if (it->is_regular_file() && !service::IsTempFileName(it->path().filename().string())) {
      files.insert(it->path().lexically_relative(root));
    }
  }
  return files;
}

TEST_F(LostDatabase, AnEmptyStoreBesideCheckpointsRefusesToStartAndRemovesNothing) {
  Start("data", {"--checkpoint-interval-s", "0.2"});
  const std::string id = Submit(LatticeScene("held", 4e-2));
  const fs::path checkpoints = dir_ / "data" / "checkpoints";
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (StateFiles(checkpoints / id).empty() && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  ASSERT_FALSE(StateFiles(checkpoints / id).empty()) << "the job wrote no checkpoint";
  server_.Stop(SIGKILL);  // a crash: the running job's checkpoints are its only state
  const std::set<fs::path> before = StateFiles(checkpoints);
  for (const char* file : {"seep.db", "seep.db-wal", "seep.db-shm"}) {
    fs::remove(dir_ / "data" / file);
  }

  const std::string port_file = (dir_ / "refused.port").string();
  std::vector<std::string> argv = SeepdArgv("data", port_file);
  argv.insert(argv.begin(), {"/usr/bin/timeout", "60"});
  const CommandResult refused = RunCommand(argv);
  EXPECT_EQ(refused.exit_code, 65) << refused.output;
  for (const std::string& part :
       {std::string("the store holds no job, but checkpoints holds "), "checkpoints/" + id + "/",
        std::string("Nothing was removed"), std::string("--accept-lost-database")}) {
    EXPECT_NE(refused.output.find(part), std::string::npos)
        << part << " not in: " << refused.output;
  }
  EXPECT_FALSE(fs::exists(port_file));
  EXPECT_EQ(StateFiles(checkpoints), before);

  // Accepted: every file moves, whole, to lost-checkpoints, and seepd serves on an empty store.
  Start("data", {"--accept-lost-database"});
  EXPECT_EQ(StateFiles(dir_ / "data" / "lost-checkpoints"), before);
  EXPECT_TRUE(StateFiles(checkpoints).empty());
  const v1::Job next = WaitTerminal(Submit(LatticeScene("after-the-loss", 4e-3)));
  EXPECT_EQ(next.state(), v1::JOB_STATE_SUCCEEDED) << next.DebugString();
}

// The recovery command: seep.db lost after a crash with one job finished and one running; the
// files alone rebuild both, under their ids, and both end bit-identical to their uninterrupted
// runs (the finished one at once, from its final state). A folder nothing can be rebuilt from
// moves to lost-checkpoints, whole. On a store that holds jobs, recovery is refused.
TEST_F(LostDatabase, RecoveryFromCheckpointsRebuildsTheJobsWhichEndBitIdentical) {
  const v1::Scene running_scene = LatticeScene("running", 2e-2);
  const v1::Scene finished_scene = LatticeScene("finished", 2e-3);
  const std::vector<std::string> expected = ReferenceHashes(
      {running_scene, finished_scene}, {"--workers", "2", "--threads-per-job", "1"});
  Start("data", {"--workers", "2", "--threads-per-job", "1", "--checkpoint-every-steps", "500"});
  const std::string running = Submit(running_scene);
  const std::string finished = Submit(finished_scene);
  ASSERT_EQ(WaitTerminal(finished).state(), v1::JOB_STATE_SUCCEEDED);
  const fs::path checkpoints = dir_ / "data" / "checkpoints";
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (StateFiles(checkpoints / running).size() < 2 &&
         std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ASSERT_GE(StateFiles(checkpoints / running).size(), 2u) << "the job wrote no checkpoints";
  server_.Stop(SIGKILL);
  for (const char* file : {"seep.db", "seep.db-wal", "seep.db-shm"}) {
    fs::remove(dir_ / "data" / file);
  }
  // A job folder with nothing to rebuild from.
  fs::create_directories(checkpoints / "j-00000000000000ff");
  std::ofstream(checkpoints / "j-00000000000000ff" / "ckpt-000000000100.bin") << "not a checkpoint";

  Start("data", {"--workers", "2", "--threads-per-job", "1", "--recover-from-checkpoints"});
  ExpectBitIdenticalToUninterrupted({running, finished}, expected,
                                    "rebuilt from its checkpoint files after seep.db was lost");
  for (const std::string& id : {running, finished}) {
    const auto events = Events(id);
    EXPECT_TRUE(std::any_of(events.begin(), events.end(), [](const auto& e) {
      return e.kind() == "REBUILT";
    })) << id;
  }
  EXPECT_EQ(Get(running).name(), "running");
  EXPECT_TRUE(fs::exists(dir_ / "data" / "lost-checkpoints" / "j-00000000000000ff" /
                         "ckpt-000000000100.bin"));
  stub_.reset();
  ASSERT_EQ(server_.Stop(SIGTERM), 0);

  const std::string port_file = (dir_ / "refused.port").string();
  std::vector<std::string> argv = SeepdArgv("data", port_file);
  argv.insert(argv.begin(), {"/usr/bin/timeout", "60"});
  argv.push_back("--recover-from-checkpoints");
  const CommandResult refused = RunCommand(argv);
  EXPECT_EQ(refused.exit_code, 65) << refused.output;
  EXPECT_NE(refused.output.find("recovery only fills an empty store"), std::string::npos)
      << refused.output;
}

}  // namespace
}  // namespace seep::testing
