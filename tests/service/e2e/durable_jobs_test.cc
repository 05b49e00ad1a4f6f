// Durable jobs end to end through the real binaries: cancel, resume, results, list filters,
// idempotent submission and rejected scenes, against a seepd on a free loopback port. The seep
// CLI drives the user-facing paths; a gRPC stub checks exact status codes and messages.
#include <google/protobuf/text_format.h>
#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <functional>
#include <limits>
#include <nlohmann/json.hpp>
#include <regex>
#include <thread>

#include "bad_scenes.h"
#include "file_text.h"
#include "process.h"
#include "seep/v1/job_service.grpc.pb.h"

namespace seep::testing {
namespace {

// A transient run that lasts far longer than any test: 200 x 200 disks, explicit solver.
constexpr const char* kLongScene = R"pb(
  name: "long-explicit"
  packing { lattice { kind: LATTICE_KIND_SQUARE columns: 200 rows: 200 radius_m: 1e-3 } }
  fluid { viscosity_pa_s: 1e-3 bulk_modulus_pa: 2.2e9 }
  aperture { residual_aperture_m: 1e-5 reference_force_n: 1e3 gap_multiplier: 0.5 }
  boundary { axis: FLOW_AXIS_X inlet_pressure_pa: 1e5 }
  solver { kind: SOLVER_KIND_EXPLICIT storage: STORAGE_VOLUME_PORE dt_factor: 0.9 end_time_s: 1e6 }
)pb";

// A small steady scene that finishes in well under a second.
constexpr const char* kQuickScene = R"pb(
  name: "quick-steady"
  packing { lattice { kind: LATTICE_KIND_SQUARE columns: 12 rows: 8 radius_m: 1e-3 } }
  fluid { viscosity_pa_s: 1e-3 bulk_modulus_pa: 2.2e9 }
  aperture { residual_aperture_m: 1e-5 reference_force_n: 1e3 gap_multiplier: 0.5 }
  boundary { axis: FLOW_AXIS_X inlet_pressure_pa: 1e5 }
  solver { kind: SOLVER_KIND_STEADY }
)pb";

v1::Scene SceneFromText(const char* text) {
  v1::Scene scene;
  EXPECT_TRUE(google::protobuf::TextFormat::ParseFromString(text, &scene));
  return scene;
}

