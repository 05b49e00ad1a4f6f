// seepd --executor slurm on a real one-node Slurm cluster (slurm_cluster.sh, started once for the
// whole binary): an 8-job sweep run through sbatch ends with the state hashes of the same sweep
// on seepd's own workers, one Slurm job per seep job, each job naming its Slurm job, node and
// state; a worker killed by `scancel --signal=KILL` loses its lease, its job is queued again, a
// new Slurm job resumes it from its checkpoint and it ends with the same hash; cancelling a sweep
// scancels the Slurm jobs of its workers, running and pending; packed, one Slurm job's worker
// drains a sweep. Where no cluster can be started (no Slurm installed, not root) every test
// skips, saying why.
#include <fmt/format.h>
#include <unistd.h>

#include <cstdlib>
#include <functional>
#include <set>
#include <sstream>

#include "../e2e/grpc_seepd_fixture.h"

namespace seep::testing {
namespace {

// Why no cluster can run here ("" when one can; the tests skip), and why one that could did not
// come up ("" when it did; the tests fail), set once by the environment below.
std::string g_no_cluster;
std::string g_cluster_failed;

class SlurmCluster : public ::testing::Environment {
 public:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() / fmt::format("seep-slurm-{}", ::getpid());
    std::filesystem::remove_all(dir_);
    // Bounded: a cluster that hangs at its start fails the tests with what it printed instead of
    // running into CTest's timeout silently.
    const CommandResult started =
        RunCommand({"/usr/bin/timeout", "120", SLURM_CLUSTER_SCRIPT, "start", dir_.string()});
    std::printf("%s", started.output.c_str());
    if (std::filesystem::exists(dir_ / "skip")) {
      g_no_cluster = ReadFile(dir_ / "skip");
    } else if (started.exit_code != 0) {
      g_cluster_failed = fmt::format(
          "slurm_cluster.sh start exited with {} (124: it hung; what it printed is above)",
          started.exit_code);
    } else {
      // seepd, and the sbatch/squeue/scancel it runs, find the cluster through it.
      ::setenv("SLURM_CONF", (dir_ / "slurm.conf").c_str(), 1);
    }
  }
  void TearDown() override {
    RunCommand({SLURM_CLUSTER_SCRIPT, "stop", dir_.string()});
    if (!::testing::UnitTest::GetInstance()->Failed()) std::filesystem::remove_all(dir_);
  }

 private:
  std::filesystem::path dir_;
};

const auto* const g_cluster = ::testing::AddGlobalTestEnvironment(new SlurmCluster);

// A Slurm command by its full path (the tests' RunCommand does not search PATH).
std::string Slurm(const std::string& command) {
  const char* path = std::getenv("PATH");
  std::istringstream dirs(path == nullptr ? "/usr/bin:/bin" : path);
  for (std::string dir; std::getline(dirs, dir, ':');) {
    const std::filesystem::path candidate = std::filesystem::path(dir) / command;
    if (::access(candidate.c_str(), X_OK) == 0) return candidate.string();
  }
  return command;
}

std::string ShortHostName() {
  char host[256] = {};
  ::gethostname(host, sizeof host - 1);
  std::string name = host;
  return name.substr(0, name.find('.'));
}

// Eight short explicit transients (about a second each).
v1::Sweep EightJobSweep(double end_time_s) {
  v1::Sweep sweep;
  EXPECT_TRUE(google::protobuf::TextFormat::ParseFromString(
      R"pb(
        name: "slurm"
        combine: SWEEP_COMBINE_PRODUCT
        axes {
          path: "boundary.inlet_pressure_pa"
          numbers: [ 1e5, 2e5, 3e5, 4e5 ]
        }
        axes {
          path: "solver.dt_factor"
          numbers: [ 0.9, 0.7 ]
        }
      )pb",
      &sweep));
  *sweep.mutable_scene() = LatticeScene("slurm", end_time_s);
  return sweep;
}

class SlurmExecutor : public GrpcSeepdTest {
 protected:
  SlurmExecutor() : GrpcSeepdTest("slurm") {}

