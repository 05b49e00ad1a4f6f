// SubmitJob with from_job_id, in process (the service's handlers called directly, a JobRunner
// running the jobs): a fork with the same stages ends bit-identical to its parent, a finished run
// forked with a stage more runs only that stage, and every refusal names its field and stores
// nothing (no job, no checkpoint copy).
#include <gtest/gtest.h>
#include <spdlog/sinks/null_sink.h>

#include <chrono>
#include <filesystem>
#include <optional>
#include <string>
#include <thread>

#include "jobs/job_hub.h"
#include "jobs/job_runner.h"
#include "jobs/physics_pool.h"
#include "jobs/store_ledger.h"
#include "rpc/seep_service.h"
#include "store/job_store.h"
#include "test_support.h"

namespace seep::service {
namespace {

// The staged box writes checkpoints at steps 500 and 1000 (in its first and third stages) and
// its final state at 1407.
constexpr std::uint64_t kCheckpointEvery = 500;

class ForkTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = testing::FreshTestDir("fork");
    auto store = JobStore::Open((dir_ / "seep.db").string());
    ASSERT_TRUE(store.ok()) << store.status().ToString();
    store_ = std::move(*store);
    logger_ =
        std::make_shared<spdlog::logger>("test", std::make_shared<spdlog::sinks::null_sink_mt>());
    JobRunnerOptions options;
    options.workers = 1;
    options.threads_per_job = 1;
    options.build_id = "test";
    options.checkpoints.enabled = true;
    ledger_.emplace(*store_, dir_ / "checkpoints", logger_);
    options.checkpoints.every_steps = kCheckpointEvery;
    options.checkpoints.interval = std::chrono::milliseconds(0);
    options.checkpoints.keep = 100;
    runner_.emplace(*ledger_, &*store_, hub_, options, logger_);
    physics_.emplace(/*threads=*/1, 1, /*max_waiting=*/4);
    service_.emplace(*store_, hub_, *physics_, "test",
                     ServiceHooks{[this] { runner_->Wake(); }, {}}, logger_);
  }

  void TearDown() override {
    runner_->Stop();
    service_.reset();
    physics_.reset();
    runner_.reset();
    store_.reset();
    if (!HasFailure()) std::filesystem::remove_all(dir_);
  }

  // The runner starts with the first job that should run, so that jobs stored directly stay
  // queued in the tests that need them so.
  void StartRunner() {
    if (!runner_started_) runner_->Start();
    runner_started_ = true;
  }

  grpc::Status Submit(const v1::SubmitJobRequest& request, v1::SubmitJobResponse* response) {
    grpc::ServerContext ctx;
    return service_->SubmitJob(&ctx, &request, response);
  }

  static v1::SubmitJobRequest ForkRequest(const std::string& parent, const v1::Scene& scene,
                                          std::optional<std::uint64_t> step = std::nullopt) {
    v1::SubmitJobRequest request;
    *request.mutable_scene() = scene;
    request.set_from_job_id(parent);
    if (step) request.set_from_step(*step);
    return request;
  }

  // Submits and returns the new job's id (the test fails when it is refused).
  std::string Queue(const v1::SubmitJobRequest& request) {
    StartRunner();
    v1::SubmitJobResponse response;
    const grpc::Status s = Submit(request, &response);
    EXPECT_TRUE(s.ok()) << s.error_message();
    EXPECT_TRUE(response.created());
    return response.job().id();
  }

  v1::Job Get(const std::string& id) {
    grpc::ServerContext ctx;
    v1::GetJobRequest request;
    request.set_id(id);
    v1::GetJobResponse response;
    const grpc::Status s = service_->GetJob(&ctx, &request, &response);
    EXPECT_TRUE(s.ok()) << s.error_message();
    return response.job();
  }

