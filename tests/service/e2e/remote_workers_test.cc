// Remote workers (seep-worker) leasing jobs from a pure coordinator (seepd --workers 0) over
// loopback: a 20-job sweep drained by two workers while one of them is SIGKILLed twice (and
// restarted each time) ends with every job SUCCEEDED exactly once and bit-identical to the same
// sweep run by seepd's own workers; and the WorkerService's refusals of bad input (unknown job,
// stale epoch, chunks out of order, short, damaged or oversized uploads), each naming the field,
// with nothing half-kept.
#include <fmt/format.h>

#include <optional>
#include <set>
#include <thread>

#include "grpc_seepd_fixture.h"
#include "seep/v1/worker_service.grpc.pb.h"
#include "store/sha256.h"

namespace seep::testing {
namespace {

// Steps of the remote workers between two checkpoints: several per job, so that a kill loses
// little and a resume has something to continue from.
constexpr int kCheckpointEverySteps = 4000;

// A 20-point sweep of short explicit transients (40,000 to 50,000 steps, about a second each).
v1::Sweep TwentyJobSweep() {
  v1::Sweep sweep;
  EXPECT_TRUE(google::protobuf::TextFormat::ParseFromString(
      R"pb(
        name: "remote"
        combine: SWEEP_COMBINE_PRODUCT
        axes {
          path: "boundary.inlet_pressure_pa"
          numbers: [ 1e5, 1.5e5, 2e5, 2.5e5, 3e5 ]
        }
        axes {
          path: "solver.dt_factor"
          numbers: [ 0.9, 0.8, 0.7, 0.6 ]
        }
      )pb",
      &sweep));
  *sweep.mutable_scene() = LatticeScene("remote", 8e-2);
  return sweep;
}

class RemoteWorkers : public GrpcSeepdTest {
 protected:
  RemoteWorkers() : GrpcSeepdTest("e2e-remote") {}

  void TearDown() override {
    for (ChildProcess* worker : {&steady_, &killed_}) {
      if (worker->running()) worker->Stop(SIGTERM);
    }
    worker_stub_.reset();
    GrpcSeepdTest::TearDown();
  }

  // Starts seepd and keeps a WorkerService stub on it too.
  void StartCoordinator(const std::vector<std::string>& flags) {
    Start("coordinator", flags);
    port_ = std::stoi(ReadFile(dir_ / "coordinator.port"));
    worker_stub_ = v1::WorkerService::NewStub(grpc::CreateChannel(
        "127.0.0.1:" + std::to_string(port_), grpc::InsecureChannelCredentials()));
  }

  // A seep-worker on the coordinator, named `name` in its leases; output to <name>-<n>.out.
  // `extra` flags follow (e.g. --token-file).
  ChildProcess StartWorker(const std::string& name, double lease_s,
                           const std::vector<std::string>& extra = {}) {
    const std::string log = (dir_ / fmt::format("{}-{}.out", name, ++worker_starts_)).string();
    std::vector<std::string> argv = {SEEP_WORKER_PATH,
                                     "--server",
                                     "127.0.0.1:" + std::to_string(port_),
                                     "--name",
                                     name,
                                     "--lease-s",
                                     fmt::format("{}", lease_s),
                                     "--checkpoint-every-steps",
                                     std::to_string(kCheckpointEverySteps),
                                     "--checkpoint-interval-s",
                                     "0",
                                     "--threads-per-job",
                                     "1"};
    argv.insert(argv.end(), extra.begin(), extra.end());
    return ChildProcess(argv, log);
  }