class DurableJobs : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("seep-e2e-jobs-" + std::to_string(::getpid()) + "-" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
    server_ = StartSeepd("seepd", &address_);
    ASSERT_FALSE(address_.empty()) << "seepd did not start; see " << (dir_ / "seepd.out");
    stub_ =
        v1::SeepService::NewStub(grpc::CreateChannel(address_, grpc::InsecureChannelCredentials()));
  }

  // A seepd with one worker on the shared data folder; its output goes to <tag>.out. Sets
  // *address, or leaves it empty when the server did not start.
  ChildProcess StartSeepd(const std::string& tag, std::string* address) {
    const std::string port_file = (dir_ / (tag + ".port")).string();
    ChildProcess process({SEEPD_PATH, "--listen", "127.0.0.1:0", "--data-dir",
                          (dir_ / "data").string(), "--port-file", port_file, "--workers", "1"},
                         (dir_ / (tag + ".out")).string());
    const int port = WaitForPortFile(port_file, std::chrono::seconds(30));
    address->clear();
    if (port > 0) *address = "127.0.0.1:" + std::to_string(port);
    return process;
  }

  // Reads a server's output until it contains text or the deadline passes (0: read once).
  bool WaitForOutput(const std::string& tag, const std::string& text,
                     std::chrono::seconds timeout = std::chrono::seconds(30)) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    for (;;) {
      const std::string output = ReadFile(dir_ / (tag + ".out"));
      if (output.find(text) != std::string::npos) return true;
      if (std::chrono::steady_clock::now() >= deadline) return false;
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
  }

  void TearDown() override {
    stub_.reset();  // closes the channel, so shutdown has no connection to drain
    if (server_.running()) {
      EXPECT_EQ(server_.Stop(SIGTERM), 0) << "seepd did not stop cleanly";
    }
    if (!HasFailure()) std::filesystem::remove_all(dir_);
  }

  CommandResult Seep(std::vector<std::string> args) {
    args.insert(args.begin(), {SEEP_CLI_PATH, "--server", address_});
    return RunCommand(args);
  }

  static void SetDeadline(grpc::ClientContext* ctx, std::chrono::seconds s) {
    ctx->set_deadline(std::chrono::system_clock::now() + s);
  }

  grpc::Status Submit(const v1::Scene& scene, const std::string& request_id,
                      v1::SubmitJobResponse* response) {
    grpc::ClientContext ctx;
    SetDeadline(&ctx, std::chrono::seconds(10));
    v1::SubmitJobRequest request;
    *request.mutable_scene() = scene;
    request.set_request_id(request_id);
    return stub_->SubmitJob(&ctx, request, response);
  }

  std::string SubmitOk(const char* scene_text) {
    v1::SubmitJobResponse response;
    const grpc::Status status = Submit(SceneFromText(scene_text), "", &response);
    EXPECT_TRUE(status.ok()) << status.error_message();
    return response.job().id();
  }

  v1::Job Get(const std::string& id) {
    grpc::ClientContext ctx;
    SetDeadline(&ctx, std::chrono::seconds(10));
    v1::GetJobRequest request;
    request.set_id(id);
    v1::GetJobResponse response;
    const grpc::Status status = stub_->GetJob(&ctx, request, &response);
    EXPECT_TRUE(status.ok()) << status.error_message();
    return response.job();
  }

  // Follows the job's WatchJob stream until its state is `state` or the deadline passes; returns
  // the last event seen.
  v1::JobEvent WatchUntil(const std::string& id, v1::JobState state,
                          std::chrono::seconds timeout = std::chrono::seconds(60)) {
    grpc::ClientContext ctx;
    SetDeadline(&ctx, timeout);
    v1::WatchJobRequest request;
    request.set_id(id);
    auto reader = stub_->WatchJob(&ctx, request);
    v1::JobEvent event;
    v1::JobEvent last;
    while (reader->Read(&event)) {
      last = event;
      if (event.job().state() == state) {
        ctx.TryCancel();
        break;
      }
    }
    (void)reader->Finish();
    return last;
  }

  std::vector<std::string> ListIds(const std::vector<v1::JobState>& states,
                                   const std::string& name) {
    grpc::ClientContext ctx;
    SetDeadline(&ctx, std::chrono::seconds(10));
    v1::ListJobsRequest request;
    for (const auto s : states) request.add_states(s);
    request.set_name_contains(name);
    v1::ListJobsResponse response;
    const grpc::Status status = stub_->ListJobs(&ctx, request, &response);
    EXPECT_TRUE(status.ok()) << status.error_message();
    std::vector<std::string> ids;
    for (const auto& job : response.jobs()) ids.push_back(job.id());
    return ids;
  }

  std::filesystem::path dir_;
  ChildProcess server_;
  std::string address_;
  std::unique_ptr<v1::SeepService::Stub> stub_;
};

TEST_F(DurableJobs, CancelARunningJobThroughTheCli) {
  const std::string id = SubmitOk(kLongScene);
  ASSERT_EQ(WatchUntil(id, v1::JOB_STATE_RUNNING).job().state(), v1::JOB_STATE_RUNNING);

  const CommandResult cancel = Seep({"cancel", id});
  ASSERT_EQ(cancel.exit_code, 0) << cancel.output;
  // The worker records the outcome: watch ends with CANCELLED and exit code 21.
  const CommandResult watch = Seep({"watch", id});
  EXPECT_EQ(watch.exit_code, 21) << watch.output;
  const v1::Job job = Get(id);
  EXPECT_EQ(job.state(), v1::JOB_STATE_CANCELLED);
  EXPECT_EQ(job.error().code(), "CANCELLED");
  EXPECT_NE(job.error().message().find("run stopped at step"), std::string::npos)
      << job.error().message();
  EXPECT_EQ(job.attempt(), 1u);

  // Terminal: cancel again is FAILED_PRECONDITION (exit 9); it has no result either.
  const CommandResult again = Seep({"cancel", id});
  EXPECT_EQ(again.exit_code, 9) << again.output;
  EXPECT_NE(again.output.find("already CANCELLED"), std::string::npos) << again.output;
  const CommandResult result = Seep({"result", id});
  EXPECT_EQ(result.exit_code, 9) << result.output;
  EXPECT_NE(result.output.find("only a SUCCEEDED job has a result"), std::string::npos)
      << result.output;
}

