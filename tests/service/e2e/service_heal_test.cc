// Failure paths that heal themselves, through the real seepd: a second seepd on a data folder
// that is in use refuses to start and changes nothing; a hung worker's job is rescued when its
// lease expires; a job over the wall-time limit fails naming it; a final write that keeps failing
// ends the job FAILED with the reason; a job that crashes seepd each time fails after three.
#include <google/protobuf/text_format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <regex>

#include "grpc_seepd_fixture.h"

namespace seep::testing {
namespace {

class ServiceHeal : public GrpcSeepdTest {
 protected:
  ServiceHeal() : GrpcSeepdTest("e2e-heal") {}
};

TEST_F(ServiceHeal, SecondSeepdOnTheSameDataFolderRefusesAndTouchesNothing) {
  Start("data", {"--checkpoint-interval-s", "0.2"});
  // Seconds of steps: a worker process's progress reaches seepd once a second.
  const std::string id = Submit(LatticeScene("held", 1.5e-1));
  const v1::Job running = WaitFor(id, [](const v1::Job& j) {
    return j.state() == v1::JOB_STATE_RUNNING && j.progress().step() > 0;
  });
  ASSERT_EQ(running.state(), v1::JOB_STATE_RUNNING) << running.DebugString();
  const std::string log_before = ReadFile(dir_ / "data" / "seepd.log");

  // The second seepd: `timeout` ends it if it wrongly starts serving.
  const std::string second_port = (dir_ / "second.port").string();
  std::vector<std::string> argv = SeepdArgv("data", second_port);
  argv.insert(argv.begin(), {"/usr/bin/timeout", "60"});
  const CommandResult second = RunCommand(argv);
  EXPECT_EQ(second.exit_code, 75) << second.output;
  EXPECT_NE(
      second.output.find("--data-dir " + (dir_ / "data").string() +
                         " is in use by another seepd (pid " + std::to_string(server_.pid()) + ","),
      std::string::npos)
      << second.output;
  EXPECT_FALSE(std::filesystem::exists(second_port));

  // The first one keeps serving, and its job finishes in its first claim.
  const v1::Job done = WaitTerminal(id);
  ASSERT_EQ(done.state(), v1::JOB_STATE_SUCCEEDED) << done.DebugString();
  EXPECT_EQ(done.attempt(), 1u);
  const std::string log = ReadFile(dir_ / "data" / "seepd.log");
  ASSERT_GE(log.size(), log_before.size());
  EXPECT_EQ(log.compare(0, log_before.size(), log_before), 0) << "the log was rewritten";
  // Nothing of the second one reached the log: no start-up line, no recovery, no second claim.
  EXPECT_EQ(Count(log, "listening on"), 1u) << log;
  EXPECT_EQ(Count(log, "recovered"), 0u) << log;
  EXPECT_EQ(Count(log, "lease epoch 2"), 0u) << log;

  // Once the first one is gone, the folder is free again.
  stub_.reset();
  EXPECT_EQ(server_.Stop(SIGTERM), 0);
  Start("data", {});
  EXPECT_EQ(Get(id).state(), v1::JOB_STATE_SUCCEEDED);
}

// A hung worker: with --test-stall-job, the worker that first claims the job stops making
// progress 1500 steps in (test-only hook: a worker thread cannot be SIGSTOPped alone, and there
// are no remote workers). The heartbeat stops renewing its lease, the rescuer requeues the job
// once the lease expired, the other worker claims it and continues from the newest checkpoint,
// and the final state is bit-identical to an uninterrupted run.
TEST_F(ServiceHeal, AHungWorkersJobIsRescuedAndEndsBitIdentical) {
  const v1::Scene scene = LatticeScene("stalls", 1e-2);
  Start("reference", {});
  const v1::Job reference = WaitTerminal(Submit(scene));
  ASSERT_EQ(reference.state(), v1::JOB_STATE_SUCCEEDED) << reference.DebugString();
  stub_.reset();
  ASSERT_EQ(server_.Stop(SIGTERM), 0);

  Start("data", {"--isolation", "thread", "--workers", "2", "--lease-s", "3",
                 "--checkpoint-every-steps", "1000", "--test-stall-job", "stalls"});
  const std::string id = Submit(scene);
  const v1::Job done = WaitTerminal(id);
  ASSERT_EQ(done.state(), v1::JOB_STATE_SUCCEEDED) << done.DebugString();
  EXPECT_EQ(done.result().state_sha256(), reference.result().state_sha256());
  EXPECT_EQ(done.attempt(), 1u);  // a rescue is not a new attempt
  const std::string log = ReadFile(dir_ / "data" / "seepd.log");
  EXPECT_NE(log.find("test hook --test-stall-job: this worker stops making progress"),
            std::string::npos)
      << log;
  EXPECT_NE(log.find("job " + id + " rescued: lease epoch 1 of seepd-"), std::string::npos) << log;
  EXPECT_NE(log.find("(attempt 1, lease epoch 2)"), std::string::npos) << log;
  EXPECT_NE(log.find("resumed from checkpoint ckpt-000000001000.bin at step 1000"),
            std::string::npos)
      << log;
  // The hung worker woke up after the rescue and wrote nothing more.
  EXPECT_NE(log.find("stopped after losing its lease; nothing recorded by this worker"),
            std::string::npos)
      << log;
  // A job that makes progress keeps its lease (renewed by progress) however long it runs.
  const std::string healthy = Submit(LatticeScene("healthy", 0.4));
  const v1::Job other = WaitTerminal(healthy);
  EXPECT_EQ(other.state(), v1::JOB_STATE_SUCCEEDED) << other.DebugString();
  EXPECT_EQ(ReadFile(dir_ / "data" / "seepd.log").find("job " + healthy + " rescued"),
            std::string::npos);
}

TEST_F(ServiceHeal, AJobOverTheWallTimeLimitFailsNamingTheLimit) {
  Start("data", {"--job-time-limit-s", "1", "--checkpoint-interval-s", "0"});
  const std::string id = Submit(LatticeScene("too-long", 1.0));
  const v1::Job done = WaitTerminal(id);
  ASSERT_EQ(done.state(), v1::JOB_STATE_FAILED) << done.DebugString();
  EXPECT_EQ(done.error().code(), "DEADLINE_EXCEEDED");
  EXPECT_NE(done.error().message().find("wall-time limit exceeded"), std::string::npos)
      << done.error().message();
  EXPECT_NE(done.error().message().find("the limit is 1 s (--job-time-limit-s)"), std::string::npos)
      << done.error().message();
  EXPECT_GT(done.progress().step(), 0u);
  EXPECT_LT(done.progress().fraction_done(), 1.0);
}

// A final write that fails a few times is tried again and the job succeeds; one that keeps
// failing ends the job FAILED with the reason (not RUNNING forever), and the queue moves on.
// --test-fail-final-writes N (test only) makes the first N tries fail as a store error would;
// each job gets 5 tries.
TEST_F(ServiceHeal, AFailingFinalWriteIsRetriedThenTheJobFailsWithTheReason) {
  Start("data", {"--isolation", "thread", "--test-fail-final-writes", "7"});
  const v1::Job failed = WaitTerminal(Submit(LatticeScene("never-stored", 1e-3)));  // tries 1-5
  ASSERT_EQ(failed.state(), v1::JOB_STATE_FAILED) << failed.DebugString();
  EXPECT_EQ(failed.error().code(), "UNAVAILABLE");
  EXPECT_EQ(failed.error().message(),
            "the result could not be recorded: result not stored after 5 tries: injected "
            "final-write failure (--test-fail-final-writes)");
  EXPECT_TRUE(failed.result().metrics().empty());
  EXPECT_TRUE(failed.result().state_sha256().empty());

  const v1::Job retried = WaitTerminal(Submit(LatticeScene("stored-late", 1e-3)));  // 2 fail
  ASSERT_EQ(retried.state(), v1::JOB_STATE_SUCCEEDED) << retried.DebugString();
  EXPECT_FALSE(retried.result().metrics().empty());
  EXPECT_EQ(retried.result().state_sha256().size(), 64u);
  const std::string log = ReadFile(dir_ / "data" / "seepd.log");
  EXPECT_EQ(Count(log, "result not stored (try 1 of 5)"), 2u) << log;
  EXPECT_EQ(Count(log, "result not stored (try 4 of 5)"), 1u) << log;
}

// A job that brings seepd down each time it runs (--test-crash-job, test only: _Exit 1500 steps
// in, before any checkpoint; on seepd's own threads, --isolation thread, where a crash is
// seepd's) is run again after each restart until its third interruption without progress; the
// next start FAILS it with that history and runs the jobs queued behind it.
TEST_F(ServiceHeal, AJobThatCrashesSeepdEachTimeFailsAfterThreeAndTheQueueMovesOn) {
  const std::vector<std::string> flags = {"--isolation", "thread", "--test-crash-job", "crasher"};
  Start("data", flags);
  const std::string crasher = Submit(LatticeScene("crasher", 1e-2));
  const std::string after = Submit(LatticeScene("after", 1e-3));
  int crashes = 0;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(180);
  while (std::chrono::steady_clock::now() < deadline) {
    if (const int status = server_.PollExit(); status >= 0) {
      EXPECT_EQ(status, 86);
      ++crashes;
      ASSERT_LE(crashes, 3) << "the crash loop did not end";
      Start("data", flags);
      continue;
    }
    grpc::ClientContext ctx;
    ctx.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(10));
    v1::GetJobRequest request;
    request.set_id(after);
    v1::GetJobResponse response;
    if (stub_->GetJob(&ctx, request, &response).ok() && IsTerminalState(response.job().state())) {
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  EXPECT_EQ(crashes, 3);
  const v1::Job failed = Get(crasher);
  ASSERT_EQ(failed.state(), v1::JOB_STATE_FAILED) << failed.DebugString();
  EXPECT_EQ(failed.error().code(), "ABORTED");
  EXPECT_EQ(failed.error().message().rfind("interrupted 3 times in a row without progress", 0), 0u)
      << failed.error().message();
  EXPECT_EQ(Get(after).state(), v1::JOB_STATE_SUCCEEDED);
  const std::string log = ReadFile(dir_ / "data" / "seepd.log");
  EXPECT_EQ(Count(log, "test hook --test-crash-job: ending the process"), 3u) << log;
  EXPECT_NE(log.find("job " + crasher + " failed: interrupted 3 times"), std::string::npos) << log;
}

// Priorities through the CLI: queued jobs run highest priority first, in submission order within
// one; an out-of-range priority is refused naming the field, and nothing is stored.
TEST_F(ServiceHeal, QueuedJobsRunByPriorityThenInSubmissionOrder) {
  Start("data", {"--workers", "1"});
  // Holds the only worker until the four are queued; then cancelled.
  const std::string blocker = Submit(LatticeScene("blocker", 100.0));
  ASSERT_EQ(
      WaitFor(blocker, [](const v1::Job& j) { return j.state() == v1::JOB_STATE_RUNNING; }).state(),
      v1::JOB_STATE_RUNNING);
  std::string text;
  ASSERT_TRUE(google::protobuf::TextFormat::PrintToString(LatticeScene("quick", 1e-3), &text));
  const std::string scene_file = (dir_ / "quick.textproto").string();
  std::ofstream(scene_file) << text;
  const std::string port = ReadFile(dir_ / "data.port");
  const auto submit = [&](const std::string& name, const std::vector<std::string>& extra) {
    std::vector<std::string> argv = {
        SEEP_CLI_PATH, "--server", "127.0.0.1:" + port, "submit", scene_file, "--name", name};
    argv.insert(argv.end(), extra.begin(), extra.end());
    const CommandResult run = RunCommand(argv);
    EXPECT_EQ(run.exit_code, 0) << run.output;
    std::smatch m;
    return std::regex_search(run.output, m, std::regex("job (j-[0-9a-f]+)")) ? m[1].str() : "";
  };
  const std::string low = submit("low", {"--priority", "-3"});
  const std::string first = submit("first", {});
  const std::string high = submit("high", {"--priority", "7"});
  const std::string second = submit("second", {"--priority", "0"});

  const CommandResult bad = RunCommand(
      {SEEP_CLI_PATH, "--server", "127.0.0.1:" + port, "submit", scene_file, "--priority", "5000"});
  EXPECT_EQ(bad.exit_code, 3) << bad.output;
  EXPECT_NE(bad.output.find("priority: must be between -1000 and 1000 (got 5000)"),
            std::string::npos)
      << bad.output;

  {
    grpc::ClientContext ctx;
    ctx.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(10));
    v1::CancelJobRequest request;
    request.set_id(blocker);
    v1::CancelJobResponse response;
    ASSERT_TRUE(stub_->CancelJob(&ctx, request, &response).ok());
  }
  std::vector<std::pair<std::int64_t, std::string>> started;
  for (const std::string& id : {low, first, high, second}) {
    const v1::Job job = WaitTerminal(id);
    ASSERT_EQ(job.state(), v1::JOB_STATE_SUCCEEDED) << job.DebugString();
    started.emplace_back(job.started_at().seconds() * 1000000000 + job.started_at().nanos(),
                         job.name());
  }
  EXPECT_EQ(Get(high).priority(), 7);
  std::sort(started.begin(), started.end());
  std::vector<std::string> order;
  for (const auto& [at, name] : started) order.push_back(name);
  EXPECT_EQ(order, (std::vector<std::string>{"high", "first", "second", "low"}));
  // The refused submit stored nothing: the blocker and the four.
  grpc::ClientContext ctx;
  ctx.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(10));
  v1::ListJobsRequest request;
  v1::ListJobsResponse response;
  ASSERT_TRUE(stub_->ListJobs(&ctx, request, &response).ok());
  EXPECT_EQ(response.jobs_size(), 5);
}

}  // namespace
}  // namespace seep::testing