  // Waits until the worker process `worker`, named `name`, runs a job that it has checkpointed
  // at least once (a CHECKPOINT event after its claim); false on timeout.
  bool WaitUntilRunningPastACheckpoint(const std::vector<std::string>& ids, const std::string& name,
                                       const ChildProcess& worker) {
    // Its lease owner: the name, the pid and a random suffix.
    const std::string owner = fmt::format("by {}-{}-", name, worker.pid());
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
    while (std::chrono::steady_clock::now() < deadline) {
      for (const std::string& id : ids) {
        if (Get(id).state() != v1::JOB_STATE_RUNNING) continue;
        bool ours = false;
        bool checkpointed = false;
        for (const auto& e : Events(id)) {
          if (e.kind() == "CLAIMED") {
            ours = e.message().find(owner) != std::string::npos;
            checkpointed = false;
          }
          checkpointed = checkpointed || e.kind() == "CHECKPOINT";
        }
        if (ours && checkpointed) return true;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return false;
  }

  int port_ = 0;
  int worker_starts_ = 0;
  ChildProcess steady_;
  ChildProcess killed_;
  std::unique_ptr<v1::WorkerService::Stub> worker_stub_;
};

TEST_F(RemoteWorkers, TwoWorkersDrainATwentyJobSweepThroughTwoSigkillsBitIdentical) {
  const v1::Sweep sweep = TwentyJobSweep();
  // The same sweep on seepd's own workers: the hashes every job must end with.
  Start("reference", {"--workers", "2", "--threads-per-job", "1"});
  const std::vector<std::string> reference_ids = JobIds(SubmitSweep(sweep));
  ASSERT_EQ(reference_ids.size(), 20u);
  std::vector<std::string> expected;
  // Deadlines here only bound a hang: under ASan on a busy 2-core machine the 20 jobs took 120 s.
  for (const auto& [id, job] : WaitAllTerminal(reference_ids, std::chrono::seconds(300))) {
    (void)id;
  }
  for (const std::string& id : reference_ids) {
    const v1::Job job = Get(id);
    ASSERT_EQ(job.state(), v1::JOB_STATE_SUCCEEDED) << job.DebugString();
    expected.push_back(job.result().state_sha256());
  }
  stub_.reset();
  ASSERT_EQ(server_.Stop(SIGTERM), 0);

  // A pure coordinator: it serves and rescues expired leases (every 0.5 s with --lease-s 2) and
  // runs nothing itself.
  StartCoordinator({"--workers", "0", "--lease-s", "2"});
  const std::vector<std::string> ids = JobIds(SubmitSweep(sweep));
  ASSERT_EQ(ids.size(), 20u);
  steady_ = StartWorker("steady", 30.0);
  // The worker that dies holds short leases, so that its jobs are rescued within a second or two.
  killed_ = StartWorker("killed", 1.0);
  for (int kill = 1; kill <= 2; ++kill) {
    ASSERT_TRUE(WaitUntilRunningPastACheckpoint(ids, "killed", killed_))
        << "the worker to kill never ran a job past a checkpoint (kill " << kill << ")";
    EXPECT_EQ(killed_.Stop(SIGKILL), 128 + SIGKILL);
    killed_ = StartWorker("killed", 1.0);
  }
  const auto jobs = WaitAllTerminal(ids, std::chrono::seconds(300));

  int rescued = 0;
  int resumed = 0;
  std::set<std::string> claimers;
  for (std::size_t i = 0; i < ids.size(); ++i) {
    const v1::Job& job = jobs.at(ids[i]);
    ASSERT_EQ(job.state(), v1::JOB_STATE_SUCCEEDED) << job.DebugString();
    EXPECT_EQ(job.result().state_sha256(), expected[i])
        << job.name() << ": final state differs from the run on seepd's own workers";
    int succeeded = 0;
    for (const auto& e : Events(ids[i])) {
      succeeded += e.kind() == "SUCCEEDED";
      rescued += e.kind() == "RESCUED";
      resumed += e.kind() == "RESUMED";
      if (e.kind() == "CLAIMED")
        claimers.insert(e.message().substr(e.message().find(" by ") + 4, 6));
    }
    // Every write is fenced by the lease epoch: one run only reaches the end.
    EXPECT_EQ(succeeded, 1) << job.name() << " ran to completion " << succeeded << " times";
  }
  // Both kills took a running job with them, which another claim continued from a checkpoint.
  EXPECT_GE(rescued, 2);
  EXPECT_GE(resumed, 2);
  EXPECT_EQ(claimers, (std::set<std::string>{"steady", "killed"}));
  // The coordinator ran nothing itself.
  EXPECT_EQ(Count(ReadFile(dir_ / "coordinator.out"), "started '"), 0u);
}

TEST_F(RemoteWorkers, BadWorkerCallsAreRefusedNamingTheFieldAndKeepNothing) {
  StartCoordinator({"--workers", "0", "--max-checkpoint-bytes", "4194304"});
  const std::string id = Submit(LatticeScene("bad-calls", 1e-3));
  const auto call = [](grpc::ClientContext& ctx) {
    ctx.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(10));
  };
  const auto expect_refused = [](const grpc::Status& status, grpc::StatusCode code,
                                 const std::string& names) {
    EXPECT_EQ(status.error_code(), code) << status.error_message();
    EXPECT_NE(status.error_message().find(names), std::string::npos) << status.error_message();
  };

  v1::ClaimJobResponse claimed;
  {
    grpc::ClientContext ctx;
    call(ctx);
    v1::ClaimJobRequest request;
    request.set_worker("test");
    request.set_lease_ms(100);
    expect_refused(worker_stub_->ClaimJob(&ctx, request, &claimed),
                   grpc::StatusCode::INVALID_ARGUMENT, "lease_ms: must be 500 .. 86400000");
  }
  {
    grpc::ClientContext ctx;
    call(ctx);
    v1::ClaimJobRequest request;
    request.set_worker("test");
    request.set_lease_ms(60000);
    ASSERT_TRUE(worker_stub_->ClaimJob(&ctx, request, &claimed).ok());
    ASSERT_EQ(claimed.job().id(), id);
    EXPECT_EQ(claimed.job().lease_epoch(), 1);
  }
  const auto heartbeat = [&](const std::string& job_id, std::int64_t epoch) {
    grpc::ClientContext ctx;
    call(ctx);
    v1::HeartbeatRequest request;
    request.mutable_lease()->set_job_id(job_id);
    request.mutable_lease()->set_lease_epoch(epoch);
    request.set_lease_ms(60000);
    v1::HeartbeatResponse response;
    return worker_stub_->Heartbeat(&ctx, request, &response);
  };
  expect_refused(heartbeat("j-0000000000000000", 1), grpc::StatusCode::NOT_FOUND,
                 "lease.job_id: no job j-0000000000000000");
  expect_refused(heartbeat(id, 2), grpc::StatusCode::ABORTED,
                 "lease.lease_epoch: job " + id + " is no longer running under lease epoch 2");
  expect_refused(heartbeat(id, 0), grpc::StatusCode::INVALID_ARGUMENT, "lease.lease_epoch");
  EXPECT_TRUE(heartbeat(id, 1).ok());

  // Uploads: the start, then the chunks given (index, payload); returns the status.
  const auto upload = [&](std::int64_t epoch, std::uint64_t declared, const std::string& sha,
                          const std::vector<std::pair<std::uint32_t, std::string>>& chunks,
                          v1::UploadCheckpointResponse* response) {
    grpc::ClientContext ctx;
    call(ctx);
    auto writer = worker_stub_->UploadCheckpoint(&ctx, response);
    v1::UploadCheckpointRequest start;
    start.mutable_start()->mutable_lease()->set_job_id(id);
    start.mutable_start()->mutable_lease()->set_lease_epoch(epoch);
    start.mutable_start()->set_build_id("test");
    start.mutable_start()->set_step(7);
    start.mutable_start()->set_state_bytes(declared);
    start.mutable_start()->set_state_sha256(sha);
    start.mutable_start()->set_keep(3);
    bool open = writer->Write(start);
    for (const auto& [index, payload] : chunks) {
      v1::UploadCheckpointRequest piece;
      piece.mutable_chunk()->set_index(index);
      piece.mutable_chunk()->set_payload(payload);
      open = open && writer->Write(piece);
    }
    if (open) writer->WritesDone();
    return writer->Finish();
  };
  // 2.5 MiB of state in three chunks (the coordinator does not parse it: a worker restores it).
  std::string state(5u << 19, '\0');
  for (std::size_t i = 0; i < state.size(); ++i) state[i] = static_cast<char>((i * 131) % 251);
  const std::string one_mib(1u << 20, 'x');
  const std::string sha = service::Sha256(state);
  const std::string wrong_sha(32, '\x01');
  v1::UploadCheckpointResponse uploaded;
  expect_refused(upload(1, 5u << 20, sha, {}, &uploaded), grpc::StatusCode::RESOURCE_EXHAUSTED,
                 "start.state_bytes: a checkpoint of 5242880 bytes is over the limit of 4194304");
  expect_refused(upload(2, state.size(), sha, {}, &uploaded), grpc::StatusCode::ABORTED,
                 "start.lease.lease_epoch");
  expect_refused(upload(1, state.size(), sha, {{1, one_mib}}, &uploaded),
                 grpc::StatusCode::INVALID_ARGUMENT, "chunk[0].index: chunks come in order");
  expect_refused(upload(1, state.size(), sha, {{0, std::string((1u << 20) + 1, 'x')}}, &uploaded),
                 grpc::StatusCode::INVALID_ARGUMENT, "chunk[0].payload: at most 1048576 bytes");
  expect_refused(upload(1, state.size(), sha, {{0, one_mib}}, &uploaded),
                 grpc::StatusCode::INVALID_ARGUMENT,
                 "start.state_bytes: the upload ended after 1048576 of 2621440 bytes");
  const std::vector<std::pair<std::uint32_t, std::string>> whole = {
      {0, state.substr(0, 1u << 20)},
      {1, state.substr(1u << 20, 1u << 20)},
      {2, state.substr(2u << 20)}};
  expect_refused(upload(1, state.size(), wrong_sha, whole, &uploaded), grpc::StatusCode::DATA_LOSS,
                 "start.state_sha256: the bytes received do not have this SHA-256");

  const auto download = [&](v1::CheckpointDownloadStart* start_out, std::string* state_out) {
    grpc::ClientContext ctx;
    call(ctx);
    v1::DownloadCheckpointRequest request;
    request.mutable_lease()->set_job_id(id);
    request.mutable_lease()->set_lease_epoch(1);
    auto reader = worker_stub_->DownloadCheckpoint(&ctx, request);
    v1::DownloadCheckpointResponse message;
    while (reader->Read(&message)) {
      if (message.has_start()) *start_out = message.start();
      if (message.has_chunk()) *state_out += message.chunk().payload();
    }
    return reader->Finish();
  };
  // Nothing of the refused uploads was kept.
  v1::CheckpointDownloadStart found;
  std::string downloaded;
  ASSERT_TRUE(download(&found, &downloaded).ok());
  EXPECT_FALSE(found.found());
  for (const auto& e : Events(id)) EXPECT_NE(e.kind(), "CHECKPOINT") << e.message();
  EXPECT_FALSE(std::filesystem::exists(dir_ / "coordinator" / "checkpoints" / id));

  // The whole upload is kept as a checkpoint file of the coordinator, and comes back intact.
  ASSERT_TRUE(upload(1, state.size(), sha, whole, &uploaded).ok());
  EXPECT_GT(uploaded.file_bytes(), static_cast<std::int64_t>(state.size()));
  ASSERT_TRUE(download(&found, &downloaded).ok());
  ASSERT_TRUE(found.found());
  EXPECT_EQ(found.step(), 7u);
  EXPECT_EQ(found.name(), "ckpt-000000000007.bin");
  EXPECT_EQ(found.state_sha256(), sha);
  EXPECT_TRUE(downloaded == state) << "the downloaded state differs from the uploaded one";

  // FinishJob with a state that does not end a job, and with a stale epoch.
  {
    grpc::ClientContext ctx;
    call(ctx);
    v1::FinishJobRequest request;
    request.mutable_lease()->set_job_id(id);
    request.mutable_lease()->set_lease_epoch(1);
    request.set_state(v1::JOB_STATE_RUNNING);
    v1::FinishJobResponse response;
    expect_refused(worker_stub_->FinishJob(&ctx, request, &response),
                   grpc::StatusCode::INVALID_ARGUMENT,
                   "state: must be JOB_STATE_SUCCEEDED, _FAILED or _CANCELLED (got "
                   "JOB_STATE_RUNNING)");
  }
  {
    grpc::ClientContext ctx;
    call(ctx);
    v1::FinishJobRequest request;
    request.mutable_lease()->set_job_id(id);
    request.mutable_lease()->set_lease_epoch(5);
    request.set_state(v1::JOB_STATE_FAILED);
    v1::FinishJobResponse response;
    expect_refused(worker_stub_->FinishJob(&ctx, request, &response), grpc::StatusCode::ABORTED,
                   "lease.lease_epoch");
  }
  EXPECT_EQ(Get(id).state(), v1::JOB_STATE_RUNNING);
}

// KeepLease, the stream seep-worker beats on: beats renew the lease (a job leased for 2 s stays
// RUNNING, never rescued, through 4 s of beats every 0.5 s) and carry progress; a pending cancel is
// news, once; a beat of a lost lease ends the stream ABORTED naming the epoch, one naming another
// lease INVALID_ARGUMENT, a renewal of 0 ms without progress INVALID_ARGUMENT naming lease_ms.
TEST_F(RemoteWorkers, KeepLeaseBeatsRenewTheLeaseCarryProgressAndEndOnALostLease) {
  StartCoordinator({"--workers", "0"});
  const std::string id = Submit(LatticeScene("beats", 1e-3));
  v1::ClaimJobResponse claimed;
  {
    grpc::ClientContext ctx;
    v1::ClaimJobRequest request;
    request.set_worker("test");
    request.set_lease_ms(2000);
    ASSERT_TRUE(worker_stub_->ClaimJob(&ctx, request, &claimed).ok());
    ASSERT_EQ(claimed.job().id(), id);
  }
  const auto beat = [&](const std::string& job_id, std::int64_t epoch, std::uint32_t lease_ms,
                        std::optional<std::uint64_t> step) {
    v1::LeaseBeat b;
    b.mutable_lease()->set_job_id(job_id);
    b.mutable_lease()->set_lease_epoch(epoch);
    b.set_lease_ms(lease_ms);
    if (step) b.mutable_progress()->set_step(*step);
    return b;
  };
  const auto deadline = [](grpc::ClientContext& ctx) {
    ctx.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(30));
  };
  {
    grpc::ClientContext ctx;
    deadline(ctx);
    auto stream = worker_stub_->KeepLease(&ctx);
    // A beat every quarter lease, as the runner's heartbeats come (seepd rewrites the expiry
    // only once less than half a lease is left).
    for (std::uint64_t i = 1; i <= 8; ++i) {
      ASSERT_TRUE(stream->Write(beat(id, 1, 2000, 100 * i)));
      std::this_thread::sleep_for(std::chrono::milliseconds(500));
    }
    const v1::Job job = Get(id);
    EXPECT_EQ(job.state(), v1::JOB_STATE_RUNNING) << "the beats did not keep the 2 s lease";
    EXPECT_EQ(job.progress().step(), 800u);
    for (const auto& e : Events(id)) EXPECT_NE(e.kind(), "RESCUED");

    // A cancel: the next beat's answer says so, and only once.
    {
      grpc::ClientContext cancel_ctx;
      Prepare(cancel_ctx);
      v1::CancelJobRequest request;
      request.set_id(id);
      v1::CancelJobResponse response;
      ASSERT_TRUE(stub_->CancelJob(&cancel_ctx, request, &response).ok());
    }
    ASSERT_TRUE(stream->Write(beat(id, 1, 2000, std::nullopt)));
    v1::LeaseNews news;
    ASSERT_TRUE(stream->Read(&news));
    EXPECT_TRUE(news.cancel_requested());
    ASSERT_TRUE(stream->Write(beat(id, 1, 2000, std::nullopt)));
    stream->WritesDone();
    EXPECT_FALSE(stream->Read(&news)) << "a second cancel news";
    const grpc::Status ended = stream->Finish();
    EXPECT_TRUE(ended.ok()) << ended.error_message();
  }
  // Beats the stream refuses, each ending it with the unary call's status.
  const auto refused = [&](const std::vector<v1::LeaseBeat>& beats) {
    grpc::ClientContext ctx;
    deadline(ctx);
    auto stream = worker_stub_->KeepLease(&ctx);
    for (const v1::LeaseBeat& b : beats) {
      if (!stream->Write(b)) break;
    }
    stream->WritesDone();
    v1::LeaseNews news;
    while (stream->Read(&news)) {
    }
    return stream->Finish();
  };
  const grpc::Status stale = refused({beat(id, 2, 2000, std::nullopt)});
  EXPECT_EQ(stale.error_code(), grpc::StatusCode::ABORTED) << stale.error_message();
  EXPECT_NE(stale.error_message().find("lease.lease_epoch: job " + id +
                                       " is no longer running under lease epoch 2"),
            std::string::npos)
      << stale.error_message();
  const grpc::Status other =
      refused({beat(id, 1, 2000, std::nullopt), beat("j-0000000000000000", 1, 2000, 5)});
  EXPECT_EQ(other.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << other.error_message();
  EXPECT_NE(other.error_message().find("every beat of a KeepLease stream names the lease of its "
                                       "first (job " +
                                       id + ", epoch 1)"),
            std::string::npos)
      << other.error_message();
  const grpc::Status empty = refused({beat(id, 1, 0, std::nullopt)});
  EXPECT_EQ(empty.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << empty.error_message();
  EXPECT_NE(empty.error_message().find("lease_ms: a beat without progress renews the lease"),
            std::string::npos)
      << empty.error_message();
  // The refused beats kept nothing: the progress is still the stream's last.
  EXPECT_EQ(Get(id).progress().step(), 800u);
}

TEST_F(RemoteWorkers, ATokenIsRequiredAndASigtermedWorkerGivesItsJobBack) {
  v1::Scene scene = LatticeScene("given-back", 8e-2);
  Start("reference", {"--workers", "1"});
  const v1::Job reference = WaitTerminal(Submit(scene));
  ASSERT_EQ(reference.state(), v1::JOB_STATE_SUCCEEDED) << reference.DebugString();
  stub_.reset();
  ASSERT_EQ(server_.Stop(SIGTERM), 0);

  token_ = "remote-worker-token-0123456789";
  const std::filesystem::path token_file = dir_ / "token";
  std::ofstream(token_file) << token_ << "\n";
  std::filesystem::permissions(
      token_file, std::filesystem::perms::owner_read | std::filesystem::perms::owner_write);
  StartCoordinator({"--workers", "0", "--lease-s", "2", "--token-file", token_file.string()});
  const std::string id = Submit(scene);
  // Without the token a worker claims nothing: every call is UNAUTHENTICATED.
  steady_ = StartWorker("tokenless", 30.0);
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));
  EXPECT_EQ(steady_.Stop(SIGTERM), 0);
  EXPECT_EQ(Get(id).state(), v1::JOB_STATE_QUEUED);
  EXPECT_NE(ReadFile(dir_ / "tokenless-1.out").find("UNAUTHENTICATED"), std::string::npos);
  // The lease stream too (authenticated once, when it opens).
  {
    grpc::ClientContext ctx;
    ctx.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(10));
    auto stream = worker_stub_->KeepLease(&ctx);
    v1::LeaseBeat beat;
    beat.mutable_lease()->set_job_id(id);
    beat.mutable_lease()->set_lease_epoch(1);
    beat.set_lease_ms(2000);
    (void)stream->Write(beat);
    stream->WritesDone();
    v1::LeaseNews news;
    while (stream->Read(&news)) {
    }
    const grpc::Status refused = stream->Finish();
    EXPECT_EQ(refused.error_code(), grpc::StatusCode::UNAUTHENTICATED) << refused.error_message();
    EXPECT_EQ(Get(id).state(), v1::JOB_STATE_QUEUED);
  }