  void SetUp() override {
    if (!g_no_cluster.empty()) GTEST_SKIP() << "no Slurm cluster: " << g_no_cluster;
    ASSERT_TRUE(g_cluster_failed.empty()) << g_cluster_failed;
    GrpcSeepdTest::SetUp();
  }
  void TearDown() override {
    if (!g_no_cluster.empty() || !g_cluster_failed.empty()) return;
    GrpcSeepdTest::TearDown();
    // Whatever a failed test left queued or running in the cluster.
    RunCommand({Slurm("scancel"), "--me"});
  }

  // A pure coordinator whose jobs Slurm jobs run; `extra` adds flags (e.g. --slurm-pack).
  void StartCoordinator(const std::vector<std::string>& extra = {}) {
    std::vector<std::string> flags = {"--workers",
                                      "0",
                                      "--executor",
                                      "slurm",
                                      "--slurm-worker",
                                      SEEP_WORKER_PATH,
                                      "--slurm-poll-s",
                                      "0.5",
                                      "--lease-s",
                                      "3",
                                      "--threads-per-job",
                                      "1",
                                      "--checkpoint-every-steps",
                                      "3000",
                                      "--checkpoint-interval-s",
                                      "0"};
    flags.insert(flags.end(), extra.begin(), extra.end());
    Start("coordinator", flags);
  }

  // The sweep on seepd's own workers: the hash each job must end with, by position.
  std::vector<std::string> LocalHashes(const v1::Sweep& sweep) {
    Start("local", {"--workers", "2", "--threads-per-job", "1"});
    const std::vector<std::string> ids = JobIds(SubmitSweep(sweep));
    const auto jobs = WaitAllTerminal(ids, std::chrono::seconds(120));
    std::vector<std::string> hashes;
    for (const std::string& id : ids) {
      EXPECT_EQ(jobs.at(id).state(), v1::JOB_STATE_SUCCEEDED) << jobs.at(id).DebugString();
      hashes.push_back(jobs.at(id).result().state_sha256());
    }
    stub_.reset();
    EXPECT_EQ(server_.Stop(SIGTERM), 0);
    return hashes;
  }

  // Those of `ids` that squeue still lists as alive once they are all gone or `timeout` passed.
  static std::set<std::string> StillAlive(const std::set<std::string>& ids,
                                          std::chrono::seconds timeout) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    for (;;) {
      std::set<std::string> alive;
      for (const std::string& id : LiveSlurmJobs()) {
        if (ids.count(id) > 0) alive.insert(id);
      }
      if (alive.empty() || std::chrono::steady_clock::now() > deadline) return alive;
      std::this_thread::sleep_for(std::chrono::milliseconds(200));
    }
  }

  std::vector<v1::JobHistoryEvent> StopItsWorkerAndExpectTheSameHash(
      const std::function<void(const std::string& slurm_job)>& stop);

  // `scancel ARGS... JOB`, expected to succeed.
  static std::function<void(const std::string&)> Scancel(std::vector<std::string> args) {
    return [args](const std::string& slurm_job) {
      std::vector<std::string> argv = {Slurm("scancel")};
      argv.insert(argv.end(), args.begin(), args.end());
      argv.push_back(slurm_job);
      const CommandResult sent = RunCommand(argv);
      EXPECT_EQ(sent.exit_code, 0) << sent.output;
    };
  }

  // The Slurm jobs squeue lists as pending or running (any user's of this test: ours).
  static std::set<std::string> LiveSlurmJobs() {
    const CommandResult listed =
        RunCommand({Slurm("squeue"), "--noheader", "--me",
                    "--states=PENDING,RUNNING,CONFIGURING,COMPLETING", "--format=%i"});
    EXPECT_EQ(listed.exit_code, 0) << listed.output;
    std::set<std::string> ids;
    std::istringstream lines(listed.output);
    for (std::string line; std::getline(lines, line);) {
      if (!line.empty()) ids.insert(line);
    }
    return ids;
  }
};

