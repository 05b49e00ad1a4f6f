// A real seepd (re)started on a data folder of a scratch directory and driven through a gRPC
// stub: what the crash-recovery and self-healing e2e tests share.
#pragma once

#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "process.h"
#include "seep/v1/job_service.grpc.pb.h"

namespace seep::testing {

inline bool IsTerminalState(v1::JobState state) {
  return state == v1::JOB_STATE_SUCCEEDED || state == v1::JOB_STATE_FAILED ||
         state == v1::JOB_STATE_CANCELLED;
}

class GrpcSeepdTest : public ::testing::Test {
 protected:
  // prefix names the scratch directory: <temp>/seep-<prefix>-<pid>-<test name>.
  explicit GrpcSeepdTest(std::string prefix) : prefix_(std::move(prefix)) {}

  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("seep-" + prefix_ + "-" + std::to_string(::getpid()) + "-" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override {
    stub_.reset();
    if (server_.running()) server_.Stop(SIGTERM);
    if (!HasFailure()) std::filesystem::remove_all(dir_);
  }

  // seepd's command line on data folder `data`, writing its port to port_file.
  std::vector<std::string> SeepdArgv(const std::string& data, const std::string& port_file) const {
    return {SEEPD_PATH,    "--listen", "127.0.0.1:0", "--data-dir", (dir_ / data).string(),
            "--port-file", port_file};
  }

  // (Re)starts seepd on data folder `data` with the given extra flags; its output is appended
  // to <data>.out.
  void Start(const std::string& data, const std::vector<std::string>& extra) {
    stub_.reset();
    const std::string port_file = (dir_ / (data + ".port")).string();
    std::filesystem::remove(port_file);
    std::vector<std::string> argv = SeepdArgv(data, port_file);
    argv.insert(argv.end(), extra.begin(), extra.end());
    server_ = ChildProcess(argv, (dir_ / (data + ".out")).string());
    const int port = WaitForPortFile(port_file, std::chrono::seconds(30));
    ASSERT_GT(port, 0) << "seepd did not start; see " << (dir_ / (data + ".out"));
    stub_ = v1::SeepService::NewStub(grpc::CreateChannel("127.0.0.1:" + std::to_string(port),
                                                         grpc::InsecureChannelCredentials()));
  }

  std::string Submit(const v1::Scene& scene) {
    grpc::ClientContext ctx;
    ctx.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(10));
    v1::SubmitJobRequest request;
    *request.mutable_scene() = scene;
    v1::SubmitJobResponse response;
    const grpc::Status status = stub_->SubmitJob(&ctx, request, &response);
    EXPECT_TRUE(status.ok()) << status.error_message();
    return response.job().id();
  }

  v1::Job Get(const std::string& id) {
    grpc::ClientContext ctx;
    ctx.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(10));
    v1::GetJobRequest request;
    request.set_id(id);
    v1::GetJobResponse response;
    const grpc::Status status = stub_->GetJob(&ctx, request, &response);
    EXPECT_TRUE(status.ok()) << status.error_message();
    return response.job();
  }

  // Polls until every job is terminal or the timeout passes; returns them by id.
  std::map<std::string, v1::Job> WaitAllTerminal(const std::vector<std::string>& ids,
                                                 std::chrono::seconds timeout) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    std::map<std::string, v1::Job> jobs;
    for (;;) {
      bool all = true;
      for (const auto& id : ids) {
        jobs[id] = Get(id);
        all = all && IsTerminalState(jobs[id].state());
      }
      if (all || std::chrono::steady_clock::now() > deadline) return jobs;
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
  }

  // The scenes run once without interruption on a fresh data folder `data`: the expected
  // final-state hashes, in the order of the scenes. seepd is stopped afterwards.
  std::vector<std::string> ReferenceHashes(const std::vector<v1::Scene>& scenes,
                                           const std::vector<std::string>& flags = {"--workers",
                                                                                    "2"},
                                           const std::string& data = "reference") {
    Start(data, flags);
    std::vector<std::string> ids;
    for (const auto& s : scenes) ids.push_back(Submit(s));
    auto jobs = WaitAllTerminal(ids, std::chrono::seconds(300));
    std::vector<std::string> hashes;
    for (const auto& id : ids) {
      EXPECT_EQ(jobs[id].state(), v1::JOB_STATE_SUCCEEDED) << jobs[id].DebugString();
      EXPECT_EQ(jobs[id].result().state_sha256().size(), 64u);
      hashes.push_back(jobs[id].result().state_sha256());
    }
    stub_.reset();
    EXPECT_EQ(server_.Stop(SIGTERM), 0);
    return hashes;
  }

  // Waits for the jobs, then expects each SUCCEEDED with the hash of its uninterrupted run
  // (`expected`, in the order of `ids`); `how` says what interrupted them, for the message.
  void ExpectBitIdenticalToUninterrupted(const std::vector<std::string>& ids,
                                         const std::vector<std::string>& expected,
                                         const std::string& how) {
    auto jobs = WaitAllTerminal(ids, std::chrono::seconds(300));
    for (std::size_t i = 0; i < ids.size(); ++i) {
      const v1::Job& job = jobs[ids[i]];
      ASSERT_EQ(job.state(), v1::JOB_STATE_SUCCEEDED) << job.DebugString();
      EXPECT_EQ(job.result().state_sha256(), expected[i])
          << job.name() << ": final state differs from the uninterrupted run (" << how << ")";
    }
  }

  std::filesystem::path dir_;
  ChildProcess server_;
  std::unique_ptr<v1::SeepService::Stub> stub_;

 private:
  std::string prefix_;
};

}  // namespace seep::testing