// A running simulation's live progress carries the newest sample of its time series, so a
// watcher sees the boundary rates and the pressure range while it runs, not only at the end.
TEST_F(DurableJobs, RunningJobShowsItsNewestSampleWhileItRuns) {
  const std::string id = SubmitOk(kLongScene);
  ASSERT_EQ(WatchUntil(id, v1::JOB_STATE_RUNNING).job().state(), v1::JOB_STATE_RUNNING);
  v1::Job job;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  do {
    job = Get(id);
  } while (job.progress().latest().count("inflow_m2_per_s") == 0 &&
           std::chrono::steady_clock::now() < deadline);
  const auto& latest = job.progress().latest();
  ASSERT_EQ(latest.count("inflow_m2_per_s"), 1u) << job.DebugString();
  ASSERT_EQ(latest.count("max_pressure_pa"), 1u);
  // Fluid enters from the inlet at 1e5 Pa into a sample that starts at 0 Pa.
  EXPECT_GT(latest.at("inflow_m2_per_s"), 0.0);
  EXPECT_LE(latest.at("max_pressure_pa"), 1e5);
  ASSERT_EQ(Seep({"cancel", id}).exit_code, 0);
}

TEST_F(DurableJobs, CancelAQueuedJobThenResumeItToSucceeded) {
  const std::string long_id = SubmitOk(kLongScene);
  ASSERT_EQ(WatchUntil(long_id, v1::JOB_STATE_RUNNING).job().state(), v1::JOB_STATE_RUNNING);
  // One worker is busy, so this one waits in the queue.
  const std::string quick_id = SubmitOk(kQuickScene);
  ASSERT_EQ(Get(quick_id).state(), v1::JOB_STATE_QUEUED);

  const CommandResult cancel = Seep({"cancel", quick_id});
  ASSERT_EQ(cancel.exit_code, 0) << cancel.output;
  EXPECT_NE(cancel.output.find("job " + quick_id + " cancelled"), std::string::npos)
      << cancel.output;
  EXPECT_EQ(Get(quick_id).state(), v1::JOB_STATE_CANCELLED);  // at once, not by a worker

  // List filters by state and name, through the stub and the CLI.
  EXPECT_EQ(ListIds({v1::JOB_STATE_CANCELLED}, ""), std::vector<std::string>{quick_id});
  EXPECT_EQ(ListIds({v1::JOB_STATE_RUNNING}, ""), std::vector<std::string>{long_id});
  EXPECT_EQ(ListIds({}, "quick"), std::vector<std::string>{quick_id});
  EXPECT_EQ(ListIds({v1::JOB_STATE_RUNNING, v1::JOB_STATE_CANCELLED}, ""),
            (std::vector<std::string>{quick_id, long_id}));  // newest first
  EXPECT_TRUE(ListIds({v1::JOB_STATE_RUNNING}, "quick").empty());
  const CommandResult listed = Seep({"--json", "list", "--state", "running", "--name", "long"});
  ASSERT_EQ(listed.exit_code, 0) << listed.output;
  const auto jobs = nlohmann::json::parse(listed.output)["jobs"];
  ASSERT_EQ(jobs.size(), 1u) << listed.output;
  EXPECT_EQ(jobs[0]["id"], long_id);
  EXPECT_EQ(Seep({"list", "--state", "sleeping"}).exit_code, 3);

  // Free the worker, then resume the cancelled job: a second attempt that succeeds.
  ASSERT_EQ(Seep({"cancel", long_id}).exit_code, 0);
  ASSERT_EQ(WatchUntil(long_id, v1::JOB_STATE_CANCELLED).job().state(), v1::JOB_STATE_CANCELLED);
  const CommandResult resume = Seep({"resume", quick_id});
  ASSERT_EQ(resume.exit_code, 0) << resume.output;
  EXPECT_NE(resume.output.find("attempt 2"), std::string::npos) << resume.output;

  const v1::JobEvent last = WatchUntil(quick_id, v1::JOB_STATE_SUCCEEDED);
  ASSERT_EQ(last.job().state(), v1::JOB_STATE_SUCCEEDED);
  EXPECT_EQ(last.job().attempt(), 2u);
  EXPECT_FALSE(last.job().has_error());
  // The final event carries the metrics.
  ASSERT_EQ(last.result().metrics().count("permeability_m2"), 1u);
  const double exact = 1e-15 / (24.0 * 1e-3);  // a0^3 / (24 R)
  EXPECT_NEAR(last.result().metrics().at("permeability_m2"), exact, 1e-8 * exact);

  const CommandResult table = Seep({"result", quick_id});
  ASSERT_EQ(table.exit_code, 0) << table.output;
  EXPECT_NE(table.output.find("METRIC"), std::string::npos) << table.output;
  EXPECT_TRUE(std::regex_search(table.output, std::regex("\npermeability_m2 +4\\.1666666")))
      << table.output;
  const CommandResult json = Seep({"result", quick_id, "--json"});
  ASSERT_EQ(json.exit_code, 0) << json.output;
  const auto parsed = nlohmann::json::parse(json.output);
  EXPECT_EQ(parsed["job_id"], quick_id);
  EXPECT_NEAR(parsed["result"]["metrics"]["permeability_m2"].get<double>(), exact, 1e-8 * exact);

  // A SUCCEEDED job can be neither resumed nor cancelled; unknown jobs are NOT_FOUND.
  EXPECT_EQ(Seep({"resume", quick_id}).exit_code, 9);
  EXPECT_EQ(Seep({"cancel", quick_id}).exit_code, 9);
  EXPECT_EQ(Seep({"cancel", "j-0000000000000000"}).exit_code, 5);
  EXPECT_EQ(Seep({"resume", "j-0000000000000000"}).exit_code, 5);
  EXPECT_EQ(Seep({"result", "j-0000000000000000"}).exit_code, 5);
}

