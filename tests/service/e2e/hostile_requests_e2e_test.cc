// Requests a careless or hostile client sends, through a real seepd: sizes that would make
// seepd build millions of things before a limit applies are refused first, naming the field;
// an overlong id is refused without being echoed; a step count past what a run can count is
// refused, not run for one step and reported SUCCEEDED; a scene the core cannot run is refused
// while seepd stays up (the same pid) and runs the next job; undecodable bytes are
// INVALID_ARGUMENT naming the message. And what seepd leaves on disk: its files its owner's
// alone whatever the umask, a loose data folder warned about (or refused), no forged log line,
// and a lost checkpoint named from the data folder on, not by the server's absolute path.
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <grpcpp/impl/client_unary_call.h>
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <fstream>
#include <sstream>

#include "../test_support.h"
#include "grpc_seepd_fixture.h"

namespace seep::testing {
namespace {

class HostileRequests : public GrpcSeepdTest {
 protected:
  HostileRequests() : GrpcSeepdTest("e2e-hostile") {}

  // seepd's peak resident memory (VmHWM of /proc/<pid>/status) in bytes; 0 when unreadable.
  std::size_t PeakRss() const {
    std::ifstream in("/proc/" + std::to_string(server_.pid()) + "/status");
    for (std::string line; std::getline(in, line);) {
      if (line.rfind("VmHWM:", 0) != 0) continue;
      std::istringstream fields(line.substr(6));
      std::size_t kib = 0;
      fields >> kib;
      return kib * 1024;
    }
    return 0;
  }

  grpc::Status SubmitSweepStatus(const v1::Sweep& sweep) {
    grpc::ClientContext ctx;
    Prepare(ctx);
    v1::SubmitSweepRequest request;
    *request.mutable_sweep() = sweep;
    v1::SubmitSweepResponse response;
    return stub_->SubmitSweep(&ctx, request, &response);
  }

  // The scene submitted: the refusal's status, or OK and the job as it ended.
  std::pair<grpc::Status, v1::Job> SubmitAndEnd(const v1::Scene& scene) {
    grpc::ClientContext ctx;
    Prepare(ctx);
    v1::SubmitJobRequest request;
    *request.mutable_scene() = scene;
    v1::SubmitJobResponse response;
    const grpc::Status status = stub_->SubmitJob(&ctx, request, &response);
    if (!status.ok()) return {status, {}};
    // These jobs end within a second when refused; a minute bounds a seepd that went down.
    return {status,
            WaitFor(
                response.job().id(), [](const v1::Job& j) { return IsTerminalState(j.state()); },
                std::chrono::seconds(60))};
  }

