// GetJobFields in process, on a real gRPC server over loopback with a bearer token: it goes
// through the common wrapper (a bad token is refused before any work), its physics runs as one
// task of the PhysicsPool (the pool whose threads carry the job's thread budget), and a call that
// passes its deadline while the pool is busy gives up without its task ever running. Also the
// bonds and wall segments it carries for the particle picture.
#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>
#include <omp.h>
#include <spdlog/sinks/null_sink.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <future>
#include <thread>

#include "jobs/job_hub.h"
#include "jobs/job_runner.h"
#include "jobs/physics_pool.h"
#include "jobs/store_ledger.h"
#include "rpc/bearer_auth.h"
#include "rpc/seep_service.h"
#include "store/job_store.h"
#include "test_support.h"

namespace seep::service {
namespace {

constexpr const char* kToken = "fields-test-token";

class GetJobFieldsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = testing::FreshTestDir("fields");
    auto store = JobStore::Open((dir_ / "seep.db").string());
    ASSERT_TRUE(store.ok()) << store.status().ToString();
    store_ = std::move(*store);
    auto auth = BearerAuth::FromToken(kToken);
    ASSERT_TRUE(auth.ok());
    auth_.emplace(std::move(*auth));
    logger_ =
        std::make_shared<spdlog::logger>("test", std::make_shared<spdlog::sinks::null_sink_mt>());

    JobRunnerOptions options;
    options.workers = 1;
    options.threads_per_job = 2;
    options.build_id = "test";
    options.checkpoints.enabled = true;
    ledger_.emplace(*store_, dir_ / "checkpoints", logger_);
    runner_.emplace(*ledger_, &*store_, hub_, options, logger_);
    physics_.emplace(/*threads=*/1, options.threads_per_job, /*max_waiting=*/4);
    service_.emplace(*store_, hub_, *physics_, "test",
                     ServiceHooks{[this] { runner_->Wake(); }, {}}, logger_,
                     ServiceGuards{&*auth_, kDefaultMaxSceneBytes, max_response_bytes_});
    grpc::ServerBuilder builder;
    int port = 0;
    builder.AddListeningPort("127.0.0.1:0", grpc::InsecureServerCredentials(), &port);
    builder.RegisterService(&*service_);
    server_ = builder.BuildAndStart();
    ASSERT_TRUE(server_ && port > 0);
    stub_ = v1::SeepService::NewStub(grpc::CreateChannel("127.0.0.1:" + std::to_string(port),
                                                         grpc::InsecureChannelCredentials()));
    runner_->Start();
  }

  void TearDown() override {
    if (server_) server_->Shutdown(std::chrono::system_clock::now() + std::chrono::seconds(2));
    if (runner_) runner_->Stop();
    server_.reset();
    service_.reset();
    physics_.reset();
    runner_.reset();
    store_.reset();
    if (!HasFailure()) std::filesystem::remove_all(dir_);
  }

  static void Authorize(grpc::ClientContext* ctx, const std::string& token = kToken) {
    ctx->AddMetadata("authorization", "Bearer " + token);
    ctx->set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(30));
  }

  // Submits the scene (by default the steady lattice) and waits until it has SUCCEEDED (its
  // final checkpoint written).
  std::string RunJob(
      const v1::Scene& scene = testing::ExampleScene("darcy_square_lattice.textproto")) {
    v1::SubmitJobRequest submit;
    *submit.mutable_scene() = scene;
    v1::SubmitJobResponse submitted;
    {
      grpc::ClientContext ctx;
      Authorize(&ctx);
      const grpc::Status s = stub_->SubmitJob(&ctx, submit, &submitted);
      EXPECT_TRUE(s.ok()) << s.error_message();
    }
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (std::chrono::steady_clock::now() < deadline) {
      grpc::ClientContext ctx;
      Authorize(&ctx);
      v1::GetJobRequest get;
      get.set_id(submitted.job().id());
      v1::GetJobResponse job;
      EXPECT_TRUE(stub_->GetJob(&ctx, get, &job).ok());
      if (job.job().state() == v1::JOB_STATE_SUCCEEDED) return job.job().id();
      EXPECT_NE(job.job().state(), v1::JOB_STATE_FAILED) << job.job().error().message();
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    ADD_FAILURE() << "the job did not succeed in time";
    return submitted.job().id();
  }

  grpc::Status Fields(const std::string& id, grpc::ClientContext* ctx,
                      v1::GetJobFieldsResponse* out, std::uint64_t step = 0) {
    v1::GetJobFieldsRequest request;
    request.set_job_id(id);
    request.set_step(step);
    return stub_->GetJobFields(ctx, request, out);
  }

  std::size_t max_response_bytes_ = kDefaultMaxResponseBytes;
  std::filesystem::path dir_;
  std::unique_ptr<JobStore> store_;
  JobHub hub_;
  std::optional<BearerAuth> auth_;
  std::shared_ptr<spdlog::logger> logger_;
  std::optional<StoreLedger> ledger_;
  std::optional<JobRunner> runner_;
  std::optional<PhysicsPool> physics_;
  std::optional<SeepServiceImpl> service_;
  std::unique_ptr<grpc::Server> server_;
  std::unique_ptr<v1::SeepService::Stub> stub_;
};