TEST_F(DurableJobs, RpcStatusCodesForCancelResumeAndResult) {
  const std::string id = SubmitOk(kQuickScene);
  ASSERT_EQ(WatchUntil(id, v1::JOB_STATE_SUCCEEDED).job().state(), v1::JOB_STATE_SUCCEEDED);
  const auto code_of = [&](auto call) {
    grpc::ClientContext ctx;
    SetDeadline(&ctx, std::chrono::seconds(10));
    return call(&ctx).error_code();
  };
  v1::CancelJobRequest cancel;
  v1::CancelJobResponse cancelled;
  v1::ResumeJobRequest resume;
  v1::ResumeJobResponse resumed;
  v1::GetResultRequest result;
  v1::GetResultResponse got;
  // Missing ids are bad requests, unknown ids are NOT_FOUND, wrong states FAILED_PRECONDITION.
  EXPECT_EQ(code_of([&](auto* c) { return stub_->CancelJob(c, cancel, &cancelled); }),
            grpc::StatusCode::INVALID_ARGUMENT);
  cancel.set_id("j-missing");
  EXPECT_EQ(code_of([&](auto* c) { return stub_->CancelJob(c, cancel, &cancelled); }),
            grpc::StatusCode::NOT_FOUND);
  cancel.set_id(id);
  EXPECT_EQ(code_of([&](auto* c) { return stub_->CancelJob(c, cancel, &cancelled); }),
            grpc::StatusCode::FAILED_PRECONDITION);
  resume.set_id(id);
  EXPECT_EQ(code_of([&](auto* c) { return stub_->ResumeJob(c, resume, &resumed); }),
            grpc::StatusCode::FAILED_PRECONDITION);
  result.set_id(id);
  EXPECT_EQ(code_of([&](auto* c) { return stub_->GetResult(c, result, &got); }),
            grpc::StatusCode::OK);
  EXPECT_EQ(got.job_id(), id);
  EXPECT_GT(got.result().metrics().at("domain_count"), 0.0);

  v1::ListJobsRequest bad_list;
  bad_list.add_states(v1::JOB_STATE_UNSPECIFIED);
  v1::ListJobsResponse listed;
  grpc::ClientContext ctx;
  SetDeadline(&ctx, std::chrono::seconds(10));
  const grpc::Status status = stub_->ListJobs(&ctx, bad_list, &listed);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_EQ(status.error_message().rfind("states:", 0), 0u) << status.error_message();
}

