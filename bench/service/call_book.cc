// Per-call latencies and errors of the service benches' clients (call_book.h).
#include "call_book.h"

#include <algorithm>
#include <cstdio>

namespace seep::bench {

void CallBook::Add(const std::string& call, double millis, const grpc::Status& status) {
  std::lock_guard lock(mutex_);
  latencies_[call].push_back(millis);
  if (!status.ok()) {
    ++errors_[call];
    if (first_errors_.size() < 5) {
      first_errors_.push_back(call + ": " + std::to_string(status.error_code()) + " " +
                              status.error_message());
    }
  }
}

int CallBook::errors() const {
  std::lock_guard lock(mutex_);
  int total = 0;
  for (const auto& [call, n] : errors_) total += n;
  return total;
}

double CallBook::Percentile(const std::string& call, double q) const {
  std::lock_guard lock(mutex_);
  const auto it = latencies_.find(call);
  return it == latencies_.end() ? 0.0 : bench::Percentile(it->second, q);
}

std::size_t CallBook::Count(const std::string& call) const {
  std::lock_guard lock(mutex_);
  const auto it = latencies_.find(call);
  return it == latencies_.end() ? 0 : it->second.size();
}

void CallBook::Print() const {
  std::lock_guard lock(mutex_);
  std::printf("%-18s %9s %7s %10s %10s %10s\n", "call", "count", "errors", "p50_ms", "p99_ms",
              "max_ms");
  for (const auto& [call, samples] : latencies_) {
    const auto e = errors_.find(call);
    std::printf("%-18s %9zu %7d %10.2f %10.2f %10.2f\n", call.c_str(), samples.size(),
                e == errors_.end() ? 0 : e->second, Median(samples),
                bench::Percentile(samples, 0.99),
                *std::max_element(samples.begin(), samples.end()));
  }
  for (const auto& line : first_errors_) std::printf("error: %s\n", line.c_str());
}

grpc::Status Timed(CallBook& book, const std::string& call, const std::function<grpc::Status()>& fn,
                   bool record) {
  const auto start = Clock::now();
  const grpc::Status status = fn();
  if (record) book.Add(call, Millis(start, Clock::now()), status);
  return status;
}

}  // namespace seep::bench