TEST_F(SlurmExecutor, EightJobSweepThroughSbatchMatchesALocalRun) {
  const v1::Sweep sweep = EightJobSweep(3e-2);
  const std::vector<std::string> expected = LocalHashes(sweep);
  ASSERT_EQ(expected.size(), 8u);

  StartCoordinator();
  const std::vector<std::string> ids = JobIds(SubmitSweep(sweep));
  ASSERT_EQ(ids.size(), 8u);
  const auto jobs = WaitAllTerminal(ids, std::chrono::seconds(300));
  std::set<std::string> slurm_jobs;
  for (std::size_t i = 0; i < ids.size(); ++i) {
    const v1::Job& job = jobs.at(ids[i]);
    ASSERT_EQ(job.state(), v1::JOB_STATE_SUCCEEDED) << job.DebugString();
    EXPECT_EQ(job.result().state_sha256(), expected[i])
        << job.name() << ": the run through Slurm differs from the local one";
    // Where it ran, as seep show prints it.
    EXPECT_EQ(job.batch().system(), "slurm") << job.DebugString();
    EXPECT_FALSE(job.batch().job_id().empty());
    EXPECT_EQ(job.batch().node(), ShortHostName());
    EXPECT_FALSE(job.batch().state().empty());
    slurm_jobs.insert(job.batch().job_id());
  }
  // One Slurm job per seep job (the default, --slurm-pack 0).
  EXPECT_EQ(slurm_jobs.size(), 8u);
  // Each worker exits after its job: no Slurm job of this seepd stays behind.
  const std::set<std::string> left = StillAlive(slurm_jobs, std::chrono::seconds(60));
  EXPECT_TRUE(left.empty()) << left.size() << " Slurm jobs still alive after their jobs ended";
}