  // Refused at submit (INVALID_ARGUMENT) or FAILED, either way with `field` in the reason.
  void ExpectRefusedOrFailedNaming(const v1::Scene& scene, const std::string& field) {
    const auto [status, job] = SubmitAndEnd(scene);
    if (!status.ok()) {
      EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << scene.name();
      EXPECT_NE(status.error_message().find(field), std::string::npos)
          << scene.name() << ": " << status.error_message();
      return;
    }
    EXPECT_EQ(job.state(), v1::JOB_STATE_FAILED) << scene.name() << ": " << job.DebugString();
    EXPECT_NE(job.error().message().find(field), std::string::npos)
        << scene.name() << ": " << job.error().message();
  }
};

TEST_F(HostileRequests, HugeSweepCountsAndListsAreRefusedNamingTheFieldBeforeAnyWork) {
  Start("data", {"--workers", "1"});
  v1::Sweep sweep;
  v1::Scene& base = *sweep.mutable_scene();
  base = LatticeScene("huge-sweep", 1e-3);
  // Any unsigned field serves as the seed: the count is what is under test.
  sweep.mutable_replicates()->set_seed_path("packing.lattice.columns");
  const auto expect_refused = [&](const v1::Sweep& request, const std::string& start) {
    const grpc::Status status = SubmitSweepStatus(request);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << start;
    EXPECT_EQ(status.error_message().rfind(start, 0), 0u) << status.error_message();
  };
  for (const std::uint32_t count : {4'294'967'295u, 100'000'000u, 10'001u}) {
    sweep.mutable_replicates()->set_count(count);
    expect_refused(sweep, "sweep.replicates.count: " + std::to_string(count) + " replicates");
  }
  // Two million explicit seeds: 2 MB on the wire, hundreds of MB once built as settings.
  sweep.mutable_replicates()->set_count(0);
  sweep.mutable_replicates()->mutable_seeds()->Resize(2'000'000, 7);
  expect_refused(sweep, "sweep.replicates.seeds: 2000000 seeds");
  sweep.clear_replicates();
  v1::SweepAxis& axis = *sweep.add_axes();
  axis.set_path("boundary.inlet_pressure_pa");
  axis.mutable_numbers()->Resize(2'000'000, 1e5);
  sweep.set_combine(v1::SWEEP_COMBINE_PRODUCT);
  expect_refused(sweep, "sweep.axes[0]: 2000000 values");
  // Nothing was built in proportion: seepd's peak stays far below what one of these needed.
  const std::size_t peak = PeakRss();
  ASSERT_GT(peak, 0u) << "cannot read seepd's VmHWM";
  EXPECT_LT(peak, std::size_t{300} << 20) << "seepd peaked at " << (peak >> 20) << " MiB";
}

TEST_F(HostileRequests, AnOverlongIdNameOrListIsRefusedShortlyWithoutEchoingIt) {
  Start("data", {"--workers", "1"});
  const std::string long_id(16 * 1024, 'j');
  const auto expect_short_refusal = [&](const grpc::Status& status, const std::string& field) {
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << field;
    EXPECT_EQ(status.error_message().rfind(field + ": at most ", 0), 0u) << field;
    EXPECT_LT(status.error_message().size(), 200u) << status.error_message().substr(0, 300);
  };
  {
    grpc::ClientContext ctx;
    Prepare(ctx);
    v1::GetJobRequest request;
    request.set_id(long_id);
    v1::GetJobResponse response;
    expect_short_refusal(stub_->GetJob(&ctx, request, &response), "id");
  }
  {
    grpc::ClientContext ctx;
    Prepare(ctx);
    v1::CancelSweepRequest request;
    request.set_id(long_id);
    v1::CancelSweepResponse response;
    expect_short_refusal(stub_->CancelSweep(&ctx, request, &response), "id");
  }
  {
    grpc::ClientContext ctx;
    Prepare(ctx);
    v1::SubmitJobRequest request;
    *request.mutable_scene() = LatticeScene("fork", 1e-3);
    request.set_from_job_id(long_id);
    v1::SubmitJobResponse response;
    expect_short_refusal(stub_->SubmitJob(&ctx, request, &response), "from_job_id");
  }
  {
    grpc::ClientContext ctx;
    Prepare(ctx);
    v1::SubmitJobRequest request;
    *request.mutable_scene() = LatticeScene(std::string(16 * 1024, 'n'), 1e-3);
    v1::SubmitJobResponse response;
    expect_short_refusal(stub_->SubmitJob(&ctx, request, &response), "scene.name");
  }
  {
    grpc::ClientContext ctx;
    Prepare(ctx);
    v1::ListJobsRequest request;
    for (int i = 0; i < 100'000; ++i) request.add_states(v1::JOB_STATE_QUEUED);
    v1::ListJobsResponse response;
    expect_short_refusal(stub_->ListJobs(&ctx, request, &response), "states");
  }
  {
    grpc::ClientContext ctx;
    Prepare(ctx);
    v1::ListCalibrationsRequest request;
    for (int i = 0; i < 10'000; ++i) request.add_tags("t");
    v1::ListCalibrationsResponse response;
    expect_short_refusal(stub_->ListCalibrations(&ctx, request, &response), "tags");
  }
  // A short unknown id is still NOT_FOUND, naming it.
  grpc::ClientContext ctx;
  Prepare(ctx);
  v1::GetJobRequest request;
  request.set_id("j-0123456789abcdef");
  v1::GetJobResponse response;
  const grpc::Status status = stub_->GetJob(&ctx, request, &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::NOT_FOUND);
  EXPECT_NE(status.error_message().find("j-0123456789abcdef"), std::string::npos);
}

TEST_F(HostileRequests, StepCountsPastCountingAreRefusedNotRunForOneStep) {
  Start("data", {"--workers", "1"});
  struct Case {
    const char* name;
    double end_time_s;
    double dt_factor;
    v1::SolverKind kind;
    const char* field;
  };
  const Case cases[] = {
      {"explicit-end-1e15", 1e15, 0.9, v1::SOLVER_KIND_EXPLICIT, "solver.end_time_s"},
      {"explicit-end-1e300", 1e300, 0.9, v1::SOLVER_KIND_EXPLICIT, "solver.end_time_s"},
      {"explicit-dt-1e-20", 4e-3, 1e-20, v1::SOLVER_KIND_EXPLICIT, "solver.dt_factor"},
      {"implicit-end-1e15", 1e15, 1.0, v1::SOLVER_KIND_IMPLICIT, "solver.end_time_s"},
      {"implicit-dt-1e-20", 4e-3, 1e-20, v1::SOLVER_KIND_IMPLICIT, "solver.dt_factor"},
      {"implicit-dt-1e-300", 4e-3, 1e-300, v1::SOLVER_KIND_IMPLICIT, "solver.dt_factor"},
  };
  for (const Case& c : cases) {
    v1::Scene scene = LatticeScene(c.name, c.end_time_s);
    scene.mutable_solver()->set_kind(c.kind);
    scene.mutable_solver()->set_dt_factor(c.dt_factor);
    ExpectRefusedOrFailedNaming(scene, c.field);
  }
  // A scene whose disks move (its step from the contacts), asked to reach 1e15 s, or with a
  // step of 1e-20 of the stable one.
  v1::Scene moving = ExampleScene("hydraulic_fracturing.textproto");
  moving.set_name("moving-end-1e15");
  moving.mutable_solver()->set_end_time_s(1e15);
  ExpectRefusedOrFailedNaming(moving, "solver.end_time_s");
  moving = ExampleScene("hydraulic_fracturing.textproto");
  moving.set_name("moving-dt-safety-1e-20");
  bool planted = false;
  for (v1::Effect& effect : *moving.mutable_effects()) {
    if (!effect.has_contacts()) continue;
    effect.mutable_contacts()->set_dt_safety(1e-20);
    planted = true;
  }
  ASSERT_TRUE(planted) << "the example has no contacts effect";
  ExpectRefusedOrFailedNaming(moving, "contacts.dt_safety");
}

TEST_F(HostileRequests, AFrozenPackingWithGravityAloneIsRefusedAndSeepdRunsTheNextJob) {
  Start("data", {"--workers", "1"});
  const pid_t pid = server_.pid();
  v1::Scene scene = LatticeScene("frozen-gravity", 2e-3);
  scene.mutable_solver()->set_kind(v1::SOLVER_KIND_IMPLICIT);
  scene.mutable_solver()->set_dt_factor(1.0);
  scene.mutable_fluid()->set_density_kg_m3(1000.0);
  scene.add_effects()->mutable_gravity()->set_gy_m_s2(-9.81);
  const auto [status, job] = SubmitAndEnd(scene);
  const std::string reason = status.ok() ? job.error().message() : status.error_message();
  if (status.ok()) {
    EXPECT_EQ(job.state(), v1::JOB_STATE_FAILED) << job.DebugString();
  } else {
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << reason;
  }
  for (const char* part : {"scene.effects", "flow"}) {
    EXPECT_NE(reason.find(part), std::string::npos) << part << " not in: " << reason;
  }
  // seepd is the same process and still runs jobs.
  const v1::Job next = WaitTerminal(Submit(LatticeScene("after-the-refusal", 1e-3)));
  EXPECT_EQ(next.state(), v1::JOB_STATE_SUCCEEDED) << next.DebugString();
  EXPECT_EQ(server_.PollExit(), -1) << "seepd ended";
  EXPECT_EQ(server_.pid(), pid);
}

TEST_F(HostileRequests, UndecodableBytesAreInvalidArgumentNamingTheMessage) {
  Start("data", {"--workers", "1"});
  const int port = WaitForPortFile((dir_ / "data.port").string(), std::chrono::seconds(5));
  auto channel =
      grpc::CreateChannel("127.0.0.1:" + std::to_string(port), grpc::InsecureChannelCredentials());
  // A field tag of wire type 7 (none exists), then bytes that go nowhere.
  const std::string garbage = "\xff\xff\xff\xff\x0f\x07junk";
  grpc::Slice slice(garbage);
  grpc::ByteBuffer request(&slice, 1);
  grpc::ByteBuffer response;
  grpc::ClientContext ctx;
  Prepare(ctx);
  const grpc::internal::RpcMethod method("/seep.v1.SeepService/GetJob",
                                         grpc::internal::RpcMethod::NORMAL_RPC);
  const grpc::Status status = grpc::internal::BlockingUnaryCall<grpc::ByteBuffer, grpc::ByteBuffer>(
      channel.get(), method, &ctx, request, &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << status.error_message();
  EXPECT_EQ(status.error_message().rfind("GetJob: the request's bytes do not decode as "
                                         "seep.v1.GetJobRequest",
                                         0),
            0u)
      << status.error_message();
  // A well-formed call on the same channel is served as before.
  EXPECT_EQ(Get(Submit(LatticeScene("after-garbage", 1e-3))).name(), "after-garbage");
}

// Every file under `root` (itself included) whose mode lets group or others in.
std::vector<std::string> LooseEntries(const std::filesystem::path& root) {
  std::vector<std::string> loose;
  const auto check = [&](const std::filesystem::path& path) {
    struct stat st {};
    if (::lstat(path.c_str(), &st) != 0) return;
    const mode_t want = S_ISDIR(st.st_mode) ? 0700 : 0600;
    if ((st.st_mode & 0777) != want) {
      loose.push_back(fmt::format("{} {:o}", path.string(), st.st_mode & 0777));
    }
  };
  check(root);
  for (const auto& entry : std::filesystem::recursive_directory_iterator(root)) {
    check(entry.path());
  }
  return loose;
}

TEST_F(HostileRequests, SeepdsFilesAreItsOwnersAloneWhateverTheUmask) {
  const mode_t before = ::umask(022);
  Start("data", {"--workers", "1", "--checkpoint-every-steps", "50"});
  ::umask(before);
  const v1::Job done = WaitTerminal(Submit(LatticeScene("private", 2e-3)));
  EXPECT_EQ(done.state(), v1::JOB_STATE_SUCCEEDED) << done.DebugString();
  const std::filesystem::path data = dir_ / "data";
  for (const char* name : {"seep.db", "seep.db-wal", "seep.db-shm", "seepd.log"}) {
    EXPECT_TRUE(std::filesystem::exists(data / name)) << name;
  }
  const std::vector<std::string> loose = LooseEntries(data);
  EXPECT_TRUE(loose.empty()) << fmt::format("{}", fmt::join(loose, "; "));
  struct stat port {};
  ASSERT_EQ(::stat((dir_ / "data.port").c_str(), &port), 0);
  EXPECT_EQ(port.st_mode & 0777, 0600u);
}

TEST_F(HostileRequests, ALooseDataFolderIsWarnedAboutOrRefusedByFlag) {
  const std::filesystem::path data = dir_ / "loose";
  std::filesystem::create_directories(data);
  ::chmod(data.c_str(), 0755);
  // --strict-permissions: refused before anything is written into it.
  std::vector<std::string> argv = SeepdArgv("loose", (dir_ / "strict.port").string());
  argv.push_back("--strict-permissions");
  const CommandResult refused = RunCommand(argv);
  EXPECT_EQ(refused.exit_code, 2) << refused.output;
  EXPECT_NE(refused.output.find("is open to group or others"), std::string::npos) << refused.output;
  EXPECT_TRUE(std::filesystem::is_empty(data));
  // Without the flag: a warning in the log, and seepd serves.
  Start("loose", {"--workers", "0"});
  const std::string log = ReadFile(data / "seepd.log");
  EXPECT_NE(log.find("is open to group or others (mode bits 055)"), std::string::npos) << log;
}

TEST_F(HostileRequests, AControlCharacterInANameCannotForgeALogLine) {
  Start("data", {"--workers", "1"});
  const std::string forged = "2030-01-01T00:00:00.000 [seepd] info: job j-0 deleted";
  const v1::Job done = WaitTerminal(Submit(LatticeScene("evil\n" + forged + "\r\x1b[2J", 1e-3)));
  EXPECT_EQ(done.state(), v1::JOB_STATE_SUCCEEDED) << done.DebugString();
  const std::string log = ReadFile(dir_ / "data" / "seepd.log");
  EXPECT_EQ(log.find("\n" + forged), std::string::npos) << log;
  EXPECT_NE(log.find("('evil\\n" + forged + "\\r\\x1b[2J')"), std::string::npos) << log;
}

TEST_F(HostileRequests, ALostCheckpointIsNamedFromTheDataFolderOn) {
  Start("data", {"--workers", "1", "--checkpoint-every-steps", "300"});
  const std::string id = Submit(LatticeScene("lost-checkpoint", 3e-3));
  ASSERT_EQ(WaitTerminal(id).state(), v1::JOB_STATE_SUCCEEDED);
  // Its periodic checkpoints are files (its final state is in the store): all of them go.
  const std::filesystem::path folder = dir_ / "data" / "checkpoints" / id;
  std::uint64_t step = 0;
  for (const auto& entry : std::filesystem::directory_iterator(folder)) {
    const std::string name = entry.path().filename().string();  // ckpt-<12 digits>.bin
    step = std::max<std::uint64_t>(step, std::stoull(name.substr(5, 12)));
    std::filesystem::remove(entry.path());
  }
  ASSERT_GT(step, 0u) << "no checkpoint file in " << folder;
  grpc::ClientContext ctx;
  Prepare(ctx);
  v1::GetJobFieldsRequest request;
  request.set_job_id(id);
  request.set_step(step);
  v1::GetJobFieldsResponse response;
  const grpc::Status status = stub_->GetJobFields(&ctx, request, &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::DATA_LOSS) << status.error_message();
  EXPECT_NE(status.error_message().find("checkpoints/" + id + "/ckpt-"), std::string::npos)
      << status.error_message();
  EXPECT_EQ(status.error_message().find(dir_.string()), std::string::npos)
      << status.error_message();
}

}  // namespace
}  // namespace seep::testing
