// Jobs isolated in worker processes (seepd --isolation process, the default), on a real seepd: a
// job that segfaults, or outgrows its memory limit, fails alone, naming the cause, while another
// job on the same seepd finishes with the bits of its run on seepd's own threads, and seepd keeps
// its pid; a set-up longer than the lease keeps its lease; a set-up that a cancel or the time
// limit cannot stop at a step is ended with its process, and the worker takes the next job;
// seepd's worker processes end with it, even when it is killed.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/types.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <set>

#include "grpc_seepd_fixture.h"

namespace seep::testing {
namespace {

// A random packing whose set-up (the packing's growth) takes a minute or more: no step, so no
// stop at a step boundary, within any of these tests.
v1::Scene LongSetUpScene(const std::string& name) {
  v1::Scene scene = LatticeScene(name, 1e-5);
  v1::RandomPacking& random = *scene.mutable_packing()->mutable_random();
  random.set_seed(5);
  random.set_width_m(0.4);
  random.set_height_m(0.4);
  random.set_min_radius_m(0.8e-3);
  random.set_max_radius_m(1.0e-3);
  random.set_particle_count(40000);
  random.set_target_porosity(0.2);
  scene.mutable_packing()->set_contact_gap_m(2e-5);
  return scene;
}

// The seep-worker processes whose parent is `parent`.
std::set<pid_t> WorkersOf(pid_t parent) {
  std::set<pid_t> pids;
  for (const auto& entry : std::filesystem::directory_iterator("/proc")) {
    const std::string name = entry.path().filename().string();
    if (name.find_first_not_of("0123456789") != std::string::npos) continue;
    std::ifstream status(entry.path() / "status");
    bool worker = false;
    for (std::string line; std::getline(status, line);) {
      if (line.rfind("Name:", 0) == 0) worker = line.find("seep-worker") != std::string::npos;
      if (worker && line.rfind("PPid:", 0) == 0 && std::stol(line.substr(5)) == parent) {
        pids.insert(static_cast<pid_t>(std::stol(name)));
      }
    }
  }
  return pids;
}

// Whether `pid` is a live seep-worker (not gone, not a zombie, not a reused pid).
bool IsLiveWorker(pid_t pid) {
  std::ifstream status("/proc/" + std::to_string(pid) + "/status");
  bool worker = false;
  for (std::string line; std::getline(status, line);) {
    if (line.rfind("Name:", 0) == 0) worker = line.find("seep-worker") != std::string::npos;
    if (line.rfind("State:", 0) == 0) return worker && line.find('Z') == std::string::npos;
  }
  return false;
}

class JobIsolation : public GrpcSeepdTest {
 protected:
  JobIsolation() : GrpcSeepdTest("e2e-isolation") {}

  int CountEvents(const std::string& id, const std::string& kind) {
    int count = 0;
    for (const auto& event : Events(id)) count += event.kind() == kind ? 1 : 0;
    return count;
  }
  bool HasEvent(const std::string& id, const std::string& kind) {
    return CountEvents(id, kind) > 0;
  }

  void Cancel(const std::string& id) {
    grpc::ClientContext ctx;
    Prepare(ctx);
    v1::CancelJobRequest request;
    request.set_id(id);
    v1::CancelJobResponse response;
    const grpc::Status status = stub_->CancelJob(&ctx, request, &response);
    ASSERT_TRUE(status.ok()) << status.error_message();
  }

