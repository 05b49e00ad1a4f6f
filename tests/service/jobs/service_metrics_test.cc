// ServiceMetrics: the text exposition format, counters that move, the step rate's window, and
// counts from many threads while scrapes render (label `concurrency`: also under TSan).
#include "metrics/service_metrics.h"

#include <gtest/gtest.h>

#include <thread>
#include <vector>

namespace seep::service {
namespace {

bool Has(const std::string& text, const std::string& line) {
  return text.find(line + "\n") != std::string::npos;
}

TEST(ServiceMetrics, RendersCountersAndGaugesInTheExpositionFormat) {
  ServiceMetrics metrics;
  MetricsSnapshotGauges gauges;
  gauges.jobs_by_state = {{"QUEUED", 3}, {"RUNNING", 1}};
  gauges.watch_streams = 2;
  std::string text = metrics.Render(gauges);
  EXPECT_TRUE(Has(text, "# TYPE seep_jobs gauge")) << text;
  EXPECT_TRUE(Has(text, "seep_jobs{state=\"QUEUED\"} 3")) << text;
  EXPECT_TRUE(Has(text, "seep_queue_depth 3")) << text;
  EXPECT_TRUE(Has(text, "seep_watch_streams 2")) << text;
  EXPECT_TRUE(Has(text, "seep_steps_total 0")) << text;
  EXPECT_TRUE(Has(text, "seep_checkpoint_write_seconds_count 0")) << text;

  metrics.CountRpc("SubmitJob", "OK");
  metrics.CountRpc("SubmitJob", "OK");
  metrics.CountRpc("GetJob", "NOT_FOUND");
  metrics.AddSteps(40);
  metrics.RecordCheckpoint(1000, 0.004);
  metrics.RecordCheckpoint(500, 2.0);
  text = metrics.Render(gauges);
  EXPECT_TRUE(Has(text, "seep_rpc_requests_total{method=\"SubmitJob\",code=\"OK\"} 2")) << text;
  EXPECT_TRUE(Has(text, "seep_rpc_requests_total{method=\"GetJob\",code=\"NOT_FOUND\"} 1")) << text;
  EXPECT_TRUE(Has(text, "seep_steps_total 40")) << text;
  EXPECT_TRUE(Has(text, "seep_checkpoints_total 2")) << text;
  EXPECT_TRUE(Has(text, "seep_checkpoint_bytes_total 1500")) << text;
  EXPECT_TRUE(Has(text, "seep_checkpoint_write_seconds_bucket{le=\"0.005\"} 1")) << text;
  EXPECT_TRUE(Has(text, "seep_checkpoint_write_seconds_bucket{le=\"5\"} 2")) << text;
  EXPECT_TRUE(Has(text, "seep_checkpoint_write_seconds_bucket{le=\"+Inf\"} 2")) << text;
  EXPECT_TRUE(Has(text, "seep_checkpoint_write_seconds_count 2")) << text;
}

TEST(ServiceMetrics, StepRateIsMeasuredOverAWindowOfAtLeastASecond) {
  ServiceMetrics metrics;
  (void)metrics.Render({});
  metrics.AddSteps(1000);
  EXPECT_TRUE(Has(metrics.Render({}), "seep_step_rate_per_second 0"));  // window too short
  std::this_thread::sleep_for(std::chrono::milliseconds(1100));
  const std::string text = metrics.Render({});
  const std::string sample = "\nseep_step_rate_per_second ";
  const std::size_t at = text.find(sample);
  ASSERT_NE(at, std::string::npos) << text;
  const double rate = std::stod(text.substr(at + sample.size()));
  EXPECT_GT(rate, 0.0);
  EXPECT_LE(rate, 1000.0);
}

TEST(ServiceMetrics, CountsFromManyThreadsWhileScrapingAddUp) {
  ServiceMetrics metrics;
  constexpr int kThreads = 4;
  constexpr int kEach = 2000;
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([&] {
      for (int i = 0; i < kEach; ++i) {
        metrics.CountRpc("GetJob", "OK");
        metrics.AddSteps(1);
        if (i % 100 == 0) metrics.RecordCheckpoint(10, 0.001);
      }
    });
  }
  threads.emplace_back([&] {
    for (int i = 0; i < 50; ++i) (void)metrics.Render({});
  });
  for (auto& t : threads) t.join();
  const std::string text = metrics.Render({});
  EXPECT_TRUE(Has(text, "seep_rpc_requests_total{method=\"GetJob\",code=\"OK\"} 8000")) << text;
  EXPECT_TRUE(Has(text, "seep_steps_total 8000")) << text;
  EXPECT_TRUE(Has(text, "seep_checkpoints_total 80")) << text;
  EXPECT_TRUE(Has(text, "seep_checkpoint_bytes_total 800")) << text;
}

}  // namespace
}  // namespace seep::service