  v1::Job WaitFinished(const std::string& id) {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
    for (;;) {
      const v1::Job job = Get(id);
      const bool finished = job.state() == v1::JOB_STATE_SUCCEEDED ||
                            job.state() == v1::JOB_STATE_FAILED ||
                            job.state() == v1::JOB_STATE_CANCELLED;
      if (finished || std::chrono::steady_clock::now() > deadline) return job;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  }

  // Runs the staged box (or `scene`) to its end; returns the finished job.
  v1::Job RunParent(const v1::Scene& scene = testing::TestDataScene("staged_box.textproto")) {
    v1::SubmitJobRequest request;
    *request.mutable_scene() = scene;
    const v1::Job job = WaitFinished(Queue(request));
    EXPECT_EQ(job.state(), v1::JOB_STATE_SUCCEEDED) << job.error().message();
    return job;
  }

  std::int64_t JobCount() {
    const auto counts = store_->CountByState();
    EXPECT_TRUE(counts.ok());
    std::int64_t n = 0;
    if (counts.ok()) {
      for (const auto& [state, count] : *counts) n += count;
    }
    return n;
  }
  // The job folders under checkpoints/: one per job that wrote or was given a checkpoint.
  std::size_t CheckpointFolders() const {
    std::size_t n = 0;
    for (const auto& entry : std::filesystem::directory_iterator(dir_ / "checkpoints")) {
      n += entry.is_directory() ? 1 : 0;
    }
    return n;
  }

  // Submits a fork that must be refused with `code` and a message starting with `prefix`; checks
  // that nothing was stored. Returns the message.
  std::string Refused(const v1::SubmitJobRequest& request, grpc::StatusCode code,
                      const std::string& prefix) {
    const std::int64_t jobs = JobCount();
    const std::size_t folders = CheckpointFolders();
    v1::SubmitJobResponse response;
    const grpc::Status s = Submit(request, &response);
    EXPECT_EQ(s.error_code(), code) << s.error_message();
    EXPECT_EQ(s.error_message().rfind(prefix, 0), 0u) << s.error_message();
    EXPECT_EQ(JobCount(), jobs) << s.error_message();
    EXPECT_EQ(CheckpointFolders(), folders) << s.error_message();
    return s.error_message();
  }

  std::filesystem::path dir_;
  std::unique_ptr<JobStore> store_;
  JobHub hub_;
  std::shared_ptr<spdlog::logger> logger_;
  std::optional<StoreLedger> ledger_;
  std::optional<JobRunner> runner_;
  bool runner_started_ = false;
  std::optional<PhysicsPool> physics_;
  std::optional<SeepServiceImpl> service_;
};

// The done-when of issue 16: forked at a checkpoint in its first stage and at one in its last,
// with the same stages, each fork ends with the parent's final-state hash; the parent lists them.
TEST_F(ForkTest, AForkWithTheSameStagesEndsWithTheParentsStateHash) {
  const v1::Scene scene = testing::TestDataScene("staged_box.textproto");
  const v1::Job parent = RunParent();
  ASSERT_EQ(parent.result().state_sha256().size(), 64u);
  for (const std::uint64_t step : {std::uint64_t{500}, std::uint64_t{1000}}) {
    const v1::Job fork = WaitFinished(Queue(ForkRequest(parent.id(), scene, step)));
    ASSERT_EQ(fork.state(), v1::JOB_STATE_SUCCEEDED) << fork.error().message();
    EXPECT_EQ(fork.result().state_sha256(), parent.result().state_sha256()) << "step " << step;
    EXPECT_EQ(fork.parent_job_id(), parent.id());
    EXPECT_EQ(fork.parent_step(), step);
    EXPECT_EQ(fork.result().metrics().at("steps"), parent.result().metrics().at("steps"));
  }
  EXPECT_EQ(Get(parent.id()).child_job_ids_size(), 2);
}

// A finished run (unset from_step: its final state) with a stage more: the fork continues at the
// new stage, with the ended stages' metrics carried over.
TEST_F(ForkTest, AFinishedRunForkedWithAStageMoreRunsThatStage) {
  v1::Scene scene = testing::TestDataScene("staged_box.textproto");
  const v1::Job parent = RunParent(scene);
  const double parent_steps = parent.result().metrics().at("steps");
  v1::Stage* hold = scene.add_stages();
  hold->set_name("hold");
  hold->add_end()->set_duration_s(1e-3);
  scene.set_name("with-hold");
  const v1::Job fork = WaitFinished(Queue(ForkRequest(parent.id(), scene)));
  ASSERT_EQ(fork.state(), v1::JOB_STATE_SUCCEEDED) << fork.error().message();
  EXPECT_EQ(fork.parent_step(), static_cast<std::uint64_t>(parent_steps));
  const auto& metrics = fork.result().metrics();
  EXPECT_EQ(metrics.at("stages_ended"), 4.0);
  EXPECT_EQ(metrics.at("stage3_steps"), parent.result().metrics().at("stage3_steps"));
  EXPECT_GT(metrics.at("steps"), parent_steps);
  EXPECT_NEAR(metrics.at("stage4_duration_s"), 1e-3, metrics.at("dem_dt_s"));
  EXPECT_EQ(fork.progress().stage_index(), 4u);
  EXPECT_EQ(fork.progress().stage_name(), "hold");
  // Its checkpoints: the copy it started from and its own.
  const auto checkpoints = store_->ListCheckpoints(fork.id());
  ASSERT_TRUE(checkpoints.ok());
  EXPECT_EQ(checkpoints->back().step, static_cast<std::uint64_t>(parent_steps));
}

TEST_F(ForkTest, RefusalsNameTheFieldAndStoreNothing) {
  const v1::Scene scene = testing::TestDataScene("staged_box.textproto");
  const std::string parent = RunParent(scene).id();
  v1::Scene other = scene;
  other.mutable_packing()->mutable_lattice()->set_rows(9);
  Refused(ForkRequest(parent, other, 500), grpc::StatusCode::INVALID_ARGUMENT,
          "scene.packing: differs from the parent job " + parent);
  other = scene;
  other.mutable_stages(1)->mutable_end(0)->set_kinetic_energy_ratio(0.02);
  Refused(ForkRequest(parent, other, 1000), grpc::StatusCode::INVALID_ARGUMENT,
          "scene.stages[1]: differs from the parent job " + parent + "'s stage 2 ('rest')");
  const std::string message =
      Refused(ForkRequest(parent, scene, 501), grpc::StatusCode::INVALID_ARGUMENT,
              "from_step: job " + parent);
  EXPECT_NE(message.find("its checkpoints are at steps 500, 1000, 1407"), std::string::npos)
      << message;
  Refused(ForkRequest(parent, scene), grpc::StatusCode::INVALID_ARGUMENT,
          "scene.stages: nothing left to run");
  Refused(ForkRequest("j-0000000000000000", scene), grpc::StatusCode::NOT_FOUND,
          "from_job_id: job j-0000000000000000 not found");
  v1::SubmitJobRequest step_alone;
  *step_alone.mutable_scene() = scene;
  step_alone.set_from_step(500);
  Refused(step_alone, grpc::StatusCode::INVALID_ARGUMENT, "from_step: only with from_job_id");
  v1::Scene invalid = scene;
  invalid.mutable_fluid()->set_viscosity_pa_s(-1);
  Refused(ForkRequest(parent, invalid, 500), grpc::StatusCode::INVALID_ARGUMENT,
          "scene.fluid.viscosity_pa_s:");
  // The stage refused from step 1000 is free from step 500, before it had begun.
  const v1::Job fork = WaitFinished(Queue(ForkRequest(parent, other, 500)));
  EXPECT_EQ(fork.state(), v1::JOB_STATE_SUCCEEDED) << fork.error().message();
}

// Parents stored directly (the runner not started): a calibration, a scene without stages, and a
// staged scene still queued, without a checkpoint.
TEST_F(ForkTest, ParentsThatCannotBeForkedAreRefusedNamingFromJobId) {
  const v1::Scene scene = testing::TestDataScene("staged_box.textproto");
  JobRecord calibration;
  calibration.id = "j-calibration";
  calibration.name = "calibration";
  calibration.kind = JobKind::kCalibration;
  calibration.scene = "x";
  JobRecord unstaged;
  unstaged.id = "j-unstaged";
  unstaged.name = "unstaged";
  unstaged.scene = testing::ExampleScene("darcy_square_lattice.textproto").SerializeAsString();
  JobRecord queued;
  queued.id = "j-queued";
  queued.name = "queued";
  queued.scene = scene.SerializeAsString();
  for (const JobRecord* job : {&calibration, &unstaged, &queued}) {
    ASSERT_TRUE(store_->Insert(*job).ok());
  }
  std::filesystem::create_directories(dir_ / "checkpoints");
  Refused(ForkRequest("j-calibration", scene), grpc::StatusCode::INVALID_ARGUMENT,
          "from_job_id: job j-calibration is a calibration");
  Refused(ForkRequest("j-unstaged", scene), grpc::StatusCode::INVALID_ARGUMENT,
          "from_job_id: job j-unstaged's scene has no stages");
  Refused(ForkRequest("j-queued", scene, 500), grpc::StatusCode::INVALID_ARGUMENT,
          "from_job_id: job j-queued has no checkpoint yet (it is QUEUED)");
  v1::SubmitJobRequest calibrate;
  calibrate.mutable_calibration()->set_name("c");
  calibrate.set_from_job_id("j-queued");
  Refused(calibrate, grpc::StatusCode::INVALID_ARGUMENT, "from_job_id: a fork continues");
}

// A fork whose copy is gone (here: never written) does not start over from the beginning: it
// fails, saying why.
TEST_F(ForkTest, AForkWithoutAUsableCheckpointFails) {
  JobRecord fork;
  fork.id = "j-fork";
  fork.name = "fork";
  fork.scene = testing::TestDataScene("staged_box.textproto").SerializeAsString();
  fork.parent_job_id = "j-gone";
  fork.parent_step = 500;
  CheckpointRecord copy;
  copy.step = 500;
  copy.path = (dir_ / "checkpoints" / "j-fork" / "ckpt-000000000500.bin").string();
  ASSERT_TRUE(store_->InsertFork(fork, copy).ok());
  StartRunner();
  runner_->Wake();
  const v1::Job failed = WaitFinished("j-fork");
  EXPECT_EQ(failed.state(), v1::JOB_STATE_FAILED);
  EXPECT_EQ(failed.error().code(), "FAILED_PRECONDITION");
  EXPECT_NE(failed.error().message().find("a fork starts from its parent job j-gone's checkpoint "
                                          "at step 500"),
            std::string::npos)
      << failed.error().message();
}

}  // namespace
}  // namespace seep::service
