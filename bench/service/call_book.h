// CallBook: the latency of every RPC a bench's client threads make, by call, with its errors;
// thread-safe, printed as one table (count, errors, p50, p99, max).
#pragma once

#include <grpcpp/grpcpp.h>

#include <functional>
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include "service_bench.h"

namespace seep::bench {

class CallBook {
 public:
  void Add(const std::string& call, double millis, const grpc::Status& status);
  int errors() const;
  // Nearest-rank percentile of one call's latencies in ms (0 when it has none).
  double Percentile(const std::string& call, double q) const;
  std::size_t Count(const std::string& call) const;
  void Print() const;

 private:
  mutable std::mutex mutex_;
  std::map<std::string, std::vector<double>> latencies_;
  std::map<std::string, int> errors_;
  std::vector<std::string> first_errors_;
};

// Runs fn, adding its latency and status to `book` under `call` when `record` is true; returns
// the status.
grpc::Status Timed(CallBook& book, const std::string& call, const std::function<grpc::Status()>& fn,
                   bool record = true);

}  // namespace seep::bench