  // With it (the CLI's --token-file), it runs the job; SIGTERM checkpoints the job and gives it
  // back, and the coordinator queues it again for the next worker, which continues from there.
  steady_ = StartWorker("first", 30.0, {"--token-file", token_file.string()});
  ASSERT_TRUE(WaitUntilRunningPastACheckpoint({id}, "first", steady_));
  EXPECT_EQ(steady_.Stop(SIGTERM), 0);
  const auto queued_again = std::chrono::steady_clock::now();
  for (;;) {
    const v1::JobState state = Get(id).state();
    if (state != v1::JOB_STATE_RUNNING) {
      EXPECT_EQ(state, v1::JOB_STATE_QUEUED);
      break;
    }
    ASSERT_LT(std::chrono::steady_clock::now() - queued_again, std::chrono::seconds(10))
        << "the job given back was not queued again";
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  killed_ = StartWorker("second", 30.0, {"--token-file", token_file.string()});
  v1::Job done;
  for (const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);;) {
    done = Get(id);
    if (done.state() == v1::JOB_STATE_SUCCEEDED || std::chrono::steady_clock::now() > deadline) {
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  ASSERT_EQ(done.state(), v1::JOB_STATE_SUCCEEDED) << done.DebugString();
  EXPECT_EQ(done.result().state_sha256(), reference.result().state_sha256());
  std::vector<std::string> kinds;
  for (const auto& e : Events(id)) kinds.push_back(e.kind());
  const auto has = [&](const std::string& kind) {
    return std::find(kinds.begin(), kinds.end(), kind) != kinds.end();
  };
  EXPECT_TRUE(has("INTERRUPTED") && has("RESCUED") && has("RESUMED"))
      << ::testing::PrintToString(kinds);
  EXPECT_EQ(std::count(kinds.begin(), kinds.end(), "SUCCEEDED"), 1);
}

}  // namespace
}  // namespace seep::testing