TEST_F(DurableJobs, SameRequestIdTwiceGivesOneJob) {
  const v1::Scene scene = SceneFromText(kQuickScene);
  v1::SubmitJobResponse first;
  v1::SubmitJobResponse second;
  ASSERT_TRUE(Submit(scene, "key-1", &first).ok());
  ASSERT_TRUE(Submit(scene, "key-1", &second).ok());
  EXPECT_TRUE(first.created());
  EXPECT_FALSE(second.created());
  EXPECT_EQ(first.job().id(), second.job().id());
  EXPECT_EQ(second.job().request_id(), "key-1");

  // The same key with another scene is a client bug: ALREADY_EXISTS, and nothing new stored.
  v1::Scene other = scene;
  other.set_name("another");
  v1::SubmitJobResponse third;
  const grpc::Status conflict = Submit(other, "key-1", &third);
  EXPECT_EQ(conflict.error_code(), grpc::StatusCode::ALREADY_EXISTS);
  EXPECT_EQ(conflict.error_message().rfind("request_id: 'key-1'", 0), 0u)
      << conflict.error_message();
  EXPECT_EQ(ListIds({}, ""), std::vector<std::string>{first.job().id()});
}

TEST_F(DurableJobs, AJobInterruptedByShutdownRunsAgainAfterRestart) {
  const std::string id = SubmitOk(kLongScene);
  ASSERT_EQ(WatchUntil(id, v1::JOB_STATE_RUNNING).job().state(), v1::JOB_STATE_RUNNING);
  stub_.reset();
  ASSERT_EQ(server_.Stop(SIGTERM), 0);
  EXPECT_TRUE(WaitForOutput("seepd", "interrupted by shutdown"));

  server_ = StartSeepd("seepd-restarted", &address_);
  ASSERT_FALSE(address_.empty());
  stub_ =
      v1::SeepService::NewStub(grpc::CreateChannel(address_, grpc::InsecureChannelCredentials()));
  EXPECT_TRUE(WaitForOutput("seepd-restarted", "recovered 1 interrupted job(s)"));
  EXPECT_TRUE(
      WaitForOutput("seepd-restarted", "started 'long-explicit' (attempt 1, lease epoch 2)"));
  EXPECT_EQ(Get(id).state(), v1::JOB_STATE_RUNNING);
  // Interruptions are not attempts; the job can still be cancelled by its new worker.
  EXPECT_EQ(Get(id).attempt(), 1u);
  ASSERT_EQ(Seep({"cancel", id}).exit_code, 0);
  EXPECT_EQ(WatchUntil(id, v1::JOB_STATE_CANCELLED).job().state(), v1::JOB_STATE_CANCELLED);
}

TEST_F(DurableJobs, BadScenesAreRejectedNamingTheFieldAndNothingIsStored) {
  ASSERT_GE(CommonBadScenes().size(), 20u);
  for (const BadScene& bad : CommonBadScenes()) {
    SCOPED_TRACE(bad.name);
    v1::Scene scene = SceneFromText(kQuickScene);
    bad.mutate(scene);
    v1::SubmitJobResponse response;
    const grpc::Status status = Submit(scene, std::string("bad-") + bad.name, &response);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << status.error_message();
    EXPECT_EQ(status.error_message().rfind(bad.field, 0), 0u)
        << "message: " << status.error_message();
    EXPECT_FALSE(response.has_job());
  }
  // No scene at all.
  v1::SubmitJobResponse response;
  grpc::ClientContext ctx;
  SetDeadline(&ctx, std::chrono::seconds(10));
  const grpc::Status missing = stub_->SubmitJob(&ctx, v1::SubmitJobRequest(), &response);
  EXPECT_EQ(missing.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_EQ(missing.error_message(), "scene: is required");

  EXPECT_TRUE(ListIds({}, "").empty());
  // The request ids were not consumed: a good scene under one of them is a new job.
  v1::SubmitJobResponse good;
  ASSERT_TRUE(Submit(SceneFromText(kQuickScene), "bad-NoPacking", &good).ok());
  EXPECT_TRUE(good.created());
  EXPECT_EQ(ListIds({}, ""), std::vector<std::string>{good.job().id()});
}

}  // namespace
}  // namespace seep::testing