// One longer job (a few seconds), checkpointed every 3000 steps, run through Slurm until it is
// past a checkpoint; then `scancel` with `signal_args` reaches its worker's Slurm job. Expects it
// to end SUCCEEDED with the hash of its uninterrupted local run, finished by a new Slurm job that
// resumed it from a checkpoint; returns its events.
std::vector<v1::JobHistoryEvent> SlurmExecutor::StopItsWorkerAndExpectTheSameHash(
    const std::function<void(const std::string& slurm_job)>& stop) {
  v1::Sweep sweep = EightJobSweep(0.25);
  sweep.mutable_axes()->DeleteSubrange(1, 1);
  sweep.mutable_axes(0)->clear_numbers();
  sweep.mutable_axes(0)->add_numbers(2.5e5);
  const std::vector<std::string> expected = LocalHashes(sweep);
  EXPECT_EQ(expected.size(), 1u);
  if (expected.size() != 1) return {};

  StartCoordinator();
  const std::string id = JobIds(SubmitSweep(sweep)).at(0);
  // Running in a Slurm job, past its first checkpoint.
  std::string signalled;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (signalled.empty() && std::chrono::steady_clock::now() < deadline) {
    const v1::Job job = Get(id);
    EXPECT_FALSE(IsTerminalState(job.state()))
        << "ended before its worker was signalled: " << job.DebugString();
    if (IsTerminalState(job.state())) return {};
    bool checkpointed = false;
    for (const auto& e : Events(id)) checkpointed = checkpointed || e.kind() == "CHECKPOINT";
    if (job.state() == v1::JOB_STATE_RUNNING && checkpointed && !job.batch().job_id().empty()) {
      signalled = job.batch().job_id();
    } else {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }
  EXPECT_FALSE(signalled.empty()) << "the job never ran past a checkpoint in a Slurm job";
  if (signalled.empty()) return {};
  stop(signalled);

  const v1::Job job = WaitTerminal(id);
  EXPECT_EQ(job.state(), v1::JOB_STATE_SUCCEEDED) << job.DebugString();
  EXPECT_EQ(job.result().state_sha256(), expected[0])
      << "the job continued after the signal differs from the uninterrupted run";
  // A new Slurm job finished it, from a checkpoint (not from the start).
  EXPECT_NE(job.batch().job_id(), signalled);
  const std::vector<v1::JobHistoryEvent> events = Events(id);
  int resumed = 0;
  for (const auto& e : events) resumed += e.kind() == "RESUMED";
  EXPECT_EQ(resumed, 1) << "the second claim did not resume from a checkpoint";
  return events;
}

// `scancel --signal=KILL`: Slurm ends the job as it ends any (SIGTERM to the worker, SIGKILL
// after KillWait); the job is queued again and a new Slurm job resumes it from a checkpoint.
TEST_F(SlurmExecutor, AWorkerKilledByScancelIsRequeuedAndResumesBitIdentical) {
  int rescued = 0;
  for (const auto& e : StopItsWorkerAndExpectTheSameHash(Scancel({"--signal=KILL"}))) {
    rescued += e.kind() == "RESCUED";
  }
  EXPECT_EQ(rescued, 1) << "the job was not queued again once";
}

// What Slurm sends a worker before its time limit (--signal=B:TERM@grace) or at preemption:
// SIGTERM to the batch step. The worker checkpoints its job, gives it back and exits; the job
// continues in a new Slurm job from that checkpoint, without waiting for a lease to expire.
TEST_F(SlurmExecutor, AWorkerToldToStopGivesItsJobBackAndItContinuesBitIdentical) {
  int interrupted = 0;
  for (const auto& e : StopItsWorkerAndExpectTheSameHash(Scancel({"--signal=TERM", "--batch"}))) {
    interrupted += e.kind() == "INTERRUPTED";
  }
  EXPECT_EQ(interrupted, 1) << "the worker did not stop its job at a step and give it back";
}

// A worker that vanishes without a word (its node lost: SIGKILL straight to the process, which
// neither it nor Slurm sees coming): its lease expires, the rescuer queues the job again and a
// new Slurm job resumes it from the checkpoint before the kill.
TEST_F(SlurmExecutor, AVanishedWorkerLosesItsLeaseAndItsJobResumesBitIdentical) {
  int rescued = 0;
  int interrupted = 0;
  const auto vanish = [](const std::string& slurm_job) {
    // The worker's command line ends with its name, slurm-<job id> (the batch script's exec).
    const CommandResult killed = RunCommand(
        {"/usr/bin/pkill", "-KILL", "-f", "seep-worker .*--name slurm-" + slurm_job + "$"});
    EXPECT_EQ(killed.exit_code, 0) << "no worker process of Slurm job " << slurm_job << " to kill";
  };
  for (const auto& e : StopItsWorkerAndExpectTheSameHash(vanish)) {
    rescued += e.kind() == "RESCUED";
    interrupted += e.kind() == "INTERRUPTED";
  }
  EXPECT_EQ(rescued, 1) << "the vanished worker's lease was not rescued once";
  EXPECT_EQ(interrupted, 0) << "a SIGKILLed worker cannot have given its job back";
}

TEST_F(SlurmExecutor, CancellingASweepScancelsItsWorkers) {
  // Long jobs: they are still running (or pending) when the sweep is cancelled.
  const v1::Sweep sweep = EightJobSweep(5.0);
  StartCoordinator();
  const v1::SweepStatus submitted = SubmitSweep(sweep);
  const std::vector<std::string> ids = JobIds(submitted);
  ASSERT_EQ(ids.size(), 8u);
  // Wait for two running in Slurm jobs (the node's two CPUs) and the rest pending.
  std::set<std::string> ours;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  int running = 0;
  while (std::chrono::steady_clock::now() < deadline) {
    running = 0;
    for (const std::string& id : ids) running += Get(id).state() == v1::JOB_STATE_RUNNING;
    ours = LiveSlurmJobs();
    if (running >= 2 && ours.size() >= 8) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  ASSERT_GE(running, 2) << "two jobs never ran at once in Slurm jobs";
  ASSERT_GE(ours.size(), 8u) << "fewer Slurm jobs than queued jobs were submitted";

  grpc::ClientContext ctx;
  Prepare(ctx);
  v1::CancelSweepRequest request;
  request.set_id(submitted.id());
  v1::CancelSweepResponse response;
  const grpc::Status status = stub_->CancelSweep(&ctx, request, &response);
  ASSERT_TRUE(status.ok()) << status.error_message();

  const auto jobs = WaitAllTerminal(ids, std::chrono::seconds(60));
  for (const std::string& id : ids) {
    EXPECT_EQ(jobs.at(id).state(), v1::JOB_STATE_CANCELLED) << jobs.at(id).DebugString();
  }
  // Every Slurm job of the sweep is gone from the queue: scancelled, not left to time out.
  const std::set<std::string> alive = StillAlive(ours, std::chrono::seconds(30));
  EXPECT_TRUE(alive.empty()) << alive.size() << " Slurm jobs of the cancelled sweep still alive";
  // The pending ones at least were scancelled by seepd (a running worker may notice its cancel
  // and end before seepd's scancel reaches it).
  const std::size_t scancelled = Count(ReadFile(dir_ / "coordinator.out"), "scancelled batch job");
  EXPECT_GE(scancelled, ours.size() - static_cast<std::size_t>(running))
      << "seepd scancelled fewer Slurm jobs than were pending";
}

// What Slurm would refuse for every batch job (here a partition it does not have) stops seepd at
// its start, with sbatch's reason, instead of failing on every round.
TEST_F(SlurmExecutor, ABatchJobSlurmRefusesStopsSeepdAtItsStart) {
  const CommandResult refused = RunCommand(
      {SEEPD_PATH, "--listen", "127.0.0.1:0", "--data-dir", (dir_ / "refused").string(),
       "--workers", "0", "--executor", "slurm", "--slurm-partition", "no-such-partition"});
  EXPECT_EQ(refused.exit_code, 2) << refused.output;
  EXPECT_NE(refused.output.find("Slurm refuses the workers' batch jobs (sbatch --test-only): "
                                "sbatch: error: "),
            std::string::npos)
      << refused.output;
  EXPECT_NE(refused.output.find("partition"), std::string::npos) << refused.output;
}

TEST_F(SlurmExecutor, PackedOneAllocationDrainsASweepAndEnds) {
  const v1::Sweep sweep = EightJobSweep(3e-2);
  const std::vector<std::string> expected = LocalHashes(sweep);
  StartCoordinator({"--slurm-pack", "2", "--slurm-max-jobs", "1"});
  const std::vector<std::string> ids = JobIds(SubmitSweep(sweep));
  const auto jobs = WaitAllTerminal(ids, std::chrono::seconds(300));
  std::set<std::string> slurm_jobs;
  for (std::size_t i = 0; i < ids.size(); ++i) {
    const v1::Job& job = jobs.at(ids[i]);
    ASSERT_EQ(job.state(), v1::JOB_STATE_SUCCEEDED) << job.DebugString();
    EXPECT_EQ(job.result().state_sha256(), expected[i]) << job.name();
    slurm_jobs.insert(job.batch().job_id());
  }
  // One allocation (--slurm-max-jobs 1) ran all eight, two at a time.
  EXPECT_EQ(slurm_jobs.size(), 1u);
}

}  // namespace
}  // namespace seep::testing

