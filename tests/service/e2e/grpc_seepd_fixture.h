// A real seepd (re)started on a data folder of a scratch directory and driven through a gRPC
// stub: what the crash-recovery and self-healing e2e tests share.
#pragma once

#include <google/protobuf/text_format.h>
#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "file_text.h"
#include "process.h"
#include "seep/v1/job_service.grpc.pb.h"

namespace seep::testing {

// An explicit transient on a square lattice: a few seconds of steps with progress all along
// (1e-2 s of simulated time is a few thousand steps).
inline v1::Scene LatticeScene(const std::string& name, double end_time_s) {
  v1::Scene scene;
  EXPECT_TRUE(google::protobuf::TextFormat::ParseFromString(
      R"pb(
        packing { lattice { kind: LATTICE_KIND_SQUARE columns: 80 rows: 50 radius_m: 1e-3 } }
        fluid { viscosity_pa_s: 1e-3 bulk_modulus_pa: 2.2e9 }
        aperture { residual_aperture_m: 1e-5 reference_force_n: 1e3 gap_multiplier: 0.5 }
        boundary { axis: FLOW_AXIS_X inlet_pressure_pa: 1e5 }
        solver { kind: SOLVER_KIND_EXPLICIT storage: STORAGE_VOLUME_PORE dt_factor: 0.9 }
      )pb",
      &scene));
  scene.set_name(name);
  scene.mutable_solver()->set_end_time_s(end_time_s);
  return scene;
}

// How many times `what` occurs in `text`.
inline std::size_t Count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

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

  // A deadline 10 s away, and the bearer token when the test set one (token_).
  void Prepare(grpc::ClientContext& ctx) const {
    ctx.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(10));
    if (!token_.empty()) ctx.AddMetadata("authorization", "Bearer " + token_);
  }

  // The submit's status, the job in `response` when it is OK.
  grpc::Status TrySubmit(const v1::Scene& scene, v1::SubmitJobResponse& response) {
    grpc::ClientContext ctx;
    Prepare(ctx);
    v1::SubmitJobRequest request;
    *request.mutable_scene() = scene;
    return stub_->SubmitJob(&ctx, request, &response);
  }
  std::string Submit(const v1::Scene& scene) {
    v1::SubmitJobResponse response;
    const grpc::Status status = TrySubmit(scene, response);
    EXPECT_TRUE(status.ok()) << status.error_message();
    return response.job().id();
  }

  v1::Job Get(const std::string& id) {
    grpc::ClientContext ctx;
    Prepare(ctx);
    v1::GetJobRequest request;
    request.set_id(id);
    v1::GetJobResponse response;
    const grpc::Status status = stub_->GetJob(&ctx, request, &response);
    EXPECT_TRUE(status.ok()) << status.error_message();
    return response.job();
  }

  // A sweep submitted in one request (30 s deadline); its status with the jobs by position.
  v1::SweepStatus SubmitSweep(const v1::Sweep& sweep) {
    grpc::ClientContext ctx;
    Prepare(ctx);
    ctx.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(30));
    v1::SubmitSweepRequest request;
    *request.mutable_sweep() = sweep;
    v1::SubmitSweepResponse response;
    const grpc::Status status = stub_->SubmitSweep(&ctx, request, &response);
    EXPECT_TRUE(status.ok()) << status.error_message();
    return response.sweep();
  }

  // The ids of a sweep's jobs, by position.
  static std::vector<std::string> JobIds(const v1::SweepStatus& sweep) {
    std::vector<std::string> ids;
    for (const v1::SweepJob& member : sweep.jobs()) ids.push_back(member.job().id());
    return ids;
  }

  // The job's history, oldest first (up to 1000 events).
  std::vector<v1::JobHistoryEvent> Events(const std::string& id) {
    grpc::ClientContext ctx;
    Prepare(ctx);
    v1::ListJobEventsRequest request;
    request.set_id(id);
    request.set_page_size(1000);
    v1::ListJobEventsResponse response;
    const grpc::Status status = stub_->ListJobEvents(&ctx, request, &response);
    EXPECT_TRUE(status.ok()) << status.error_message();
    return {response.events().begin(), response.events().end()};
  }

  // Polls the job until `done` holds for it or the timeout passes; returns it as last seen.
  v1::Job WaitFor(const std::string& id, const std::function<bool(const v1::Job&)>& done,
                  std::chrono::seconds timeout = std::chrono::seconds(240)) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    for (;;) {
      v1::Job job = Get(id);
      if (done(job) || std::chrono::steady_clock::now() > deadline) return job;
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
  }
  v1::Job WaitTerminal(const std::string& id) {
    return WaitFor(id, [](const v1::Job& j) { return IsTerminalState(j.state()); });
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
  std::string token_;  // sent with every call when set (a seepd started with --token-file)

 private:
  std::string prefix_;
};

}  // namespace seep::testing