TEST_F(GetJobFieldsTest, ABadTokenIsRefusedByTheCommonWrapperBeforeAnyWork) {
  const std::string id = RunJob();
  for (const char* token : {"", "not-the-token"}) {
    grpc::ClientContext ctx;
    if (*token != '\0') ctx.AddMetadata("authorization", std::string("Bearer ") + token);
    v1::GetJobFieldsResponse out;
    const grpc::Status s = Fields(id, &ctx, &out);
    EXPECT_EQ(s.error_code(), grpc::StatusCode::UNAUTHENTICATED) << token;
    EXPECT_EQ(out.fields().particle_x_m_size(), 0);
  }
  EXPECT_EQ(physics_->tasks_run(), 0u);
}

TEST_F(GetJobFieldsTest, RunsItsPhysicsAsOneTaskOfThePhysicsPool) {
  const std::string id = RunJob();
  EXPECT_EQ(physics_->core_threads(), 2);  // --threads-per-job of the workers
  grpc::ClientContext ctx;
  Authorize(&ctx);
  v1::GetJobFieldsResponse out;
  const grpc::Status s = Fields(id, &ctx, &out);
  ASSERT_TRUE(s.ok()) << s.error_message();
  EXPECT_EQ(out.job_id(), id);
  EXPECT_EQ(out.fields().particle_x_m_size(), 60 * 40);
  EXPECT_GT(out.fields().domain_pressure_pa_size(), 0);
  ASSERT_EQ(out.available_steps_size(), 1);
  EXPECT_EQ(out.step(), out.available_steps(0));
  EXPECT_EQ(physics_->tasks_run(), 1u);
  // The pool's thread, the one that ran it, runs the core's loops on the job's budget.
  int threads = 0;
  auto probe = physics_->Post([&threads] { threads = omp_get_max_threads(); });
  ASSERT_NE(probe, nullptr);
  ASSERT_TRUE(probe->WaitFor(std::chrono::milliseconds(10000)));
  EXPECT_EQ(threads, 2);

  // Checks that need no physics answer on the handler thread, with the same messages as ever.
  grpc::ClientContext missing;
  Authorize(&missing);
  v1::GetJobFieldsResponse none;
  const grpc::Status bad_step = Fields(id, &missing, &none, out.step() + 7);
  EXPECT_EQ(bad_step.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_EQ(bad_step.error_message(), "step: job " + id + " has no checkpoint at step " +
                                          std::to_string(out.step() + 7) +
                                          "; available steps: " + std::to_string(out.step()));
  EXPECT_EQ(physics_->tasks_run(), 2u);
}

// The fracturing example cut down to a 12 x 10 lattice on its floor alone, for 1 ms (before any
// bond breaks): the bonds are the touching pairs, sorted, none broken; the floor, cut by no other
// wall, spans the disks' bounding box widened by two largest diameters on each side, at the
// height of the lowest disk's underside.
TEST_F(GetJobFieldsTest, CarriesTheBondsAndALoneFloorAcrossTheWidenedPacking) {
  v1::Scene scene = testing::ExampleScene("hydraulic_fracturing.textproto");
  scene.mutable_packing()->mutable_lattice()->set_columns(12);
  scene.mutable_packing()->mutable_lattice()->set_rows(10);
  scene.mutable_solver()->set_end_time_s(1e-3);
  for (v1::Effect& effect : *scene.mutable_effects()) {
    if (!effect.has_walls()) continue;
    v1::WallsEffect floor_only;
    for (const v1::Wall& wall : effect.walls().walls()) {
      if (wall.side() == v1::WALL_SIDE_BOTTOM) *floor_only.add_walls() = wall;
    }
    *effect.mutable_walls() = floor_only;
  }
  const std::string id = RunJob(scene);
  grpc::ClientContext ctx;
  Authorize(&ctx);
  v1::GetJobFieldsResponse out;
  const grpc::Status s = Fields(id, &ctx, &out);
  ASSERT_TRUE(s.ok()) << s.error_message();
  const v1::JobFields& f = out.fields();
  const int n = f.particle_x_m_size();
  ASSERT_GT(n, 0);

  double x_lo = HUGE_VAL, x_hi = -HUGE_VAL, y_lo = HUGE_VAL, r_max = 0.0;
  for (int k = 0; k < n; ++k) {
    x_lo = std::min(x_lo, f.particle_x_m(k) - f.particle_radius_m(k));
    x_hi = std::max(x_hi, f.particle_x_m(k) + f.particle_radius_m(k));
    y_lo = std::min(y_lo, f.particle_y_m(k) - f.particle_radius_m(k));
    r_max = std::max(r_max, f.particle_radius_m(k));
  }
  ASSERT_EQ(f.wall_x0_m_size(), 1);
  ASSERT_EQ(f.wall_y0_m_size(), 1);
  ASSERT_EQ(f.wall_x1_m_size(), 1);
  ASSERT_EQ(f.wall_y1_m_size(), 1);
  EXPECT_NEAR(f.wall_x0_m(0), x_lo - 4.0 * r_max, 1e-12);
  EXPECT_NEAR(f.wall_x1_m(0), x_hi + 4.0 * r_max, 1e-12);
  EXPECT_EQ(f.wall_y0_m(0), f.wall_y1_m(0));
  EXPECT_NEAR(f.wall_y0_m(0), y_lo, 0.05 * r_max);  // the disks press on it by microns

  // Touching pairs counted from the positions (the lattice's neighbours touch; the next nearest
  // are a radius or more apart).
  int touching = 0;
  for (int i = 0; i < n; ++i) {
    for (int j = i + 1; j < n; ++j) {
      const double d =
          std::hypot(f.particle_x_m(j) - f.particle_x_m(i), f.particle_y_m(j) - f.particle_y_m(i));
      if (d < f.particle_radius_m(i) + f.particle_radius_m(j) + 0.01 * r_max) ++touching;
    }
  }
  const int bonds = f.bond_particle_i_size();
  EXPECT_EQ(bonds, touching);
  ASSERT_EQ(f.bond_particle_j_size(), bonds);
  ASSERT_EQ(f.bond_broken_size(), bonds);
  for (int b = 0; b < bonds; ++b) {
    const int i = f.bond_particle_i(b);
    const int j = f.bond_particle_j(b);
    ASSERT_TRUE(i >= 0 && i < j && j < n) << b << ": " << i << " " << j;
    if (b > 0) {
      EXPECT_LT(std::pair(f.bond_particle_i(b - 1), f.bond_particle_j(b - 1)), std::pair(i, j));
    }
    const double d =
        std::hypot(f.particle_x_m(j) - f.particle_x_m(i), f.particle_y_m(j) - f.particle_y_m(i));
    EXPECT_LT(d, f.particle_radius_m(i) + f.particle_radius_m(j) + 0.01 * r_max) << b;
    EXPECT_FALSE(f.bond_broken(b)) << b;
  }
}

TEST_F(GetJobFieldsTest, ACallPastItsDeadlineGivesUpAndItsTaskNeverRuns) {
  const std::string id = RunJob();
  std::promise<void> release;
  std::shared_future<void> released = release.get_future().share();
  auto busy = physics_->Post([released] { released.wait(); });  // the pool's only thread
  ASSERT_NE(busy, nullptr);
  grpc::ClientContext ctx;
  ctx.AddMetadata("authorization", std::string("Bearer ") + kToken);
  ctx.set_deadline(std::chrono::system_clock::now() + std::chrono::milliseconds(300));
  v1::GetJobFieldsResponse out;
  const grpc::Status s = Fields(id, &ctx, &out);
  EXPECT_EQ(s.error_code(), grpc::StatusCode::DEADLINE_EXCEEDED) << s.error_message();
  // The handler has left (the server notices the deadline within its wait slice); then the
  // pool's thread is freed, and only the blocking task has run.
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  release.set_value();
  ASSERT_TRUE(busy->WaitFor(std::chrono::milliseconds(10000)));
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  EXPECT_EQ(physics_->tasks_run(), 1u);
}

// A server whose responses may hold 4 KiB: the lattice's fields are larger, so the call is
// refused with the size and the limit instead of a bare transport error.
class GetJobFieldsSmallResponseTest : public GetJobFieldsTest {
 protected:
  GetJobFieldsSmallResponseTest() { max_response_bytes_ = 4096; }
};

TEST_F(GetJobFieldsSmallResponseTest, AResponseOverTheLimitIsRefusedWithItsSize) {
  const std::string id = RunJob();
  grpc::ClientContext ctx;
  Authorize(&ctx);
  v1::GetJobFieldsResponse out;
  const grpc::Status status = Fields(id, &ctx, &out);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED) << status.error_message();
  EXPECT_NE(status.error_message().find("GetJobFields: the fields of job " + id + " at step"),
            std::string::npos)
      << status.error_message();
  EXPECT_NE(status.error_message().find(
                "over the limit of 4096 bytes per response (seepd --max-response-bytes)"),
            std::string::npos)
      << status.error_message();
}

}  // namespace
}  // namespace seep::service