namespace seep::testing {
namespace {

// Refusals that need no cluster: a --slurm-* flag without --executor slurm, and --executor slurm
// where sbatch cannot be found, each exit 2 naming what is wrong, before anything is served.
TEST(SlurmExecutorFlags, ASlurmFlagWithoutTheSlurmExecutorIsRefused) {
  const CommandResult refused =
      RunCommand({SEEPD_PATH, "--listen", "127.0.0.1:0", "--data-dir",
                  (std::filesystem::temp_directory_path() / "seep-slurm-flag-refused").string(),
                  "--slurm-partition", "compute"});
  EXPECT_EQ(refused.exit_code, 2) << refused.output;
  EXPECT_NE(refused.output.find("--slurm-partition needs --executor slurm"), std::string::npos)
      << refused.output;
}

TEST(SlurmExecutorFlags, TheSlurmExecutorWithoutSbatchIsRefused) {
  const auto data =
      std::filesystem::temp_directory_path() / fmt::format("seep-slurm-no-sbatch-{}", ::getpid());
  std::filesystem::remove_all(data);
  // A PATH with none of Slurm's commands on it.
  const CommandResult refused =
      RunCommand({"/usr/bin/env", "PATH=/nonexistent", SEEPD_PATH, "--listen", "127.0.0.1:0",
                  "--data-dir", data.string(), "--workers", "0", "--executor", "slurm"});
  EXPECT_EQ(refused.exit_code, 2) << refused.output;
  EXPECT_NE(refused.output.find("--executor slurm: sbatch does not answer"), std::string::npos)
      << refused.output;
  std::filesystem::remove_all(data);
}

}  // namespace
}  // namespace seep::testing
