// JobRunner::Wake: one wake-up after a sweep is queued starts every idle worker at once. (Each
// once took the jobs queued with a wake-up of one worker only; the others slept until their next
// poll, a second a lane lost at the start of every sweep.)
#include <gtest/gtest.h>
#include <spdlog/sinks/null_sink.h>

#include <chrono>
#include <filesystem>
#include <optional>
#include <string>
#include <thread>

#include "jobs/job_hub.h"
#include "jobs/job_runner.h"
#include "jobs/store_ledger.h"
#include "store/job_store.h"
#include "test_support.h"

namespace seep::service {
namespace {

using namespace std::chrono_literals;

TEST(JobRunnerWake, OneWakeStartsEveryIdleWorker) {
  const std::filesystem::path dir = testing::FreshTestDir("runner-wake");
  auto store = JobStore::Open((dir / "seep.db").string());
  ASSERT_TRUE(store.ok()) << store.status().ToString();
  const auto logger =
      std::make_shared<spdlog::logger>("test", std::make_shared<spdlog::sinks::null_sink_mt>());
  StoreLedger ledger(**store, dir / "checkpoints", logger);
  JobHub hub;
  JobRunnerOptions options;
  options.workers = 2;
  options.threads_per_job = 1;
  options.build_id = "test";
  // No poll within the test: only the wake-up can start a worker.
  options.idle_poll = std::chrono::minutes(10);
  JobRunner runner(ledger, store->get(), hub, options, logger);
  runner.Start();
  std::this_thread::sleep_for(200ms);  // both workers have found nothing and sleep

  // Two jobs that run until they are stopped.
  v1::Scene scene = testing::ExampleScene("transient_1d.textproto");
  scene.mutable_solver()->set_end_time_s(1000.0);
  for (const char* id : {"j-first", "j-second"}) {
    JobRecord job;
    job.id = id;
    job.name = id;
    job.scene = scene.SerializeAsString();
    ASSERT_TRUE((*store)->Insert(job).ok());
  }
  runner.Wake();

  const auto running = [&](const std::string& id) {
    auto job = (*store)->Get(id);
    return job.ok() && job->state == JobState::kRunning;
  };
  const auto deadline = std::chrono::steady_clock::now() + 20s;
  while (!(running("j-first") && running("j-second")) &&
         std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(10ms);
  }
  EXPECT_TRUE(running("j-first"));
  EXPECT_TRUE(running("j-second")) << "one wake-up started one worker only";
  runner.Stop();
  store->reset();
  if (!::testing::Test::HasFailure()) std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace seep::service
