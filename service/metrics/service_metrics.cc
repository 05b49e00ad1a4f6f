#include "metrics/service_metrics.h"

#include <fmt/format.h>

namespace seep::service {
namespace {

// A label value as the exposition format wants it: backslash, quote and newline escaped.
std::string LabelValue(std::string_view value) {
  std::string out;
  for (const char c : value) {
    if (c == '\\' || c == '"') out += '\\';
    if (c == '\n') {
      out += "\\n";
      continue;
    }
    out += c;
  }
  return out;
}

void Header(std::string& out, const char* name, const char* type, const char* help) {
  out += fmt::format("# HELP {} {}\n# TYPE {} {}\n", name, help, name, type);
}

}  // namespace

void ServiceMetrics::CountRpc(std::string_view method, std::string_view code) {
  std::lock_guard lock(mutex_);
  ++rpcs_[{std::string(method), std::string(code)}];
}

void ServiceMetrics::RecordCheckpoint(std::int64_t bytes, double seconds) {
  std::lock_guard lock(mutex_);
  ++checkpoints_;
  checkpoint_bytes_ += static_cast<std::uint64_t>(std::max<std::int64_t>(0, bytes));
  checkpoint_seconds_ += seconds;
  for (std::size_t b = 0; b < std::size(kLatencyBuckets); ++b) {
    if (seconds <= kLatencyBuckets[b]) ++latency_counts_[b];
  }
}

std::string ServiceMetrics::Render(const MetricsSnapshotGauges& gauges) {
  const std::uint64_t steps = steps_.load(std::memory_order_relaxed);
  std::lock_guard lock(mutex_);
  const auto now = std::chrono::steady_clock::now();
  if (const double window = std::chrono::duration<double>(now - rate_since_).count();
      window >= 1.0) {
    step_rate_ = static_cast<double>(steps - rate_steps_since_) / window;
    rate_since_ = now;
    rate_steps_since_ = steps;
  }
  std::string out;
  Header(out, "seep_jobs", "gauge", "Jobs in the store by state.");
  std::int64_t queued = 0;
  for (const auto& [state, count] : gauges.jobs_by_state) {
    out += fmt::format("seep_jobs{{state=\"{}\"}} {}\n", LabelValue(state), count);
    if (state == "QUEUED") queued = count;
  }
  Header(out, "seep_queue_depth", "gauge", "Jobs waiting for a worker.");
  out += fmt::format("seep_queue_depth {}\n", queued);
  Header(out, "seep_watch_streams", "gauge", "WatchJob streams open now.");
  out += fmt::format("seep_watch_streams {}\n", gauges.watch_streams);
  Header(out, "seep_steps_total", "counter", "Simulation steps taken by this seepd's workers.");
  out += fmt::format("seep_steps_total {}\n", steps);
  Header(out, "seep_step_rate_per_second", "gauge",
         "Steps per wall second, over the newest window of at least a second between scrapes.");
  out += fmt::format("seep_step_rate_per_second {}\n", step_rate_);
  Header(out, "seep_checkpoints_total", "counter", "Checkpoints written and recorded.");
  out += fmt::format("seep_checkpoints_total {}\n", checkpoints_);
  Header(out, "seep_checkpoint_bytes_total", "counter", "Bytes of the checkpoints written.");
  out += fmt::format("seep_checkpoint_bytes_total {}\n", checkpoint_bytes_);
  Header(out, "seep_checkpoint_write_seconds", "histogram",
         "Wall time of one checkpoint: serialize, write, fsync, rename, record.");
  for (std::size_t b = 0; b < std::size(kLatencyBuckets); ++b) {
    out += fmt::format("seep_checkpoint_write_seconds_bucket{{le=\"{}\"}} {}\n", kLatencyBuckets[b],
                       latency_counts_[b]);
  }
  out += fmt::format("seep_checkpoint_write_seconds_bucket{{le=\"+Inf\"}} {}\n", checkpoints_);
  out += fmt::format("seep_checkpoint_write_seconds_sum {}\n", checkpoint_seconds_);
  out += fmt::format("seep_checkpoint_write_seconds_count {}\n", checkpoints_);
  Header(out, "seep_rpc_requests_total", "counter",
         "seep.v1.SeepService calls finished, by method and status code.");
  for (const auto& [key, count] : rpcs_) {
    out += fmt::format("seep_rpc_requests_total{{method=\"{}\",code=\"{}\"}} {}\n",
                       LabelValue(key.first), LabelValue(key.second), count);
  }
  return out;
}

}  // namespace seep::service
