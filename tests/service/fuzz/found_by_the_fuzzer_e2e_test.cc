// What the request fuzzer found (fuzz_session.h), each on a real seepd as the fuzzer met it,
// named by the seed and request that found it (bench/service/seep_service_fuzz_bench --seed S
// replays the run).
#include <gtest/gtest.h>

#include "../e2e/grpc_seepd_fixture.h"
#include "base_requests.h"

namespace seep::testing {
namespace {

class FoundByTheFuzzer : public GrpcSeepdTest {
 protected:
  FoundByTheFuzzer() : GrpcSeepdTest("e2e-found-by-fuzzer") {}

  static v1::Scene Base(const std::string& name) {
    for (const fuzz::BaseScene& base : fuzz::BaseScenes()) {
      if (base.name == name) return base.scene;
    }
    ADD_FAILURE() << "no base scene " << name;
    return {};
  }

  // Refused at submit naming `field`, or accepted and FAILED naming it; either way seepd is the
  // same process afterwards and runs the next job.
  void ExpectRefusedOrFailedNamingAndSeepdRunsOn(const v1::Scene& scene, const std::string& field) {
    const pid_t pid = server_.pid();
    grpc::ClientContext ctx;
    Prepare(ctx);
    v1::SubmitJobRequest request;
    *request.mutable_scene() = scene;
    v1::SubmitJobResponse response;
    const grpc::Status status = stub_->SubmitJob(&ctx, request, &response);
    std::string reason = status.error_message();
    if (status.ok()) {
      // Polled while seepd lives: a seepd that went down fails the test at once.
      v1::Job job = response.job();
      const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
      while (!IsTerminalState(job.state()) && std::chrono::steady_clock::now() < deadline) {
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
        ASSERT_EQ(server_.PollExit(), -1) << "seepd ended running " << scene.ShortDebugString();
        job = Get(job.id());
      }
      EXPECT_EQ(job.state(), v1::JOB_STATE_FAILED) << job.DebugString();
      reason = job.error().message();
    } else {
      EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << reason;
    }
    EXPECT_NE(reason.find(field), std::string::npos) << field << " not in: " << reason;
    ASSERT_EQ(server_.PollExit(), -1) << "seepd ended";
    EXPECT_EQ(server_.pid(), pid);
    const v1::Job next = WaitTerminal(Submit(Base("steady-lattice")));
    EXPECT_EQ(next.state(), v1::JOB_STATE_SUCCEEDED) << next.DebugString();
  }
};

// Seed 1, request 137: a lattice of disks 5e-324 m in radius (the smallest subnormal double)
// segfaulted seepd when its job started: the contact detection's cell grid took 1 / 5e-324 = inf
// as the inverse of its cell width, binned every disk at NaN, and indexed outside its arrays.
TEST_F(FoundByTheFuzzer, ASubnormalLatticeRadiusIsRefusedWhileSeepdRunsOn) {
  Start("data", {"--workers", "1"});
  v1::Scene scene = Base("regions");
  scene.mutable_packing()->mutable_lattice()->set_radius_m(5e-324);
  ASSERT_NO_FATAL_FAILURE(
      ExpectRefusedOrFailedNamingAndSeepdRunsOn(scene, "scene.packing.lattice.radius_m"));
  scene = Base("steady-lattice");
  scene.mutable_packing()->mutable_lattice()->set_radius_m(2e-310);
  ASSERT_NO_FATAL_FAILURE(
      ExpectRefusedOrFailedNamingAndSeepdRunsOn(scene, "scene.packing.lattice.radius_m"));
}

// Seed 1, request ~18,600 of a 50,000-request run: the moving-disks scene with a residual
// aperture of 0.1 m (1e4 times its own) makes the fluid's critical step 5.9e-19 s against a DEM
// step of 6.4e-8 s, and its first flow update 1.2e11 explicit sub-steps (the limit was 1e12):
// days inside one DEM step, where neither cancel, --job-time-limit-s nor the lease reach. Its
// lease expired, the job was queued again onto the second worker, both workers hung, and 101
// queued jobs waited for minutes.
TEST_F(FoundByTheFuzzer, AFlowUpdateOfTooManySubStepsFailsTheJobAndTheQueueMovesOn) {
  Start("data", {"--workers", "2", "--job-time-limit-s", "5"});
  v1::Scene scene = Base("moving-disks");
  scene.mutable_aperture()->set_residual_aperture_m(0.1);
  const std::string hung = Submit(scene);
  const std::string next = Submit(Base("steady-lattice"));
  const v1::Job job = WaitFor(
      hung, [](const v1::Job& j) { return IsTerminalState(j.state()); }, std::chrono::seconds(30));
  EXPECT_EQ(job.state(), v1::JOB_STATE_FAILED) << job.DebugString();
  EXPECT_NE(job.error().message().find("sub-steps"), std::string::npos) << job.DebugString();
  const v1::Job after = WaitTerminal(next);
  EXPECT_EQ(after.state(), v1::JOB_STATE_SUCCEEDED) << after.DebugString();
}

// Seed 50, request 985 (with GeneratorLimits::max_disks 0): a steady lattice of 8 x 100,000
// disks, valid, held a worker in its set-up for over 30 s at step 0 and took seepd to 988 MiB,
// with --job-time-limit-s 5 (the limit was checked at steps only). Now its set-up runs in a
// worker process that seepd ends 5 s past the limit (or the admission estimate refuses it, on a
// machine with less memory for a job).
TEST_F(FoundByTheFuzzer, AValidLatticeOf800000DisksIsBoundedByTheJobTimeLimit) {
  Start("data", {"--workers", "1", "--job-time-limit-s", "5"});
  v1::Scene scene = Base("steady-lattice");
  scene.mutable_packing()->mutable_lattice()->set_rows(100'000);
  grpc::ClientContext ctx;
  Prepare(ctx);
  v1::SubmitJobRequest request;
  *request.mutable_scene() = scene;
  v1::SubmitJobResponse response;
  const grpc::Status status = stub_->SubmitJob(&ctx, request, &response);
  if (!status.ok()) {
    EXPECT_EQ(status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED) << status.error_message();
    EXPECT_NE(status.error_message().find("scene.packing"), std::string::npos);
    return;
  }
  const v1::Job job = WaitFor(
      response.job().id(), [](const v1::Job& j) { return IsTerminalState(j.state()); },
      std::chrono::seconds(40));
  EXPECT_EQ(job.state(), v1::JOB_STATE_FAILED) << job.DebugString();
  EXPECT_EQ(job.error().code(), "DEADLINE_EXCEEDED") << job.DebugString();
  EXPECT_EQ(job.progress().step(), 0u) << "ended in its set-up";
}

}  // namespace
}  // namespace seep::testing