  // A short job on seepd after a job was ended with its process: SUCCEEDED, so the worker slot
  // took a job again.
  void ExpectTheWorkerRunsTheNextJob() {
    const v1::Job next = WaitFor(
        Submit(LatticeScene("next", 1e-3)),
        [](const v1::Job& j) { return IsTerminalState(j.state()); }, std::chrono::seconds(60));
    EXPECT_EQ(next.state(), v1::JOB_STATE_SUCCEEDED) << next.DebugString();
  }
};

TEST_F(JobIsolation, ASegfaultFailsItsJobAloneNamingTheSignalWhileAnotherFinishesBitIdentical) {
  // The neighbour's bits from seepd's own threads: processes and threads run the same physics.
  const v1::Scene neighbour = LatticeScene("neighbour", 1e-2);
  const std::vector<std::string> expected = ReferenceHashes(
      {neighbour}, {"--isolation", "thread", "--workers", "1", "--threads-per-job", "1"});
  Start("data", {"--workers", "2", "--threads-per-job", "1", "--test-segfault-job", "crasher"});
  const pid_t seepd = server_.pid();
  const std::string crasher = Submit(LatticeScene("crasher", 1e-2));
  const std::string neighbour_id = Submit(neighbour);
  auto jobs = WaitAllTerminal({crasher, neighbour_id}, std::chrono::seconds(120));
  const v1::Job& failed = jobs[crasher];
  ASSERT_EQ(failed.state(), v1::JOB_STATE_FAILED) << failed.DebugString();
  EXPECT_EQ(failed.error().code(), "INTERNAL");
  const std::string& why = failed.error().message();
  EXPECT_NE(why.find("was killed by signal 11 (SIGSEGV"), std::string::npos) << why;
  EXPECT_NE(why.find("its last progress stored: step"), std::string::npos) << why;
  // The last lines its process logged, the hook's own among them.
  EXPECT_NE(why.find("test hook --test-segfault-job: a segmentation fault"), std::string::npos)
      << why;
  EXPECT_TRUE(HasEvent(crasher, "WORKER_DIED"));
  EXPECT_EQ(jobs[neighbour_id].state(), v1::JOB_STATE_SUCCEEDED);
  EXPECT_EQ(jobs[neighbour_id].result().state_sha256(), expected[0]);
  EXPECT_TRUE(server_.running());
  EXPECT_EQ(server_.pid(), seepd);
  ExpectTheWorkerRunsTheNextJob();
  ExpectTheWorkerRunsTheNextJob();  // both slots: the crashed one was restarted
}

TEST_F(JobIsolation, AJobPastItsMemoryLimitFailsNamingTheLimitWhileAnotherFinishesBitIdentical) {
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "an address-space limit (RLIMIT_AS) and AddressSanitizer's shadow memory do "
                  "not mix: the Release suite runs this";
#endif
  const v1::Scene neighbour = LatticeScene("neighbour", 1e-2);
  const std::vector<std::string> expected = ReferenceHashes(
      {neighbour}, {"--isolation", "thread", "--workers", "1", "--threads-per-job", "1"});
  // --test-hog-memory-job: the job allocates 1500 steps in until an allocation fails.
  Start("data", {"--workers", "2", "--threads-per-job", "1", "--job-memory-limit-mb", "700",
                 "--test-hog-memory-job", "hog"});
  const pid_t seepd = server_.pid();
  const std::string hog = Submit(LatticeScene("hog", 1e-2));
  const std::string neighbour_id = Submit(neighbour);
  auto jobs = WaitAllTerminal({hog, neighbour_id}, std::chrono::seconds(120));
  const v1::Job& failed = jobs[hog];
  ASSERT_EQ(failed.state(), v1::JOB_STATE_FAILED) << failed.DebugString();
  EXPECT_EQ(failed.error().code(), "RESOURCE_EXHAUSTED");
  EXPECT_NE(failed.error().message().find("limited to 700 MiB (seepd --job-memory-limit-mb)"),
            std::string::npos)
      << failed.error().message();
  EXPECT_EQ(jobs[neighbour_id].state(), v1::JOB_STATE_SUCCEEDED);
  EXPECT_EQ(jobs[neighbour_id].result().state_sha256(), expected[0]);
  EXPECT_EQ(server_.pid(), seepd);
  EXPECT_TRUE(server_.running());
  ExpectTheWorkerRunsTheNextJob();
}

// The admission estimate: a scene whose run cannot fit in the memory a job may use is refused
// at submit with the figures, and nothing is stored.
TEST_F(JobIsolation, ASceneTooLargeForTheMemoryLimitIsRefusedAtSubmitWithTheFigures) {
  Start("data", {"--workers", "1", "--job-memory-limit-mb", "700"});
  // Three million disks: about 4 GB at set-up.
  v1::Scene huge = LatticeScene("huge", 1e-3);
  huge.mutable_packing()->mutable_lattice()->set_columns(2000);
  huge.mutable_packing()->mutable_lattice()->set_rows(1500);
  grpc::ClientContext ctx;
  Prepare(ctx);
  v1::SubmitJobRequest request;
  *request.mutable_scene() = huge;
  v1::SubmitJobResponse response;
  const grpc::Status status = stub_->SubmitJob(&ctx, request, &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  const std::string& why = status.error_message();
  EXPECT_EQ(why.rfind("scene.packing: a run of this scene needs about ", 0), 0u) << why;
  EXPECT_NE(why.find("3000000 particles"), std::string::npos) << why;
  EXPECT_NE(why.find("more than the 700 MiB a job may use (seepd --job-memory-limit-mb)"),
            std::string::npos)
      << why;
  grpc::ClientContext list_ctx;
  Prepare(list_ctx);
  v1::ListJobsRequest list;
  v1::ListJobsResponse jobs;
  ASSERT_TRUE(stub_->ListJobs(&list_ctx, list, &jobs).ok());
  EXPECT_EQ(jobs.jobs_size(), 0);
}

TEST_F(JobIsolation, ASetUpKeepsItsLeaseAndACancelDuringItEndsTheProcessAndFreesTheWorker) {
  Start("data", {"--workers", "1", "--lease-s", "1"});
  const std::string slow = Submit(LongSetUpScene("slow-set-up"));
  ASSERT_EQ(
      WaitFor(slow, [](const v1::Job& j) { return j.state() == v1::JOB_STATE_RUNNING; }).state(),
      v1::JOB_STATE_RUNNING);
  // Six leases' worth of set-up: still the first claim, never rescued.
  std::this_thread::sleep_for(std::chrono::seconds(6));
  EXPECT_EQ(Get(slow).state(), v1::JOB_STATE_RUNNING);
  EXPECT_EQ(CountEvents(slow, "CLAIMED"), 1);
  EXPECT_FALSE(HasEvent(slow, "RESCUED"));
  const auto cancelled_at = std::chrono::steady_clock::now();
  Cancel(slow);
  const v1::Job cancelled = WaitFor(
      slow, [](const v1::Job& j) { return IsTerminalState(j.state()); }, std::chrono::seconds(30));
  EXPECT_EQ(cancelled.state(), v1::JOB_STATE_CANCELLED) << cancelled.DebugString();
  // The grace (5 s) and a check a second.
  EXPECT_LT(std::chrono::steady_clock::now() - cancelled_at, std::chrono::seconds(10));
  EXPECT_NE(cancelled.error().message().find("did not stop it within 5 s"), std::string::npos)
      << cancelled.error().message();
  ExpectTheWorkerRunsTheNextJob();
}

TEST_F(JobIsolation, ASetUpPastTheTimeLimitFailsDeadlineExceededAndFreesTheWorker) {
  Start("data", {"--workers", "1", "--job-time-limit-s", "2"});
  const std::string slow = Submit(LongSetUpScene("slow-set-up"));
  const v1::Job failed = WaitFor(
      slow, [](const v1::Job& j) { return IsTerminalState(j.state()); }, std::chrono::seconds(30));
  ASSERT_EQ(failed.state(), v1::JOB_STATE_FAILED) << failed.DebugString();
  EXPECT_EQ(failed.error().code(), "DEADLINE_EXCEEDED");
  EXPECT_NE(failed.error().message().find("--job-time-limit-s 2"), std::string::npos)
      << failed.error().message();
  EXPECT_EQ(failed.progress().step(), 0u);
  ExpectTheWorkerRunsTheNextJob();
}

TEST_F(JobIsolation, TheWorkerProcessesEndWithSeepdEvenWhenItIsKilled) {
  Start("data", {"--workers", "2"});
  // Started once seepd serves; they may take a moment to exec.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  std::set<pid_t> workers;
  while ((workers = WorkersOf(server_.pid())).size() < 2 &&
         std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  ASSERT_EQ(workers.size(), 2u);
  EXPECT_EQ(server_.Stop(SIGKILL), 128 + SIGKILL);
  const auto gone_by = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  const auto any_alive = [&] { return std::any_of(workers.begin(), workers.end(), IsLiveWorker); };
  while (any_alive() && std::chrono::steady_clock::now() < gone_by) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  EXPECT_FALSE(any_alive()) << "seep-worker processes outlived seepd";
}

}  // namespace
}  // namespace seep::testing
