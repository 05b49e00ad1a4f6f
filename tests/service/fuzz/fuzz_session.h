// A fuzz run against a real seepd: the seeded requests (request_generator.h) sent one by one,
// and after each the invariants of issue 50 checked: seepd alive with the same pid, its RSS under
// the bound, every refusal naming a field (refusal_rule.h), the store holding exactly what the
// accepted requests made (a refusal stores nothing: the jobs and sweeps counted in its database);
// at the end every accepted job ended, SUCCEEDED with finite metrics or FAILED with a reason
// (CANCELLED only when the fuzzer cancelled it), and no checkpoint folder without its job.
// A violation names the run's seed, the request's index and how the request was made.
#pragma once

#include <grpcpp/grpcpp.h>
#include <sys/types.h>

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <ostream>
#include <set>
#include <string>
#include <vector>

#include "request_generator.h"
#include "seep/v1/job_service.grpc.pb.h"
#include "seepd_observer.h"

namespace seep::fuzz {

struct FuzzOptions {
  std::uint64_t seed = 1;
  std::uint64_t requests = 2000;
  std::size_t rss_limit_bytes = 0;  // 0: RSS is measured, not bounded
  // How long the accepted jobs get to end after the last request.
  std::chrono::seconds end_wait{60};
  std::chrono::seconds call_deadline{30};
  GeneratorLimits limits;
  // Before each request, while more jobs than this are QUEUED or RUNNING the fuzzer waits, so
  // that every accepted job can end within end_wait; a queue that ends no job for `stall` is a
  // violation. 0: no wait.
  std::int64_t max_backlog = 100;
  std::chrono::seconds stall{120};
  std::ostream* progress = nullptr;  // a line every `progress_every` requests, when set
  std::uint64_t progress_every = 1000;
};

struct FuzzCounts {
  std::uint64_t requests = 0;
  std::uint64_t redrawn = 0;  // drawn and left out by GeneratorLimits
  std::map<std::string, std::uint64_t> by_method;
  std::map<std::string, std::uint64_t> by_code;  // OK included
  std::uint64_t jobs_accepted = 0;               // created by SubmitJob and SubmitSweep
  std::uint64_t jobs_deleted = 0;                // of those, deleted by the fuzzer's own calls
  std::uint64_t succeeded = 0;
  std::uint64_t failed = 0;
  std::uint64_t failed_at_time_limit = 0;  // FAILED with DEADLINE_EXCEEDED
  std::uint64_t cancelled = 0;
  std::uint64_t unfinished = 0;  // still QUEUED or RUNNING when the wait ended
  std::map<std::string, std::uint64_t> failure_reasons;  // the first words of each reason
  std::size_t peak_rss_bytes = 0;
  double seconds = 0.0;
  double backlog_wait_s = 0.0;  // of those, waiting for the queue to drain
};

class FuzzSession {
 public:
  FuzzSession(std::shared_ptr<grpc::Channel> channel, pid_t seepd_pid,
              std::filesystem::path data_dir, FuzzOptions options);

  // Sends the requests, checking the invariants after each; stops early when seepd is gone or
  // its queue stands still.
  void SendRequests();
  // Waits for the accepted jobs and checks how they ended, the store and its folders.
  void CheckEndings();

  const std::vector<std::string>& violations() const { return violations_; }
  const FuzzCounts& counts() const { return counts_; }
  // The counts and the invariants' results, as lines.
  std::string Report() const;

 private:
  struct TrackedJob {
    std::uint64_t request = 0;  // the index of the request that made it
    std::string what;           // how that request was made
    bool cancel_requested = false;
  };

  grpc::Status Call(const FuzzRequest& request, grpc::ByteBuffer* response);
  grpc::Status Watch(const FuzzRequest& request);
  void Absorb(std::uint64_t index, const FuzzRequest& request, const grpc::ByteBuffer& response);
  void Track(std::uint64_t index, const FuzzRequest& request, const v1::Job& job);
  void Forget(const std::string& id);
  void CheckStore(std::uint64_t index, const FuzzRequest& request);
  void CheckProcess(std::uint64_t index, const FuzzRequest& request);
  void Violation(std::uint64_t index, const FuzzRequest* request, const std::string& problem);
  void RebuildContext();
  void WaitForBacklog(std::uint64_t index);
  std::vector<v1::Job> ListAll();

  std::shared_ptr<grpc::Channel> channel_;
  std::unique_ptr<v1::SeepService::Stub> stub_;
  SeepdObserver observer_;
  FuzzOptions options_;
  FuzzCounts counts_;
  FuzzContext context_;
  std::map<std::string, TrackedJob> jobs_;
  std::map<std::string, std::vector<std::string>> sweeps_;  // sweep id -> its job ids
  std::map<std::string, v1::Scene> staged_;                 // fork parents
  std::set<std::string> request_ids_;
  std::int64_t expected_jobs_ = 0;
  std::int64_t expected_sweeps_ = 0;
  bool seepd_gone_ = false;
  bool queue_stuck_ = false;  // no job ended for options_.stall
  bool rss_reported_ = false;
  std::vector<std::string> violations_;
};

}  // namespace seep::fuzz
