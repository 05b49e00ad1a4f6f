// A full disk through the real seepd (store/free_space.h). A running job whose checkpoint finds the
// data folder's file system below --min-free-disk-mb fails, naming the free space and the flag,
// and resumes from its newest checkpoint once space is freed; submits are refused with
// RESOURCE_EXHAUSTED saying the same; reads go on; the WAL gives its space back. A seepd started
// on a full disk serves read-only (it used to refuse to start: "recovery failed: disk full") and
// recovers the interrupted job once space is back, without a restart.
//
// The disk is made "full" without filling one: the threshold set above what the file system has,
// or the free space read from a file the test writes (--test-free-disk-bytes-file).
#include <gtest/gtest.h>

#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>

#include "grpc_seepd_fixture.h"

namespace seep::testing {
namespace {

namespace fs = std::filesystem;

class DiskFull : public GrpcSeepdTest {
 protected:
  DiskFull() : GrpcSeepdTest("e2e-disk-full") {}

  void SetFree(std::uint64_t bytes) const { std::ofstream(FreeFile()) << bytes; }
  std::string FreeFile() const { return (dir_ / "free-bytes").string(); }

  // Polls the job's events until one of `kind` is there (the timeout passed: the test fails).
  void WaitForEvent(const std::string& id, const std::string& kind) {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (std::chrono::steady_clock::now() < deadline) {
      for (const v1::JobHistoryEvent& event : Events(id)) {
        if (event.kind() == kind) return;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    ADD_FAILURE() << "no " << kind << " event for job " << id;
  }

  grpc::Status SubmitRefused(const v1::Scene& scene) {
    v1::SubmitJobResponse response;
    return TrySubmit(scene, response);
  }

  grpc::Status Resume(const std::string& id) {
    grpc::ClientContext ctx;
    Prepare(ctx);
    v1::ResumeJobRequest request;
    request.set_id(id);
    v1::ResumeJobResponse response;
    return stub_->ResumeJob(&ctx, request, &response);
  }

  int ListedJobs() {
    grpc::ClientContext ctx;
    Prepare(ctx);
    v1::ListJobsRequest request;
    v1::ListJobsResponse response;
    EXPECT_TRUE(stub_->ListJobs(&ctx, request, &response).ok());
    return response.jobs_size();
  }
};

void ExpectNamed(const std::string& text, const std::vector<std::string>& parts) {
  for (const std::string& part : parts) {
    EXPECT_NE(text.find(part), std::string::npos) << part << " not in: " << text;
  }
}

TEST_F(DiskFull, ARunningJobFailsAtItsCheckpointNamingTheSpaceAndResumesOnceFreed) {
  SetFree(10ull << 30);
  Start("data", {"--checkpoint-interval-s", "0.2", "--test-free-disk-bytes-file", FreeFile()});
  const std::string id = Submit(LatticeScene("filling", 0.2));
  WaitForEvent(id, "CHECKPOINT");

  SetFree(10u << 20);  // 10 MiB: below the default 256
  const v1::Job failed = WaitTerminal(id);
  ASSERT_EQ(failed.state(), v1::JOB_STATE_FAILED) << failed.DebugString();
  EXPECT_EQ(failed.error().code(), "RESOURCE_EXHAUSTED");
  ExpectNamed(failed.error().message(),
              {"disk full", "10.0 MiB free", "--min-free-disk-mb 256", "seep resume"});
  bool checkpoint_failed = false;
  for (const v1::JobHistoryEvent& event : Events(id)) {
    checkpoint_failed =
        checkpoint_failed || (event.kind() == "CHECKPOINT_FAILED" &&
                              event.message().find("disk full") != std::string::npos);
  }
  EXPECT_TRUE(checkpoint_failed) << "no CHECKPOINT_FAILED event naming the full disk";

  const grpc::Status refused = SubmitRefused(LatticeScene("refused", 1e-3));
  EXPECT_EQ(refused.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED) << refused.error_message();
  ExpectNamed(refused.error_message(), {"disk full", "10.0 MiB free", "--min-free-disk-mb 256"});
  EXPECT_EQ(ListedJobs(), 1);  // nothing stored for the refusal; reads answered

  // seepd's own files stop growing: the WAL gives its space back.
  const fs::path wal = dir_ / "data" / "seep.db-wal";
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (fs::file_size(wal) > 0 && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  EXPECT_EQ(fs::file_size(wal), 0u) << "the WAL kept its space on a full disk";

  SetFree(10ull << 30);  // space freed: the job continues from its newest checkpoint
  ASSERT_TRUE(Resume(id).ok());
  const v1::Job resumed = WaitTerminal(id);
  EXPECT_EQ(resumed.state(), v1::JOB_STATE_SUCCEEDED) << resumed.DebugString();
  WaitForEvent(id, "RESUMED");
}

TEST_F(DiskFull, ASeepdStartedOnAFullDiskServesReadsRefusesSubmitsAndRecoversOnceFreed) {
  Start("data", {"--checkpoint-interval-s", "0.2"});
  const std::string done = Submit(LatticeScene("done", 1e-3));
  ASSERT_EQ(WaitTerminal(done).state(), v1::JOB_STATE_SUCCEEDED);
  const std::string interrupted = Submit(LatticeScene("interrupted", 0.2));
  WaitForEvent(interrupted, "CHECKPOINT");
  server_.Stop(SIGKILL);

  // A threshold above what the file system has: the disk is full as far as seepd can tell.
  Start("data", {"--min-free-disk-mb", "1000000000"});
  const v1::Job finished = Get(done);
  EXPECT_EQ(finished.state(), v1::JOB_STATE_SUCCEEDED);
  EXPECT_EQ(finished.result().state_sha256().size(), 64u);
  EXPECT_TRUE(finished.held_reason().empty());
  EXPECT_EQ(ListedJobs(), 2);
  EXPECT_FALSE(Events(interrupted).empty());
  const v1::Job held = Get(interrupted);
  EXPECT_EQ(held.state(), v1::JOB_STATE_RUNNING);  // its recovery waits for space
  ExpectNamed(held.held_reason(), {"disk full", "--min-free-disk-mb 1000000000"});
  const grpc::Status refused = SubmitRefused(LatticeScene("refused", 1e-3));
  EXPECT_EQ(refused.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED) << refused.error_message();
  ExpectNamed(refused.error_message(), {"disk full", "--min-free-disk-mb 1000000000"});
  // `seep show` says why the job does not go on.
  const std::string port = ReadFile(dir_ / "data.port");
  const CommandResult shown =
      RunCommand({SEEP_CLI_PATH, "--server", "127.0.0.1:" + port.substr(0, port.find('\n')), "show",
                  interrupted});
  EXPECT_EQ(shown.exit_code, 0) << shown.output;
  ExpectNamed(shown.output, {"held      disk full", "--min-free-disk-mb 1000000000"});
  stub_.reset();
  EXPECT_EQ(server_.Stop(SIGTERM), 0);

  // Started low again, then space is freed: the interrupted job is recovered and finishes, with
  // no restart.
  SetFree(1u << 20);
  Start("data", {"--test-free-disk-bytes-file", FreeFile()});
  EXPECT_EQ(Get(interrupted).state(), v1::JOB_STATE_RUNNING);
  SetFree(10ull << 30);
  const v1::Job recovered = WaitTerminal(interrupted);
  EXPECT_EQ(recovered.state(), v1::JOB_STATE_SUCCEEDED) << recovered.DebugString();
  EXPECT_TRUE(recovered.held_reason().empty());
}

}  // namespace
}  // namespace seep::testing
