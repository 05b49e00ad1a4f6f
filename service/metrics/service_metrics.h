// ServiceMetrics: the counters seepd exposes to Prometheus (metrics_endpoint.h serves them).
// Counters only ever grow and are safe to bump from any thread; the gauges that describe the
// store (jobs by state, queue depth) are read when a scrape asks for them and passed to Render.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <map>
#include <mutex>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace seep::service {

// What a scrape reads at its own time.
struct MetricsSnapshotGauges {
  std::vector<std::pair<std::string, std::int64_t>> jobs_by_state;  // e.g. {"QUEUED", 3}
  int watch_streams = 0;
};

class ServiceMetrics {
 public:
  // Upper bounds (seconds) of the checkpoint write-latency histogram's buckets.
  static constexpr double kLatencyBuckets[] = {0.001, 0.005, 0.01, 0.05, 0.1, 0.5, 1, 5, 10};

  // One finished RPC; code is the canonical status name ("OK", "NOT_FOUND", ...).
  void CountRpc(std::string_view method, std::string_view code);
  // Steps taken by the workers' jobs.
  void AddSteps(std::uint64_t steps) { steps_.fetch_add(steps, std::memory_order_relaxed); }
  // One checkpoint written and recorded: its size and how long writing it took.
  void RecordCheckpoint(std::int64_t bytes, double seconds);

  // The text exposition format (version 0.0.4), counters and the given gauges. The step rate is
  // measured between two renders at least a second apart (the newest such window).
  std::string Render(const MetricsSnapshotGauges& gauges);

 private:
  std::atomic<std::uint64_t> steps_{0};
  std::mutex mutex_;
  std::map<std::pair<std::string, std::string>, std::uint64_t> rpcs_;  // (method, code)
  std::uint64_t checkpoints_ = 0;
  std::uint64_t checkpoint_bytes_ = 0;
  double checkpoint_seconds_ = 0.0;
  std::uint64_t latency_counts_[std::size(kLatencyBuckets)] = {};
  // The step-rate window.
  std::chrono::steady_clock::time_point rate_since_ = std::chrono::steady_clock::now();
  std::uint64_t rate_steps_since_ = 0;
  double step_rate_ = 0.0;
};

}  // namespace seep::service
